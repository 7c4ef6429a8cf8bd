// SPDX-License-Identifier: BSD-3-Clause
// Per-pixel surface normals and incidence angles of an AHAT range image, through the ray table.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "tofnav/core/image.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

struct RangeNormalOptions {
  /// Half-width of the edge-aware range smoothing before differencing [px]; 0 = none.
  int smoothing_radius_px = 2;
  /// Pixel offset of the central differences [px] (larger: less noise, less detail).
  int difference_step_px = 2;
  /// Neighbours differ from the centre by more than max(edge_abs_mm, edge_rel * range) are across
  /// a depth edge: left out of the smoothing and of the differences.
  double edge_abs_mm = 8.0;
  double edge_rel = 0.03;  // dimensionless
  void Check() const;      // throws std::invalid_argument naming the bad field
};

struct RangeNormals {
  /// Unit normal in `ahat`, facing the camera (n . P < 0); zero where not computable (invalid
  /// range, invalid ray, or no valid neighbour pair in either direction).
  Image<Eigen::Vector3f> normal;
  /// theta = arccos(|n . P| / |P|) [rad]; NaN where the normal is zero.
  Image<float> incidence_rad;
};

/// Normals from a range image [mm] (0 = invalid): the range is smoothed over valid neighbours on
/// the same side of any depth edge, unprojected (d * ray) and differenced (central where both
/// neighbours are valid and on the same surface, one-sided otherwise); n = du x dv.
RangeNormals ComputeRangeNormals(const Image<float>& range_mm, const AhatCamera& camera,
                                 const RangeNormalOptions& options = {});
/// ComputeRangeNormals' normals alone, without the incidence angles (their arccos is a fifth of
/// the cost): for callers that need only the normals, such as the multipath removal.
Image<Eigen::Vector3f> ComputeRangeNormalVectors(const Image<float>& range_mm,
                                                 const AhatCamera& camera,
                                                 const RangeNormalOptions& options = {});

struct PixelNormal {
  Eigen::Vector3f normal;  // unit, facing the camera
  float incidence_rad = 0.0f;
};
/// The normal of one pixel exactly as ComputeRangeNormals gives it (smoothing evaluated on demand
/// around the pixel): for sparse samples; nullopt where ComputeRangeNormals gives none.
std::optional<PixelNormal> ComputePixelNormal(const Image<float>& range_mm,
                                              const AhatCamera& camera, int u, int v,
                                              const RangeNormalOptions& options = {});

/// The range image of a frame as float [mm] (codes 0 and >= kAhatInvalidRange become 0).
Image<float> RangeAsFloat(const Image<std::uint16_t>& range_mm);

}  // namespace tofnav
