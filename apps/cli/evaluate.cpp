// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate: dispatches to the registered evaluators (tracking, ...).
#include "evaluate.hpp"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string_view>
#include <vector>

#include "commands.hpp"

namespace tofnav {
namespace {

std::vector<Evaluator>& Evaluators() {
  // Filled during static initialisation (evaluate_<name>.cpp); "depth" is listed here.
  static std::vector<Evaluator> evaluators = {
      {"depth", "depth error per object before/after correction vs simulator truth",
       RunEvaluateDepth}};
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
