// SPDX-License-Identifier: BSD-3-Clause
// A depth model applied in reconstruction: Eq. (4) on the surface pixels and its f_rf on the
// tool's markers (`tofnav reconstruct --depth-model`, the demo's reconstruction stage).
#pragma once

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/correction/correct_range.hpp"
#include "tofnav/pipeline/reconstruct.hpp"

namespace tofnav {

/// Sets options.correct_range to CorrectRangeImage with file.model (its range gates and marker
/// mask taken from `options`), and options.marker_error to file.marker_range when present.
void UseDepthModel(const DepthModelFile& file, ReconstructOptions& options,
                   CorrectRangeOptions correct = {});

}  // namespace tofnav
