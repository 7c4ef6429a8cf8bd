// SPDX-License-Identifier: BSD-3-Clause
// Per-pixel surface normals and incidence angles of an AHAT range image, through the ray table.
#include "tofnav/correction/range_normals.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {
namespace {

// Neighbours within max(edge_abs_mm, edge_rel * centre) of the centre's range lie on its surface.
double EdgeTolerance(float centre_mm, const RangeNormalOptions& options) {
  return std::max(options.edge_abs_mm, options.edge_rel * centre_mm);
}

bool SameSurface(float centre_mm, float b_mm, double tolerance) {
  return b_mm > 0.0f && std::abs(static_cast<double>(centre_mm - b_mm)) <= tolerance;
}

// Edge-aware box mean at (u, v) over point-symmetric pairs of neighbours that are both on the
// centre's surface: the mean of a locally linear range stays exact next to an edge. 0 = invalid.
// Pixels whose window lies inside the image read it through precomputed offsets (the image's
// inner loop; the same pairs in the same order as at the border, so the same sum to the bit).
float SmoothedAt(const Image<float>& range_mm, int u, int v, const RangeNormalOptions& options) {
  const float centre = range_mm(u, v);
  const int r = options.smoothing_radius_px;
  if (centre <= 0.0f || r == 0) return centre;
  const double tolerance = EdgeTolerance(centre, options);
  double sum = centre;
  int count = 1;
  auto add_pair = [&](float a, float b) {
    if (!SameSurface(centre, a, tolerance) || !SameSurface(centre, b, tolerance)) return;
    sum += static_cast<double>(a) + b;
    count += 2;
  };
  const int w = range_mm.width();
  if (u >= r && v >= r && u + r < w && v + r < range_mm.height()) {
    const float* c = &range_mm(u, v);
    for (int dv = 0; dv <= r; ++dv) {
      for (int du = (dv == 0 ? 1 : -r); du <= r; ++du) {  // half of the window: one of each pair
        const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(dv) * w + du;
        add_pair(c[offset], c[-offset]);
      }
    }
    return static_cast<float>(sum / count);
  }
  auto at = [&](int uu, int vv) { return range_mm.Contains(uu, vv) ? range_mm(uu, vv) : 0.0f; };
  for (int dv = 0; dv <= r; ++dv) {
    for (int du = (dv == 0 ? 1 : -r); du <= r; ++du)
      add_pair(at(u + du, v + dv), at(u - du, v - dv));
  }
  return static_cast<float>(sum / count);
}

// Tangent along one image axis at (u, v) of the range `at(u, v)`: central difference when both
// neighbours are on the surface, else one-sided, else nothing.
template <typename RangeAt>
std::optional<Eigen::Vector3f> Tangent(const RangeAt& at, const AhatCamera& camera, int u, int v,
                                       int du, int dv, const RangeNormalOptions& options) {
  const float centre = at(u, v);
  const double tolerance = EdgeTolerance(centre, options);
  auto point = [&](int uu, int vv) -> std::optional<Eigen::Vector3f> {
    if (uu < 0 || vv < 0 || uu >= camera.width() || vv >= camera.height() ||
        !camera.IsValid(uu, vv)) {
      return std::nullopt;
    }
    const float d = at(uu, vv);
    if (!SameSurface(centre, d, tolerance)) return std::nullopt;
    return Eigen::Vector3f(camera.PixelRay(uu, vv) * d);
  };
  const std::optional<Eigen::Vector3f> plus = point(u + du, v + dv);
  const std::optional<Eigen::Vector3f> minus = point(u - du, v - dv);
  if (plus && minus) return *plus - *minus;
  const Eigen::Vector3f here = camera.PixelRay(u, v) * centre;
  if (plus) return *plus - here;
  if (minus) return here - *minus;
  return std::nullopt;
}

// Camera-facing unit normal at (u, v), or nothing.
template <typename RangeAt>
std::optional<Eigen::Vector3f> NormalAt(const RangeAt& at, const AhatCamera& camera, int u, int v,
                                        const RangeNormalOptions& options) {
  if (!camera.IsValid(u, v) || at(u, v) <= 0.0f) return std::nullopt;
  const int step = options.difference_step_px;
  const auto tu = Tangent(at, camera, u, v, step, 0, options);
  if (!tu) return std::nullopt;
  const auto tv = Tangent(at, camera, u, v, 0, step, options);
  if (!tv) return std::nullopt;
  Eigen::Vector3f n = tu->cross(*tv);
  const float norm = n.norm();
  if (!(norm > 0.0f)) return std::nullopt;
  n /= norm;
  if (n.dot(camera.PixelRay(u, v)) > 0.0f) n = -n;
  return n;
}

float Incidence(const Eigen::Vector3f& normal, const Eigen::Vector3f& ray) {
  return std::acos(std::min(1.0f, std::abs(normal.dot(ray))));
}

}  // namespace

