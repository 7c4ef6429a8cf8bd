// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate: one evaluator per file (evaluate_<name>.cpp), chosen by the first argument.
#include <cstdlib>
#include <iostream>
#include <string_view>

#include "commands.hpp"

namespace tofnav {

int RunEvaluate(int argc, char** argv) {
  struct Evaluator {
    std::string_view name, summary;
    int (*run)(int, char**);
  };
  constexpr Evaluator kEvaluators[] = {
      {"depth", "depth error per object before/after correction vs simulator truth",
       RunEvaluateDepth},
  };
  if (argc >= 2) {
    for (const Evaluator& e : kEvaluators) {
      if (e.name == argv[1]) return e.run(argc - 1, argv + 1);
    }
  }
  std::cerr << "usage: tofnav evaluate <evaluator> [options]\n";
  for (const Evaluator& e : kEvaluators) std::cerr << "  " << e.name << "\t" << e.summary << "\n";
  return argc >= 2 && (std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h")
             ? EXIT_SUCCESS
             : EXIT_FAILURE;
}

}  // namespace tofnav
