// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate fidelity: the published measurements of real devices re-done on the simulator,
// each with its own protocol: published, ours, within the published spread (docs/simulator.md 10).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "config_json.hpp"
#include "evaluate.hpp"
#include "progress.hpp"
#include "tofnav/evaluation/fidelity.hpp"
#include "tofnav/io/file.hpp"

namespace tofnav {
namespace {

nlohmann::ordered_json RowJson(const FidelityRow& r) {
  return {{"experiment", r.experiment},
          {"figure", r.figure},
          {"source", r.source},
          {"published", r.published},
          {"published_low", r.published_low},
          {"published_high", r.published_high},
          {"band", r.spread_published ? "published mean +- sd" : "+-25 % (no spread published)"},
          {"ours", r.ours},
          {"within", r.within()}};
}

int RunEvaluateFidelity(int argc, char** argv) {
  CLI::App app{
      "The published measurements of real HoloLens 2 devices re-done on the simulator, each with "
      "its own protocol (the tape on a linear stage, STTAR's sphere markers, the materials "
      "plate, Table I's phantoms, the skin study): published, ours, within the published spread "
      "(docs/simulator.md 10)",
      "tofnav evaluate fidelity"};
  AddConfigOptions(app);
  FidelityOptions options;
  std::filesystem::path out = "tofnav-fidelity";
  bool json = false, quiet = false;
  app.add_option("--out", out, "output folder: one folder per simulation, fidelity.json");
  app.add_option("--seed", options.seed, "random seed of the simulations and participants");
  app.add_option("--frames-scale", options.frames_scale,
                 "every protocol's frames times this (1: about 4 minutes on 2 cores)")
      ->check(CLI::Range(0.05, 20.0));
  app.add_option("--participants", options.participants, "the skin study's participants")
      ->check(CLI::Range(2, 100));
  app.add_option("--marker-positions", options.marker_positions,
                 "STTAR markers: static positions of the sphere tool over 350-700 mm")
      ->check(CLI::Range(2, 148));
  app.add_option("--only", options.only,
                 "run only these experiments (repeatable): tape, markers (STTAR's sphere tool), "
                 "materials, phantoms, skin")
      ->check(CLI::IsMember(FidelityExperiments()));
  std::optional<double> multipath_gain;
  app.add_option("--multipath-gain", multipath_gain,
                 "one-bounce multipath of every simulation (unset: the simulator's calibrated "
                 "default, 0.7, docs/simulator.md 10; 0: off, to see what the indirect light does "
                 "to each row)")
      ->check(CLI::Range(0.0, 1.0));
  std::optional<double> floor_exponent;
  app.add_option(
         "--noise-floor-exponent", floor_exponent,
         "the range noise floor grows as (range / 350 mm)^E in every simulation (unset: "
         "the simulator's default, 1.5; 0: flat as before session 29; docs/simulator.md 10.1)")
      ->check(CLI::Range(0.0, 4.0));
  std::vector<std::string> phantom_models;
  app.add_option("--phantom-depth-model", phantom_models,
                 "PHANTOM=depth_model.json (photopolymer or nylon; repeatable): Table I after "
                 "correction, the phantom's frames corrected by this model (e.g. identified on a "
                 "session of that phantom)");
  app.add_flag("--json", json, "print fidelity.json to stdout (nothing else on stdout)");
  app.add_flag("-q,--quiet", quiet, "no progress bars");
  TOFNAV_PARSE(app, argc, argv);
  options.out = out;
  for (const std::string& given : phantom_models) {
    const std::size_t eq = given.find('=');
    const std::string phantom = given.substr(0, eq);
    if (eq == std::string::npos || (phantom != "photopolymer" && phantom != "nylon")) {
      std::fprintf(stderr,
                   "tofnav evaluate fidelity: --phantom-depth-model '%s': expected "
                   "photopolymer=FILE or nylon=FILE\n",
                   given.c_str());
      return EXIT_FAILURE;
    }
    options.phantom_depth_models[phantom] = ReadDepthModelJson(given.substr(eq + 1));
  }
  if (multipath_gain || floor_exponent) {
    options.vary = [multipath_gain, floor_exponent](sim::Scenario& s) {
      if (multipath_gain) s.render.multipath.gain = *multipath_gain;
      if (floor_exponent) s.render.noise.depth_sigma_floor_exponent = *floor_exponent;
    };
  }
  std::filesystem::create_directories(out);
  std::unique_ptr<ProgressBar> bar;
  std::string bar_label;
  options.progress = [&](const std::string& label, std::size_t done, std::size_t total) {
    if (label != bar_label || !bar) {
      bar = std::make_unique<ProgressBar>("fidelity: " + label, quiet || json);
      bar_label = label;
    }
    bar->Update(done, total);
  };
  const FidelityResult result = RunFidelity(options);
  bar.reset();
  nlohmann::ordered_json doc{{"format", "tofnav-fidelity"},
                             {"version", 1},
                             {"tofnav_version", TOFNAV_VERSION},
                             {"seed", options.seed},
                             {"frames_scale", options.frames_scale},
                             {"rows", nlohmann::ordered_json::array()},
                             {"details", result.details},
                             {"options", EffectiveOptions(app)}};
  std::size_t within = 0;
  for (const FidelityRow& r : result.rows) {
    doc["rows"].push_back(RowJson(r));
    within += r.within() ? 1 : 0;
  }
  doc["within"] = within;
  WriteFileAtomically(out / "fidelity.json", doc.dump(2) + "\n");
  if (json) {
    std::cout << doc.dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::printf("%-24s %-52s %9s %17s %9s %s\n", "experiment", "figure", "published", "band", "ours",
              "within");
  for (const FidelityRow& r : result.rows) {
    std::printf("%-24s %-52s %9.2f %7.2f - %-7.2f %9.2f %s\n", r.experiment.c_str(),
                r.figure.c_str(), r.published, r.published_low, r.published_high, r.ours,
                r.within() ? "yes" : "NO");
  }
  std::printf(
      "\n%zu of %zu rows within the published spread (a figure published without one: "
      "+-25 %%); fidelity.json in %s\n",
      within, result.rows.size(), out.string().c_str());
  return EXIT_SUCCESS;
}

[[maybe_unused]] const bool kFidelityRegistered = RegisterEvaluator(
    {"fidelity", "the published real-device measurements re-done on the simulator",
     RunEvaluateFidelity});

}  // namespace
}  // namespace tofnav
