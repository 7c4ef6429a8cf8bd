// SPDX-License-Identifier: BSD-3-Clause
// Damage of one bright blob: its shape (merged markers) and its surroundings (occluders, other
// blobs), from the AB and range images (docs/tracking.md section 6).
#pragma once

#include <Eigen/Core>
#include <span>

#include "tofnav/markers/bright_blobs.hpp"
#include "tofnav/markers/marker_detection.hpp"

namespace tofnav {

/// Mean pixel and length of a blob: 4 sqrt of the largest eigenvalue of its pixels' covariance
/// [px], the diameter of a uniform disc, the length of an ellipse's major axis.
struct BlobShape {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  double length_px = 0.0;
};
BlobShape MeasureBlobShape(std::span<const PixelRun> runs);

/// The blob is cut by the edge of the field: a blob pixel touches (8-neighbourhood) the image
/// border, a pixel without a valid ray, or a pixel outside the illumination (range code 4095 in
/// raw frames; AB 0 and range 0 in recordings, whose writers map codes >= 4090 to 0).
bool TouchesFieldEdge(const AhatFrame& frame, const AhatCamera& camera,
                      std::span<const PixelRun> runs);

/// Occluder and near-blob flags of a kept marker: the pixels within a few pixels of the blob
/// (Chebyshev distance), their AB against `threshold` (another blob) and their range against
/// the marker's surface range (something in front). `pitch_mm`: one pixel at the marker [mm].
MarkerDamage AssessRing(const AhatFrame& frame, const BrightBlob& blob,
                        std::span<const PixelRun> runs, double threshold, double surface_range_mm,
                        double pitch_mm, const MarkerDetectionOptions& options);

}  // namespace tofnav
