// SPDX-License-Identifier: BSD-3-Clause
// tofnav simulate: render a scenario into an hl2ss recording plus ground truth.
#include "tofnav/scenario/simulate.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "config_json.hpp"
#include "profile_option.hpp"
#include "progress.hpp"
#include "tofnav/scenario/patient_head.hpp"
#include "tofnav/scenario/scenario_json.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav {

int RunSimulate(int argc, char** argv) {
  CLI::App app{
      "Render a scenario (a JSON file or a built-in name) into an hl2ss AHAT recording, "
      "its calibration folder and ground truth (docs/simulator.md)",
      "tofnav simulate"};
  AddConfigOptions(app);
  std::string scenario_name;
  std::filesystem::path out_dir;
  std::optional<std::int64_t> frames;
  std::optional<std::uint64_t> seed;
  bool quiet = false, json = false, list = false;
  SimulateOptions options;
  std::string profile = "raw";
  app.add_option("scenario", scenario_name, "scenario .json file or built-in name (see --list)");
  app.add_option("--out", out_dir, "output folder (created if missing)");
  std::string head;
  app.add_option("--head", head,
                 "patient head of a built-in scenario: phantom, mesh:<skin.ply> or ct:<volume> "
                 "(e.g. ct:/usr/share/doc/invesalius-examples/examples/Cranium.inv3)");
  app.add_option("--frames", frames, "render only the first N frames")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "random seed (unset: the scenario's)");
  AddProfileOptions(app, profile, options.bitrate_bps);
  app.add_flag("--truth-depth", options.truth_depth,
               "also write truth_range_f32.bin (true first-hit range per pixel, float32 mm)");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the summary as one JSON object");
  app.add_flag("--list", list, "list the built-in scenarios and exit");
  TOFNAV_PARSE(app, argc, argv);

  if (list) {
    for (const std::string& name : sim::BuiltinScenarioNames()) {
      std::cout << name << "\n  " << sim::BuiltinScenarioSummary(name) << "\n";
    }
    return EXIT_SUCCESS;
  }
  if (scenario_name.empty() || out_dir.empty()) {
    std::cerr << "tofnav simulate: a scenario and --out DIR are required (--help)\n";
    return EXIT_FAILURE;
  }
  sim::Scenario scenario;
  if (head.empty()) {
    scenario = LoadScenario(scenario_name);
  } else {
    const std::vector<std::string> names = sim::BuiltinScenarioNames();
    if (std::find(names.begin(), names.end(), scenario_name) == names.end()) {
      std::cerr << "tofnav simulate: --head applies to built-in scenarios; a scenario file names "
                   "its head in patient.head\n";
      return EXIT_FAILURE;
    }
    const sim::PatientHead patient_head = LoadPatientHead(head);
    scenario = sim::BuiltinScenario(scenario_name, &patient_head);
  }
  options.frames = frames;
  options.seed = seed;
  options.profile = *ParseHl2ssStreamProfile(profile);
  ProgressBar progress("simulate " + scenario.name, quiet || json);
  options.progress = [&](std::size_t done, std::size_t total) { progress.Update(done, total); };
  const std::string name = scenario.name;
  const auto start = std::chrono::steady_clock::now();
  const SimulateResult result = RunSimulation(std::move(scenario), out_dir, options);
  progress.Finish();
  for (const std::string& warning : result.warnings) {
    std::cerr << "tofnav simulate: warning: " << warning << "\n";
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double rate = elapsed_s > 0.0 ? static_cast<double>(result.frames) / elapsed_s : 0.0;
  if (json) {
    nlohmann::ordered_json summary{{"scenario", name},
                                   {"out", out_dir.string()},
                                   {"frames", result.frames},
                                   {"dropped_slots", result.dropped_slots},
                                   {"recording_duration_s", result.duration_s},
                                   {"elapsed_s", elapsed_s},
                                   {"frames_per_s", rate},
                                   {"files", nlohmann::ordered_json::array()}};
    for (const std::filesystem::path& f : result.files) summary["files"].push_back(f.string());
    summary["warnings"] = result.warnings;
    std::cout << WithOptions(summary, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "wrote " << result.frames << " frames of '" << name << "' (" << result.dropped_slots
            << " dropped slots, " << result.duration_s << " s of recording) to " << out_dir.string()
            << " in " << elapsed_s << " s (" << rate << " frames/s)\n";
  for (const std::filesystem::path& f : result.files) std::cout << "  " << f.string() << "\n";
  return EXIT_SUCCESS;
}

}  // namespace tofnav
