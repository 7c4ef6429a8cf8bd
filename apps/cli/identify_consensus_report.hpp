// SPDX-License-Identifier: BSD-3-Clause
// tofnav identify --consensus: the runs and the one kept, as JSON and as text.
#pragma once

#include <nlohmann/json.hpp>

#include "tofnav/pipeline/identify_consensus.hpp"

namespace tofnav {

/// The runs (each model's C1 at the medoid's references, C2-C4, final cost, distance to the
/// medoid), the medoid's index and the runs' ConsensusMean (its coefficients, distance to the
/// medoid, jackknife, and whether it was kept: `mean_kept`); an empty object without subsets.
nlohmann::ordered_json ConsensusToJson(const IdentifyConsensusResult& runs, bool mean_kept);
/// The same as lines on stdout, the kept model starred.
void PrintConsensus(const IdentifyConsensusResult& runs, bool mean_kept);

}  // namespace tofnav
