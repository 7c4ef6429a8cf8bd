// SPDX-License-Identifier: BSD-3-Clause
// `tofnav evaluate <what>`: evaluators register themselves, one file each.
#pragma once

namespace tofnav {

struct Evaluator {
  const char* name;                   // `tofnav evaluate <name>`
  const char* summary;                // one line for the usage
  int (*run)(int argc, char** argv);  // argv[0] is "<name>"
};

/// Adds an evaluator to `tofnav evaluate`. Call it from a namespace-scope initialiser of the
/// evaluator's own file (adding an evaluator = one new file in apps/cli/CMakeLists.txt):
///   [[maybe_unused]] const bool kRegistered = RegisterEvaluator({"depth", "...", RunDepth});
bool RegisterEvaluator(const Evaluator& evaluator);

}  // namespace tofnav
