// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate guidance: the plan placed by tofnav navigate against the simulator's truth
// (paper Sec. "Use Cases": entry-point and trajectory-direction error over every trajectory).
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "config_json.hpp"
#include "evaluate.hpp"
#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/evaluation/guidance_evaluate.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

OrderedJson GuidanceStatsJson(const Summary& s) {
  return {
      {"count", s.count}, {"median", s.median}, {"iqr", s.iqr()}, {"rms", s.rms}, {"p95", s.p95}};
}

int RunEvaluateGuidance(int argc, char** argv) {
  CLI::App app{
      "Entry-point and direction error of the plan placed by tofnav navigate, against a "
      "simulation's truth (every trajectory, every placed frame)",
      "tofnav evaluate guidance"};
  AddConfigOptions(app);
  std::filesystem::path nav_path, truth_dir, plan_path;
  bool json = false, quiet = false;
  app.add_option("navigation", nav_path, "per-frame CSV of tofnav navigate --out")->required();
  app.add_option("--truth", truth_dir, "simulation folder (truth.json, plan.mrk.json)")->required();
  app.add_option("--plan", plan_path, "the plan navigate used (unset: TRUTH/plan.mrk.json)");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the figures as JSON");
  TOFNAV_PARSE(app, argc, argv);
  if (plan_path.empty()) plan_path = truth_dir / "plan.mrk.json";

  const std::vector<PlacedFrame> placed = ReadNavigationCsv(nav_path);
  if (placed.empty()) throw std::runtime_error(nav_path.string() + ": no frame placed the plan");
  const std::vector<Trajectory> plan = ReadTrajectories(plan_path);
  const GuidanceEvaluation g = EvaluateGuidanceAgainstTruth(placed, truth_dir / "truth.json", plan);
  const Summary& entry = g.entry_mm;
  const Summary& world = g.entry_world_mm;
  const Summary& angle = g.direction_deg;
  const std::size_t unmatched = g.unmatched;
  if (json) {
    OrderedJson out{{"frames", g.frames},
                    {"unmatched_frames", unmatched},
                    {"trajectories", plan.size()},
                    {"entry_error_mm", GuidanceStatsJson(entry)},
                    {"entry_error_world_mm", GuidanceStatsJson(world)},
                    {"direction_error_deg", GuidanceStatsJson(angle)},
                    {"per_trajectory", OrderedJson::array()}};
    for (const TrajectoryGuidanceError& t : g.trajectories) {
      out["per_trajectory"].push_back(
          {{"name", t.name},
           {"entry_error_mm", GuidanceStatsJson(t.entry_mm)},
           {"direction_error_deg", GuidanceStatsJson(t.direction_deg)}});
    }
    std::cout << WithOptions(out, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "frames " << g.frames << " (unmatched " << unmatched << "), " << plan.size()
            << " trajectories\n"
            << "trajectory        entry median / p95 [mm]   direction median / p95 [deg]\n";
  for (const TrajectoryGuidanceError& t : g.trajectories) {
    const Summary& e = t.entry_mm;
    const Summary& d = t.direction_deg;
    std::cout << "  " << t.name << "\t" << e.median << " / " << e.p95 << "\t\t" << d.median << " / "
              << d.p95 << "\n";
  }
  std::cout << "all: entry median " << entry.median << " mm (p95 " << entry.p95 << ", RMS "
            << entry.rms << "), in world (with the headset's pose error) " << world.median
            << " mm; direction median " << angle.median << " deg (p95 " << angle.p95 << ")\n";
  return EXIT_SUCCESS;
}

[[maybe_unused]] const bool kGuidanceRegistered = RegisterEvaluator(
    {"guidance", "plan placed by tofnav navigate against a simulation's truth (entry, direction)",
     RunEvaluateGuidance});

}  // namespace
}  // namespace tofnav
