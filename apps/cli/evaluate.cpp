// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate: dispatches to the registered evaluators (tracking, ...).
#include "evaluate.hpp"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string_view>
#include <vector>

#include "commands.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/open_recording.hpp"

namespace tofnav {
namespace {

std::vector<Evaluator>& Evaluators() {
  static std::vector<Evaluator> evaluators;  // filled during static initialisation
  return evaluators;
}

void PrintUsage() {
  std::cout << "usage: tofnav evaluate <what> [options]   (tofnav evaluate <what> --help)\n\n";
  std::vector<Evaluator> sorted = Evaluators();
  std::sort(sorted.begin(), sorted.end(), [](const Evaluator& a, const Evaluator& b) {
    return std::string_view(a.name) < std::string_view(b.name);
  });
  for (const Evaluator& e : sorted) std::cout << "  " << e.name << "\t" << e.summary << "\n";
}

}  // namespace

void SimulatedRunArgs::AddOptions(CLI::App& app, const std::string& truth_help) {
  app.add_option("recording", recording, "the simulated recording")->required();
  app.add_option("--truth", truth_dir, truth_help)->required();
  app.add_option("--calibration", calibration, "calibration folder (unset: TRUTH/calibration)");
  app.add_option("--scenario", scenario_name, "scenario file or built-in (unset: truth.json's)");
  app.add_option("--max-frames", max_frames, "frames evaluated, evenly spread")
      ->check(CLI::PositiveNumber);
  app.add_flag("--json", json, "print JSON");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
}

AhatCamera SimulatedRunArgs::Camera() const {
  return AhatCamera(
      ReadHl2ssCalibration(calibration.empty() ? truth_dir / "calibration" : calibration));
}

std::unique_ptr<AhatRecording> SimulatedRunArgs::Open() const {
  return OpenAhatRecording(recording);
}

bool IsEvaluatorName(std::string_view name) {
  return std::any_of(Evaluators().begin(), Evaluators().end(),
                     [&](const Evaluator& e) { return e.name == name; });
}

bool RegisterEvaluator(const Evaluator& evaluator) {
  Evaluators().push_back(evaluator);
  return true;
}

int RunEvaluate(int argc, char** argv) {
  if (argc < 2 || std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h") {
    PrintUsage();
    return argc < 2 ? EXIT_FAILURE : EXIT_SUCCESS;
  }
  for (const Evaluator& e : Evaluators()) {
    if (std::string_view(e.name) == argv[1]) return e.run(argc - 1, argv + 1);
  }
  std::cerr << "tofnav evaluate: unknown evaluator '" << argv[1] << "'\n";
  PrintUsage();
  return EXIT_FAILURE;
}

}  // namespace tofnav