void RangeNormalOptions::Check() const {
  if (smoothing_radius_px < 0 || smoothing_radius_px > 10) {
    throw std::invalid_argument("RangeNormalOptions::smoothing_radius_px must be in [0, 10]");
  }
  if (difference_step_px < 1 || difference_step_px > 10) {
    throw std::invalid_argument("RangeNormalOptions::difference_step_px must be in [1, 10]");
  }
  if (!(edge_abs_mm > 0.0) || !(edge_rel >= 0.0)) {
    throw std::invalid_argument("RangeNormalOptions: edge_abs_mm must be > 0, edge_rel >= 0");
  }
}

namespace {

// The normals of ComputeRangeNormals, and their incidence angles when `incidence_rad` is given.
Image<Eigen::Vector3f> NormalsOf(const Image<float>& range_mm, const AhatCamera& camera,
                                 const RangeNormalOptions& options, Image<float>* incidence_rad) {
  options.Check();
  if (range_mm.width() != camera.width() || range_mm.height() != camera.height()) {
    throw std::invalid_argument("ComputeRangeNormals: range image and camera sizes differ");
  }
  const int w = range_mm.width(), h = range_mm.height();
  Image<float> smooth(w, h);
  ParallelFor(0, h, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    for (int u = 0; u < w; ++u) smooth(u, v) = SmoothedAt(range_mm, u, v, options);
  });
  auto at = [&](int u, int v) { return smooth(u, v); };
  Image<Eigen::Vector3f> normal(w, h);
  if (incidence_rad) *incidence_rad = Image<float>(w, h, std::numeric_limits<float>::quiet_NaN());
  ParallelFor(0, h, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    for (int u = 0; u < w; ++u) {
      const std::optional<Eigen::Vector3f> n = NormalAt(at, camera, u, v, options);
      if (!n) continue;
      normal(u, v) = *n;
      if (incidence_rad) (*incidence_rad)(u, v) = Incidence(*n, camera.PixelRay(u, v));
    }
  });
  return normal;
}

}  // namespace

RangeNormals ComputeRangeNormals(const Image<float>& range_mm, const AhatCamera& camera,
                                 const RangeNormalOptions& options) {
  RangeNormals out;
  out.normal = NormalsOf(range_mm, camera, options, &out.incidence_rad);
  return out;
}

Image<Eigen::Vector3f> ComputeRangeNormalVectors(const Image<float>& range_mm,
                                                 const AhatCamera& camera,
                                                 const RangeNormalOptions& options) {
  return NormalsOf(range_mm, camera, options, nullptr);
}

Image<float> RangeAsFloat(const Image<std::uint16_t>& range_mm) {
  Image<float> out(range_mm.width(), range_mm.height());
  for (std::size_t i = 0; i < range_mm.size(); ++i) {
    const std::uint16_t code = range_mm.pixels()[i];
    out.pixels()[i] = (code == 0 || code >= kAhatInvalidRange) ? 0.0f : static_cast<float>(code);
  }
  return out;
}

std::optional<PixelNormal> ComputePixelNormal(const Image<float>& range_mm,
                                              const AhatCamera& camera, int u, int v,
                                              const RangeNormalOptions& options) {
  options.Check();
  if (!range_mm.Contains(u, v) || range_mm.width() != camera.width() ||
      range_mm.height() != camera.height()) {
    return std::nullopt;
  }
  auto at = [&](int uu, int vv) { return SmoothedAt(range_mm, uu, vv, options); };
  const std::optional<Eigen::Vector3f> n = NormalAt(at, camera, u, v, options);
  if (!n) return std::nullopt;
  return PixelNormal{*n, Incidence(*n, camera.PixelRay(u, v))};
}

}  // namespace tofnav
