// SPDX-License-Identifier: BSD-3-Clause
// Ray casting a scenario at the poses of one truth.json frame.
#include "tofnav/evaluation/truth_hits.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <vector>

#include "tofnav/io/io_error.hpp"
#include "tofnav/scenario/patient_head.hpp"
#include "tofnav/scenario/scenario_json.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav {
namespace {

Rigid3d PoseFromMatrix(const nlohmann::json& m) {
  Eigen::Matrix4d a;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      a(r, c) = m.at(static_cast<std::size_t>(r)).at(static_cast<std::size_t>(c)).get<double>();
    }
  }
  return Rigid3d(Eigen::Quaterniond(a.topLeftCorner<3, 3>()).normalized(),
                 a.topRightCorner<3, 1>());
}

}  // namespace

Rigid3d TruthMatrix(const nlohmann::json& rows) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      m(r, c) = rows.at(static_cast<std::size_t>(r)).at(static_cast<std::size_t>(c)).get<double>();
    }
  }
  return Rigid3d::FromMatrix(m);
}

SimulationTruth ReadSimulationTruth(const std::filesystem::path& dir, std::string scenario_name) {
  std::ifstream file(dir / "truth.json");
  if (!file) throw IoError(dir / "truth.json", std::nullopt, "cannot open");
  SimulationTruth out;
  try {
    out.truth = nlohmann::json::parse(file);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(dir / "truth.json", std::nullopt, std::string("not JSON: ") + e.what());
  }
  if (!scenario_name.empty()) {
    out.scenario = LoadScenario(scenario_name);
    return out;
  }
  // A built-in scenario simulated with `--head mesh:...` or `ct:...` has another head object.
  const nlohmann::json& truth = out.truth;
  scenario_name = truth.at("scenario").get<std::string>();
  const nlohmann::json* head = truth.contains("patient") && truth["patient"].contains("head")
                                   ? &truth["patient"]["head"]
                                   : nullptr;
  const std::vector<std::string> builtins = sim::BuiltinScenarioNames();
  if (head == nullptr || !head->is_string() || head->get<std::string>() == "phantom" ||
      std::find(builtins.begin(), builtins.end(), scenario_name) == builtins.end()) {
    out.scenario = LoadScenario(scenario_name);
  } else {
    const sim::PatientHead patient_head = LoadPatientHead(head->get<std::string>());
    out.scenario = sim::BuiltinScenario(scenario_name, &patient_head);
  }
  return out;
}

TruthHits CastTruthHits(sim::Scene& scene, sim::SceneRaycaster& caster,
                        const nlohmann::json& truth_frame, const AhatCamera& camera) {
  const nlohmann::json& objects = truth_frame.at("ahat_from_objects");
  // A scene rebuilt from the truth's scenario name lacks what a variation (the suite's) changed.
  const auto absent = [](const std::string& what) {
    return std::runtime_error("the truth's frames have no pose of " + what +
                              ": the recorded scene differs from the scenario it names (a suite "
                              "variation?); give the scenario file with --scenario");
  };
  for (sim::SceneObject& o : scene.objects) {
    if (!objects.contains(o.name)) throw absent("object '" + o.name + "'");
    o.scene_from_object = PoseFromMatrix(objects.at(o.name));
  }
  for (sim::Tool& t : scene.tools) {
    if (!truth_frame.contains("ahat_from_" + t.name)) throw absent("tool '" + t.name + "'");
    t.scene_from_tool = PoseFromMatrix(truth_frame.at("ahat_from_" + t.name));
  }
  caster.SetPoses(scene, Rigid3d());
  const int w = camera.width(), h = camera.height();
  std::vector<Eigen::Vector3d> rays(static_cast<std::size_t>(w) * static_cast<std::size_t>(h),
                                    Eigen::Vector3d::UnitZ());
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (camera.IsValid(u, v)) {
        rays[static_cast<std::size_t>(v * w + u)] =
            camera.PixelRay(u, v).cast<double>().normalized();
      }
    }
  }
  std::vector<sim::RayHit> hits(rays.size());
  caster.Intersect(rays, hits);
  TruthHits truth{Image<int>(w, h, -1), Image<int>(w, h, -1), Image<float>(w, h, 0.0f)};
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const sim::RayHit& hit = hits[static_cast<std::size_t>(v * w + u)];
      if (!camera.IsValid(u, v) || !hit.hit()) continue;
      truth.object(u, v) = hit.object >= 0 ? hit.object : -2;
      truth.material(u, v) = hit.material;
      truth.range_mm(u, v) = static_cast<float>(hit.range_mm);
    }
  }
  return truth;
}

}  // namespace tofnav
