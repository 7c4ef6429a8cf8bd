// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate depth: depth error per object before/after correction vs simulator truth.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "evaluate.hpp"
#include "progress.hpp"
#include "tofnav/correction/correct_range.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/io/ahat_recording.hpp"
#include "tofnav/io/depth_model_json.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/hl2ss_calibration.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/patient_head.hpp"
#include "tofnav/io/scenario_json.hpp"
#include "tofnav/sim/raycaster.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;
constexpr std::size_t kTruthFrameBytes = 4u * kAhatPixels;
constexpr int kEdgeMarginPx = 2;      // pixels this close to another object or a marker: mixed
constexpr double kEdgeJumpMm = 10.0;  // truth range jump that marks a depth edge

Rigid3d MatrixPose(const Json& m) {
  Eigen::Matrix4d a;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c)
      a(r, c) = m.at(static_cast<std::size_t>(r)).at(static_cast<std::size_t>(c)).get<double>();
  }
  return Rigid3d(Eigen::Quaterniond(a.topLeftCorner<3, 3>()).normalized(),
                 a.topRightCorner<3, 1>());
}

// Object label per pixel (-1: none, -2: marker) from ray casting the scenario at the truth poses.
Image<int> ObjectLabels(sim::Scene& scene, sim::SceneRaycaster& caster, const Json& frame,
                        const AhatCamera& camera) {
  for (sim::SceneObject& o : scene.objects) {
    o.scene_from_object = MatrixPose(frame.at("ahat_from_objects").at(o.name));
  }
  for (sim::Tool& t : scene.tools) t.scene_from_tool = MatrixPose(frame.at("ahat_from_" + t.name));
  caster.SetPoses(scene, Rigid3d());
  std::vector<Eigen::Vector3d> rays(kAhatPixels, Eigen::Vector3d::UnitZ());
  for (int v = 0; v < kAhatHeight; ++v) {
    for (int u = 0; u < kAhatWidth; ++u) {
      if (camera.IsValid(u, v))
        rays[static_cast<std::size_t>(v * kAhatWidth + u)] = camera.PixelRay(u, v).cast<double>();
    }
  }
  std::vector<sim::RayHit> hits(rays.size());
  caster.Intersect(rays, hits);
  Image<int> labels(kAhatWidth, kAhatHeight, -1);
  for (int v = 0; v < kAhatHeight; ++v) {
    for (int u = 0; u < kAhatWidth; ++u) {
      const sim::RayHit& h = hits[static_cast<std::size_t>(v * kAhatWidth + u)];
      if (!camera.IsValid(u, v) || !h.hit()) continue;
      labels(u, v) = h.object >= 0 ? h.object : -2;
    }
  }
  return labels;
}

// Interior pixels of an object: same label and no truth depth edge within the margin.
bool Interior(const Image<int>& labels, const Image<float>& truth, int u, int v) {
  const int label = labels(u, v);
  for (int dv = -kEdgeMarginPx; dv <= kEdgeMarginPx; ++dv) {
    for (int du = -kEdgeMarginPx; du <= kEdgeMarginPx; ++du) {
      if (!labels.Contains(u + du, v + dv) || labels(u + du, v + dv) != label) return false;
      if (std::abs(truth(u + du, v + dv) - truth(u, v)) > kEdgeJumpMm) return false;
    }
  }
  return true;
}

struct Stats {
  double median = 0.0, q1 = 0.0, q3 = 0.0;
  std::size_t count = 0;
};
Stats Summarise(std::vector<float>& e) {
  Stats s;
  s.count = e.size();
  if (e.empty()) return s;
  auto at = [&](double q) {
    const auto k = static_cast<std::size_t>(q * static_cast<double>(e.size() - 1));
    std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(k), e.end());
    return static_cast<double>(e[k]);
  };
  s.q1 = at(0.25), s.median = at(0.5), s.q3 = at(0.75);
  return s;
}

