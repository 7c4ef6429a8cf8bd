// SPDX-License-Identifier: BSD-3-Clause
// Truncated marker blobs: the centroid shift of a disc cut by a chord, the area deficit
// against the tool's other blobs (docs/tracking.md 6).
#include "tofnav/tracking/blob_truncation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "tofnav/core/require.hpp"
#include "tofnav/core/statistics.hpp"

namespace tofnav {
namespace {

constexpr double kSamePlateCosine = 0.99;    // markers whose plate normals agree share a plate
constexpr double kMinIncidenceCosine = 0.2;  // grazing discs: the area's cosine is not trusted

// Area of the cap of the unit disc beyond the chord at distance h from its centre.
double CapArea(double h) { return std::acos(h) - h * std::sqrt(1.0 - h * h); }

}  // namespace

void BlobTruncationOptions::Check() const {
  Require(area_ratio_sd >= 0.0 && damaged_grace_sds >= 0.0 && whole_grace_sds >= 0.0,
          "BlobTruncationOptions: area_ratio_sd and the grace sds must be >= 0");
}

double TruncatedDiscCentroidShift(double visible_fraction) {
  if (!(visible_fraction < 1.0)) return 0.0;
  const double a = std::max(visible_fraction, 1e-3);
  // The hidden cap's area pi (1 - a) falls from pi to 0 as h goes from -1 to 1: bisection.
  const double cap = std::numbers::pi * (1.0 - a);
  double lo = -1.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double h = 0.5 * (lo + hi);
    (CapArea(h) > cap ? lo : hi) = h;
  }
  const double h = 0.5 * (lo + hi);
  // The cap's first moment about the centre is (2/3)(1 - h^2)^(3/2); the visible part's centroid
  // lies that moment over its area on the other side.
  return (2.0 / 3.0) * std::pow(1.0 - h * h, 1.5) / (std::numbers::pi * a);
}

std::vector<double> TruncationLateralSigmasMm(std::span<const DetectedMarker> detections,
                                              std::span<const int> marker_detection,
                                              const ToolGeometry& tool, const Points3d& centres,
                                              const Rigid3d& ahat_from_tool,
                                              const BlobTruncationOptions& options) {
  const std::size_t n = marker_detection.size();
  std::vector<double> sigmas(n, 0.0);
  if (!options.enabled) return sigmas;
  const bool disc = tool.marker_type == MarkerType::kDisc;
  std::vector<Eigen::Vector3d> normals(n, Eigen::Vector3d::UnitZ());
  if (disc) {
    const std::vector<MarkerPlate> plates = MarkerPlates(tool);
    for (std::size_t k = 0; k < n && k < plates.size(); ++k) normals[k] = plates[k].normal_in_tool;
  }
  // Each matched blob's area scaled to a common range (and, for discs, to face-on).
  std::vector<double> area(n, -1.0);
  for (std::size_t k = 0; k < n; ++k) {
    if (marker_detection[k] < 0) continue;
    const auto i = static_cast<std::size_t>(marker_detection[k]);
    if (!(detections[i].pixel_pitch_rad > 0.0) || detections[i].area_px <= 0) continue;  // no blob
    const Eigen::Vector3d& c = centres[i];
    double scaled = detections[i].area_px * c.squaredNorm();
    if (disc) {
      const double cosine = std::abs((ahat_from_tool.rotation * normals[k]).dot(c.normalized()));
      if (cosine < kMinIncidenceCosine) continue;
      scaled /= cosine;
    }
    area[k] = scaled;
  }
  const double radius_mm = 0.5 * tool.marker_diameter_mm;
  for (std::size_t k = 0; k < n; ++k) {
    if (area[k] < 0.0) continue;
    std::vector<double> siblings;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == k || area[j] < 0.0) continue;
      if (disc && std::abs(normals[j].dot(normals[k])) < kSamePlateCosine) continue;
      siblings.push_back(area[j]);
    }
    if (siblings.size() < 2) continue;
    const double reference = Median(siblings);
    if (!(reference > 0.0)) continue;
    const bool damaged = detections[static_cast<std::size_t>(marker_detection[k])].damage.Any();
    const double grace =
        options.area_ratio_sd * (damaged ? options.damaged_grace_sds : options.whole_grace_sds);
    sigmas[k] = radius_mm * TruncatedDiscCentroidShift(area[k] / reference + grace);
  }
  return sigmas;
}

}  // namespace tofnav
