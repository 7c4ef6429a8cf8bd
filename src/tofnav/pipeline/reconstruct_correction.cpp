// SPDX-License-Identifier: BSD-3-Clause
// A depth model applied in reconstruction.
#include "tofnav/pipeline/reconstruct_correction.hpp"

namespace tofnav {

void UseDepthModel(const DepthModelFile& file, ReconstructOptions& options,
                   CorrectRangeOptions correct) {
  if (file.marker_range) options.marker_error = *file.marker_range;
  correct.segmentation.min_range_mm = options.tsdf.min_range_mm;
  correct.segmentation.max_range_mm = options.tsdf.max_range_mm;
  correct.segmentation.transition_dilation_px = options.marker_mask_dilation_px;
  correct.segmentation.head_region = options.head_region;
  options.correct_range = [model = file.model, correct](const AhatFrame& frame,
                                                        const AhatCamera& camera) {
    CorrectedFrame corrected = CorrectFrame(frame, camera, model, correct);
    return CorrectedRange{std::move(corrected.range_mm), std::move(corrected.indirect_ratio)};
  };
}

}  // namespace tofnav
