// SPDX-License-Identifier: BSD-3-Clause
// The --consensus and --consensus-medoid flags shared by demo and evaluate suite.
#pragma once

#include <CLI/CLI.hpp>
#include <iostream>
#include <string>

namespace tofnav {

/// What the two flags ask: keep a consensus of the stability runs, and whether it is the medoid
/// (docs/correction.md 2.9) rather than the runs' weighted mean (the default, 2.16).
struct ConsensusFlags {
  bool consensus = false;
  bool medoid = false;
};

inline void AddConsensusOptions(CLI::App& app, ConsensusFlags& flags) {
  app.add_flag("--consensus", flags.consensus,
               "with --stability N >= 2: keep the consensus of the full identification and the "
               "N runs (their weighted mean; docs/correction.md 2.9, 2.16), not the full one");
  app.add_flag("--consensus-medoid", flags.medoid,
               "with --consensus: keep the runs' medoid, not their weighted mean (the default "
               "since session 58: the mean moves less when a run is left out; "
               "docs/correction.md 2.16); both are reported either way");
}

/// False, after one line on stderr prefixed with `command`, when the flags cannot hold: a
/// consensus needs two stability runs, the medoid a consensus.
inline bool CheckConsensusOptions(const ConsensusFlags& flags, int stability_subsets,
                                  const std::string& command) {
  if (flags.consensus && stability_subsets < 2) {
    std::cerr << command
              << ": --consensus needs --stability 2 or more (the medoid of the full run and "
                 "those runs)\n";
    return false;
  }
  if (flags.medoid && !flags.consensus) {
    std::cerr << command << ": --consensus-medoid needs --consensus (the runs to choose from)\n";
    return false;
  }
  return true;
}

}  // namespace tofnav
