// SPDX-License-Identifier: BSD-3-Clause
// `tofnav evaluate <what>`: evaluators register themselves, one file each.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>

#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

struct Evaluator {
  const char* name;                   // `tofnav evaluate <name>`
  const char* summary;                // one line for the usage
  int (*run)(int argc, char** argv);  // argv[0] is "<name>"
};

/// Adds an evaluator to `tofnav evaluate`. Call it from a namespace-scope initialiser of the
/// evaluator's own file (adding an evaluator = one new file in apps/cli/CMakeLists.txt):
///   [[maybe_unused]] const bool kRegistered = RegisterEvaluator({"depth", "...", RunDepth});
/// The file must be a source of the tofnav executable itself: in a static library the linker
/// would drop the unreferenced object and its registration with it.
bool RegisterEvaluator(const Evaluator& evaluator);

/// The options every evaluator of a simulated recording shares: the recording, --truth,
/// --calibration (unset: TRUTH/calibration), --scenario, --max-frames, --json, -q.
struct SimulatedRunArgs {
  std::filesystem::path recording, truth_dir, calibration;
  std::string scenario_name;
  int max_frames = 60;
  bool json = false, quiet = false;

  void AddOptions(CLI::App& app, const std::string& truth_help);
  AhatCamera Camera() const;  // from --calibration, else TRUTH/calibration
  std::unique_ptr<AhatRecording> Open() const;
};

}  // namespace tofnav
