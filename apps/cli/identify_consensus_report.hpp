// SPDX-License-Identifier: BSD-3-Clause
// tofnav identify --consensus: the runs and the one kept, as JSON and as text.
#pragma once

#include <nlohmann/json.hpp>

#include "tofnav/pipeline/identify_consensus.hpp"

namespace tofnav {

/// The runs (each model's C1 at the kept one's references, C2-C4, final cost, distance to the
/// kept) and the kept run's index; an empty object without subsets.
nlohmann::ordered_json ConsensusToJson(const IdentifyConsensusResult& runs);
/// The same as lines on stdout, the kept run starred.
void PrintConsensus(const IdentifyConsensusResult& runs);

}  // namespace tofnav
