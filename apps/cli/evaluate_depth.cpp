// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate depth: depth error per object before/after correction vs simulator truth.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "config_json.hpp"
#include "evaluate.hpp"
#include "progress.hpp"
#include "tofnav/evaluation/depth_evaluate.hpp"
#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

using Json = nlohmann::json;

int RunEvaluateDepth(int argc, char** argv) {
  CLI::App app{
      "Depth error per object before and after correction, against the simulator's "
      "truth_range_f32.bin (paper Table I layout; docs/correction.md)",
      "tofnav evaluate depth"};
  AddConfigOptions(app);
  SimulatedRunArgs run;
  std::filesystem::path model_path;
  run.AddOptions(app, "simulator output folder (truth.json, truth_range_f32.bin)");
  app.add_option("--depth-model", model_path, "depth_model.json: also report after correction");
  TOFNAV_PARSE(app, argc, argv);

  const AhatCamera camera = run.Camera();
  const std::unique_ptr<AhatRecording> recording = run.Open();
  const std::filesystem::path& truth_dir = run.truth_dir;
  const bool json_out = run.json;
  std::optional<DepthModelFile> model;
  if (!model_path.empty()) model = ReadDepthModelJson(model_path);
  ProgressBar progress("evaluate depth", run.quiet || json_out);
  const DepthEvaluation evaluation = EvaluateDepthAgainstTruth(
      *recording, camera, truth_dir, ReadSimulationTruth(truth_dir, run.scenario_name).scenario,
      model, run.max_frames,
      [&](std::size_t done, std::size_t total) { progress.Update(done, total); });
  Json rows = Json::array();
  for (const ObjectDepthError& o : evaluation.objects) {
    Json row{{"object", o.name},
             {"role", o.role},
             {"pixels", o.before_mm.count},
             {"head_region_percent", o.head_region_percent},
             {"before_median_mm", o.before_mm.median},
             {"before_iqr_mm", o.before_mm.iqr()}};
    if (o.after_mm) {
      row["after_median_mm"] = o.after_mm->median;
      row["after_iqr_mm"] = o.after_mm->iqr();
      row["reduction_percent"] = o.reduction_percent;
    }
    row["by_incidence_deg"] = DepthErrorBinsJson(o.by_incidence_deg, "deg");
    row["by_range_mm"] = DepthErrorBinsJson(o.by_range_mm, "mm");
    rows.push_back(row);
  }
  if (json_out) {
    std::cout << WithOptions(Json{{"frames", evaluation.frames},
                                  {"model", model ? model->model.Name() : ""},
                                  {"target_object", evaluation.target_object},
                                  {"objects", rows}},
                             app)
                     .dump(2)
              << "\n";
    return EXIT_SUCCESS;
  }
  const std::string& target = evaluation.target_object;
  std::cout << "depth error (measured - true range) [mm], " << evaluation.frames << " frames"
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
  for (const ObjectDepthError& o : evaluation.objects) {
    if (o.role != "target") continue;
    const auto print_bins = [&](const std::vector<DepthErrorBin>& bins, const char* what,
                                const char* unit) {
      std::cout << "'" << o.name << "' by true " << what << ": " << std::setprecision(0);
      for (const DepthErrorBin& b : bins) {
        std::cout << "\n  " << std::setw(4) << b.from << "-" << std::left << std::setw(4) << b.to
                  << std::right << unit << std::setw(9) << b.pixels << " px  before "
                  << std::setprecision(2) << std::setw(6) << b.before_median_mm;
        if (b.after_median_mm) std::cout << "  after " << std::setw(6) << *b.after_median_mm;
        std::cout << std::setprecision(0);
      }
      std::cout << "\n" << std::setprecision(2);
    };
    print_bins(o.by_incidence_deg, "incidence", " deg");
    print_bins(o.by_range_mm, "range", " mm");
  }
  return EXIT_SUCCESS;
}

namespace {
[[maybe_unused]] const bool kDepthRegistered =
    RegisterEvaluator({"depth", "depth error per object before/after correction vs simulator truth",
                       RunEvaluateDepth});
}  // namespace

}  // namespace tofnav