// The scenario that was simulated: --scenario, else truth.json's, with its patient head (a
// built-in scenario simulated with `--head mesh:...` or `ct:...` has another head object).
sim::Scenario ScenarioOfTruth(const Json& truth, const std::string& scenario_name) {
  if (!scenario_name.empty()) return LoadScenario(scenario_name);
  const auto name = truth.at("scenario").get<std::string>();
  const std::vector<std::string> builtins = sim::BuiltinScenarioNames();
  const Json* head = truth.contains("patient") && truth["patient"].contains("head")
                         ? &truth["patient"]["head"]
                         : nullptr;
  if (head == nullptr || !head->is_string() || head->get<std::string>() == "phantom" ||
      std::find(builtins.begin(), builtins.end(), name) == builtins.end()) {
    return LoadScenario(name);
  }
  const sim::PatientHead patient_head = LoadPatientHead(head->get<std::string>());
  return sim::BuiltinScenario(name, &patient_head);
}

}  // namespace

int RunEvaluateDepth(int argc, char** argv) {
  CLI::App app{
      "Depth error per object before and after correction, against the simulator's "
      "truth_range_f32.bin (paper Table I layout; docs/correction.md)",
      "tofnav evaluate depth"};
  std::filesystem::path recording_path, truth_dir, calibration_path, model_path;
  std::string scenario_name;
  int max_frames = 60;
  bool json_out = false, quiet = false;
  app.add_option("recording", recording_path, "the simulated recording")->required();
  app.add_option("--truth", truth_dir, "simulator output folder (truth.json, truth_range_f32.bin)")
      ->required();
  app.add_option("--calibration", calibration_path,
                 "calibration folder (default: TRUTH/calibration)");
  app.add_option("--depth-model", model_path, "depth_model.json: also report after correction");
  app.add_option("--scenario", scenario_name, "scenario file or built-in (default: truth.json's)");
  app.add_option("--max-frames", max_frames, "frames evaluated, evenly spread")
      ->check(CLI::PositiveNumber);
  app.add_flag("--json", json_out, "print JSON");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  CLI11_PARSE(app, argc, argv);

  if (calibration_path.empty()) calibration_path = truth_dir / "calibration";
  const AhatCamera camera(ReadHl2ssCalibration(calibration_path));
  const std::unique_ptr<AhatRecording> recording = OpenAhatRecording(recording_path);
  std::ifstream truth_file(truth_dir / "truth.json");
  if (!truth_file) throw IoError(truth_dir / "truth.json", std::nullopt, "cannot open");
  const Json truth = Json::parse(truth_file);
  sim::Scenario scenario = ScenarioOfTruth(truth, scenario_name);
  sim::SceneRaycaster caster(scenario.scene);
  const Json& truth_frames = truth.at("frames");
  const RandomAccessFile ranges(truth_dir / "truth_range_f32.bin");
  if (ranges.size() != truth_frames.size() * kTruthFrameBytes ||
      truth_frames.size() != recording->frame_count()) {
    throw IoError(truth_dir / "truth_range_f32.bin", std::nullopt,
                  "frame count differs from truth.json or the recording");
  }
  std::optional<DepthModelFile> model;
  if (!model_path.empty()) model = ReadDepthModelJson(model_path);
  CorrectRangeOptions correct_options;
  correct_options.roi_only = false;
  if (model && model->marker_range) correct_options.marker_model = *model->marker_range;

  // The automatic head region (as identify segments): how much of each object it keeps.
  const SegmentationOptions roi_options = IdentificationSampling{}.segmentation;
  std::map<std::string, std::size_t> in_roi;
  std::string target;  // the object the head model is identified on (none: no patient)
  if (truth.contains("patient") && truth["patient"].contains("object")) {
    target = truth["patient"]["object"].get<std::string>();
  }
  std::map<std::string, std::vector<float>> before, after;
  const std::vector<int> picked = EvenSubsample(static_cast<int>(truth_frames.size()), max_frames);
  ProgressBar progress("evaluate depth", quiet || json_out);
  for (std::size_t n = 0; n < picked.size(); ++n) {
    const auto i = static_cast<std::size_t>(picked[n]);
    const AhatFrame frame = recording->ReadFrame(i);
    Image<float> truth_range(kAhatWidth, kAhatHeight);
    ranges.ReadAt(i * kTruthFrameBytes,
                  std::span(reinterpret_cast<std::uint8_t*>(truth_range.data()), kTruthFrameBytes),
                  "a truth range frame (float32 little-endian)");
    const Image<int> labels = ObjectLabels(scenario.scene, caster, truth_frames[i], camera);
    const FrameSegmentation roi = SegmentFrame(frame, camera, roi_options);
    std::optional<Image<float>> corrected;
    if (model) corrected = CorrectRangeImage(frame, camera, model->model, correct_options);
    for (int v = 0; v < kAhatHeight; ++v) {
      for (int u = 0; u < kAhatWidth; ++u) {
        const int label = labels(u, v);
        const std::uint16_t measured = frame.range_mm(u, v);
        if (label < 0 || truth_range(u, v) <= 0.0f || measured == 0) continue;
        if (!Interior(labels, truth_range, u, v)) continue;
        const std::string& name = scenario.scene.objects[static_cast<std::size_t>(label)].name;
        if (corrected && (*corrected)(u, v) <= 0.0f) continue;  // dropped: not in either column
        before[name].push_back(static_cast<float>(measured) - truth_range(u, v));
        if (roi.labels(u, v) == static_cast<std::uint8_t>(PixelClass::kHead)) ++in_roi[name];
        if (corrected) after[name].push_back((*corrected)(u, v) - truth_range(u, v));
      }
    }
    progress.Update(n + 1, picked.size());
  }
  Json rows = Json::array();
  for (auto& [name, errors] : before) {
    const Stats b = Summarise(errors);
    Json row{{"object", name},
             {"role", target.empty()   ? "object"
                      : name == target ? "target"
                                       : "other"},
             {"pixels", b.count},
             {"head_region_percent",
              b.count > 0 ? 100.0 * static_cast<double>(in_roi[name]) / static_cast<double>(b.count)
                          : 0.0},
             {"before_median_mm", b.median},
             {"before_iqr_mm", b.q3 - b.q1}};
    if (model) {
      const Stats a = Summarise(after[name]);
      row["after_median_mm"] = a.median;
      row["after_iqr_mm"] = a.q3 - a.q1;
      row["reduction_percent"] =
          b.median != 0.0 ? 100.0 * (1.0 - std::abs(a.median) / std::abs(b.median)) : 0.0;
    }
    rows.push_back(row);
  }
  if (json_out) {
    std::cout << Json{{"frames", picked.size()},
                      {"model", model ? model->model.Name() : ""},
                      {"target_object", target},
                      {"objects", rows}}
                     .dump(2)
              << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "depth error (measured - true range) [mm], " << picked.size() << " frames"
            << (target.empty() ? std::string()
                               : "; the model is identified on '" + target + "' (target)")
            << "\n"
            << std::left << std::setw(22) << "object" << std::right << std::setw(10) << "pixels"
            << std::setw(8) << "in ROI" << std::setw(12) << "before med" << std::setw(8) << "IQR";
  if (model)
    std::cout << std::setw(12) << "after med" << std::setw(8) << "IQR" << std::setw(11)
              << "reduction";
  std::cout << "\n" << std::fixed << std::setprecision(2);
  bool others = false;
  for (const Json& r : rows) {
    std::cout << std::left << std::setw(22) << r["object"].get<std::string>() << std::right
              << std::setw(10) << r["pixels"].get<std::size_t>() << std::setw(7)
              << std::setprecision(0) << r["head_region_percent"].get<double>() << "%"
              << std::setprecision(2) << std::setw(12) << r["before_median_mm"].get<double>()
              << std::setw(8) << r["before_iqr_mm"].get<double>();
    if (model) {
      std::cout << std::setw(12) << r["after_median_mm"].get<double>() << std::setw(8)
                << r["after_iqr_mm"].get<double>() << std::setw(10)
                << r["reduction_percent"].get<double>() << "%";
    }
    const std::string role = r["role"].get<std::string>();
    others = others || role == "other";
    std::cout << (role == "target"           ? "  target"
                  : role == "other" && model ? "  other (*)"
                                             : "")
              << "\n";
  }
  if (model && others) {
    std::cout << "(*) not the target's material: the head model is applied to every pixel here "
                 "for reference only; worse after correction is expected, not a failure\n";
  }
  std::cout << "in ROI: share of the object's pixels in the automatic head region (identify's)\n";
  return EXIT_SUCCESS;
}

namespace {
[[maybe_unused]] const bool kRegistered =
    RegisterEvaluator({"depth", "depth error per object before/after correction vs simulator truth",
                       RunEvaluateDepth});
}  // namespace

}  // namespace tofnav
