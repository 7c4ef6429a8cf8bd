// SPDX-License-Identifier: BSD-3-Clause
// MarkerVoidTest: a marker the pose puts in front of a far, dark surface is not there.
#include "tofnav/markers/marker_void.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {

void MarkerVoidOptions::Check() const {
  Require(ab_threshold > 0.0, "MarkerVoidOptions::ab_threshold must be > 0");
  Require(behind_margin_mm > 0.0, "MarkerVoidOptions::behind_margin_mm must be > 0");
  Require(min_valid_fraction > 0.0 && min_valid_fraction <= 1.0,
          "MarkerVoidOptions::min_valid_fraction must be in (0, 1]");
  Require(in_front_margin_mm >= 0.0, "MarkerVoidOptions::in_front_margin_mm must be >= 0");
  Require(max_in_front_fraction >= 0.0 && max_in_front_fraction < 1.0,
          "MarkerVoidOptions::max_in_front_fraction must be in [0, 1)");
  Require(pad_px >= 0.0, "MarkerVoidOptions::pad_px must be >= 0");
}

MarkerVoidTest::MarkerVoidTest(const AhatFrame& frame, const AhatCamera& camera,
                               const MarkerVoidOptions& options)
    : frame_(frame), camera_(camera), options_(options) {
  options_.Check();
}

MarkerVoidTest::MarkerVoidTest(const AhatFrame& frame, const AhatCamera& camera,
                               double detector_ab_threshold)
    : MarkerVoidTest(frame, camera, [&] {
        MarkerVoidOptions options;
        if (detector_ab_threshold > 0.0) options.ab_threshold = detector_ab_threshold;
        return options;
      }()) {}

bool MarkerVoidTest::IsVoid(const Eigen::Vector3d& centre_in_ahat,
                            double marker_diameter_mm) const {
  const double range_mm = centre_in_ahat.norm();
  if (!(range_mm > 0.0) || !centre_in_ahat.allFinite()) return false;
  const std::optional<Eigen::Vector2d> centre_px = camera_.Project(centre_in_ahat);
  if (!centre_px) return false;
  // The disc's radius in pixels: project a point one marker radius aside, across the ray.
  const double radius_mm = 0.5 * marker_diameter_mm;
  const Eigen::Vector3d across = centre_in_ahat.unitOrthogonal();
  const std::optional<Eigen::Vector2d> rim_px =
      camera_.Project(centre_in_ahat + radius_mm * across);
  if (!rim_px) return false;
  const double radius_px = (*rim_px - *centre_px).norm() + options_.pad_px;
  const Image<std::uint16_t>& range = frame_.range_mm;
  const Image<std::uint16_t>& ab = frame_.ab;
  if (ab.width() != range.width() || ab.height() != range.height()) return false;
  const int u0 = static_cast<int>(std::floor((*centre_px)(0) - radius_px));
  const int u1 = static_cast<int>(std::ceil((*centre_px)(0) + radius_px));
  const int v0 = static_cast<int>(std::floor((*centre_px)(1) - radius_px));
  const int v1 = static_cast<int>(std::ceil((*centre_px)(1) + radius_px));
  // A disc that leaves the image cannot be judged: part of it may be the marker.
  if (!range.Contains(u0, v0) || !range.Contains(u1, v1)) return false;
  std::vector<double> valid;
  int pixels = 0, in_front = 0;
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      if ((Eigen::Vector2d(u, v) - *centre_px).norm() > radius_px) continue;
      ++pixels;
      if (ab(u, v) >= options_.ab_threshold) return false;  // something bright: maybe the marker
      const double r = range(u, v);
      if (r <= 0.0) continue;
      valid.push_back(r);
      if (r < range_mm - radius_mm - options_.in_front_margin_mm) ++in_front;
    }
  }
  if (pixels == 0) return false;
  const double valid_count = static_cast<double>(valid.size());
  if (valid_count < options_.min_valid_fraction * pixels) return false;
  if (in_front > options_.max_in_front_fraction * valid_count) return false;  // hidden
  auto mid = valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2);
  std::nth_element(valid.begin(), mid, valid.end());
  return *mid >= range_mm + options_.behind_margin_mm;
}

}  // namespace tofnav
