// SPDX-License-Identifier: BSD-3-Clause
// The sensor's cyclic range error from the f_rf stage recording: the plate the tape sits on,
// against the plane of its f_rf-corrected markers (docs/correction.md 2.8).
#pragma once

#include <vector>

#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/correction/plate_cyclic_error.hpp"
#include "tofnav/pipeline/marker_tasks.hpp"

namespace tofnav {

struct PlateSampleOptions {
  /// The plate: a disc of this radius around the markers' centroid in their plane [mm] (the
  /// largest circle the plate holds; > 0).
  double plate_radius_mm = 0.0;
  double edge_margin_mm = 10.0;   // left out inside the plate's edge: mixed pixels
  double marker_margin_mm = 8.0;  // left out beyond each tape's radius: its bloom and scatter
  int pixel_stride = 3;           // every n-th row and column
  double split_jump_mm = 20.0;    // a larger structure jump between posed frames starts a run
  void Check() const;             // throws std::invalid_argument naming the bad field
};

/// In every frame of `poses` with a raw pose (TrackTools of the stage's structure with f_rf and
/// the filter off: the plane of that frame's tape), samples the plate pixels' measured range
/// against the range of their ray to the markers' plane, one run per stage run. Frames whose
/// depth steps are coarser than 2 mm (SAME + H26x, lossy) give none.
std::vector<PlateRangeSample> CollectPlateSamples(const MarkerSource& source,
                                                  const std::vector<ToolPoseRecord>& poses,
                                                  const ToolGeometry& structure,
                                                  const PlateSampleOptions& options);

/// What frf.json keeps of a plate fit (MarkerRangeFile::cyclic_error).
StageCyclicErrorInfo StageCyclicErrorOf(const PlateCyclicFit& fit);

}  // namespace tofnav
