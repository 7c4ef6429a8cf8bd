// SPDX-License-Identifier: BSD-3-Clause
// Fast point -> pixel lookup for the TSDF kernel, built from the camera's pixel rays.
#include "tofnav/fusion/pixel_lookup.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr int kMaxNodesPerSide = 2048;     // bounds the table (32 MB) for any calibration
constexpr double kInsideTolerance = 1e-9;  // barycentric slack, so shared triangle edges are hit

// The table is built from 2 x 262144 triangles: plain doubles and loops rather than Eigen keep
// that fast in unoptimised test builds.

/// A valid pixel's ray on the stereographic plane.
struct PlanePosition {
  double a = 0.0, b = 0.0;
  bool valid = false;
};

/// Node grid over the plane: node (i, j) sits at (min_a + i step, min_b + j step).
struct NodeGrid {
  double min_a, min_b, step;
  int width, height;
};

/// Writes into `nodes` the pixel position of every node inside the triangle of pixels
/// (u_k, v_k) with plane positions p_k, by barycentric interpolation.
void Rasterise(const NodeGrid& grid, const PlanePosition* p[3], const double u[3],
               const double v[3], Image<PixelLookup::Position>& nodes) {
  const double e1a = p[1]->a - p[0]->a, e1b = p[1]->b - p[0]->b;
  const double e2a = p[2]->a - p[0]->a, e2b = p[2]->b - p[0]->b;
  const double det = e1a * e2b - e1b * e2a;
  if (std::abs(det) < 1e-18) return;
  double lo_a = p[0]->a, hi_a = p[0]->a, lo_b = p[0]->b, hi_b = p[0]->b;
  for (int k = 1; k < 3; ++k) {
    lo_a = std::min(lo_a, p[k]->a), hi_a = std::max(hi_a, p[k]->a);
    lo_b = std::min(lo_b, p[k]->b), hi_b = std::max(hi_b, p[k]->b);
  }
  const int i0 = std::max(0, static_cast<int>(std::ceil((lo_a - grid.min_a) / grid.step)));
  const int j0 = std::max(0, static_cast<int>(std::ceil((lo_b - grid.min_b) / grid.step)));
  const int i1 =
      std::min(grid.width - 1, static_cast<int>(std::floor((hi_a - grid.min_a) / grid.step)));
  const int j1 =
      std::min(grid.height - 1, static_cast<int>(std::floor((hi_b - grid.min_b) / grid.step)));
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const double da = grid.min_a + grid.step * i - p[0]->a;
      const double db = grid.min_b + grid.step * j - p[0]->b;
      const double w1 = (da * e2b - db * e2a) / det;
      const double w2 = (e1a * db - e1b * da) / det;
      if (w1 < -kInsideTolerance || w2 < -kInsideTolerance || w1 + w2 > 1.0 + kInsideTolerance) {
        continue;
      }
      nodes(i, j) = {static_cast<float>(u[0] + w1 * (u[1] - u[0]) + w2 * (u[2] - u[0])),
                     static_cast<float>(v[0] + w1 * (v[1] - v[0]) + w2 * (v[2] - v[0]))};
    }
  }
}

}  // namespace

PixelLookup::PixelLookup(const AhatCamera& camera, double node_step_px)
    : image_width_(camera.width()), image_height_(camera.height()) {
  Require(node_step_px > 0.0 && node_step_px <= 16.0,
          "PixelLookup: node_step_px must be in (0, 16]");
  const int w = image_width_, h = image_height_;
  std::vector<PlanePosition> plane(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  double lo_a = INFINITY, lo_b = INFINITY, hi_a = -INFINITY, hi_b = -INFINITY;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (!camera.IsValid(u, v)) continue;
      const Eigen::Vector3f& ray = camera.PixelRay(u, v);  // unit: z + |ray| = z + 1
      const double x = ray.x(), y = ray.y(), z = ray.z();
      const double scale = 1.0 / (z + std::sqrt(x * x + y * y + z * z));
      PlanePosition& p = plane[static_cast<std::size_t>(v * w + u)];
      p = {scale * x, scale * y, true};
      lo_a = std::min(lo_a, p.a), lo_b = std::min(lo_b, p.b);
      hi_a = std::max(hi_a, p.a), hi_b = std::max(hi_b, p.b);
    }
  }
  Require(lo_a <= hi_a && lo_b <= hi_b, "PixelLookup: the camera has no valid pixel");
  // The finest pixel spacing on the plane (at the image centre for a fisheye) sets the step.
  double min_spacing = INFINITY;
  for (int v = 0; v + 1 < h; ++v) {
    for (int u = 0; u + 1 < w; ++u) {
      const PlanePosition& c = plane[static_cast<std::size_t>(v * w + u)];
      const PlanePosition& right = plane[static_cast<std::size_t>(v * w + u + 1)];
      const PlanePosition& below = plane[static_cast<std::size_t>((v + 1) * w + u)];
      if (c.valid && right.valid)
        min_spacing = std::min(min_spacing, std::hypot(right.a - c.a, right.b - c.b));
      if (c.valid && below.valid)
        min_spacing = std::min(min_spacing, std::hypot(below.a - c.a, below.b - c.b));
    }
  }
  const double extent = std::max(hi_a - lo_a, hi_b - lo_b);
  double step = std::isfinite(min_spacing) ? min_spacing * node_step_px : extent;
  step = std::max({step, extent / (kMaxNodesPerSide - 2), 1e-9});
  const NodeGrid grid{lo_a, lo_b, step, static_cast<int>(std::ceil((hi_a - lo_a) / step)) + 2,
                      static_cast<int>(std::ceil((hi_b - lo_b) / step)) + 2};
  nodes_ = Image<Position>(grid.width, grid.height, Position{kNaN, kNaN});
  min_a_ = static_cast<float>(lo_a);
  min_b_ = static_cast<float>(lo_b);
  inverse_step_ = static_cast<float>(1.0 / step);
  max_index_a_ = static_cast<float>(grid.width - 1);
  max_index_b_ = static_cast<float>(grid.height - 1);

  // Two triangles per square of four valid pixels (a piecewise-linear inverse of the ray mesh).
  for (int v = 0; v + 1 < h; ++v) {
    for (int u = 0; u + 1 < w; ++u) {
      const PlanePosition* q00 = &plane[static_cast<std::size_t>(v * w + u)];
      const PlanePosition* q10 = q00 + 1;
      const PlanePosition* q01 = q00 + w;
      const PlanePosition* q11 = q01 + 1;
      if (!q00->valid || !q10->valid || !q01->valid || !q11->valid) continue;
      const double u0 = u, u1 = u + 1, v0 = v, v1 = v + 1;
      const PlanePosition* first[3] = {q00, q10, q11};
      const double first_u[3] = {u0, u1, u1}, first_v[3] = {v0, v0, v1};
      Rasterise(grid, first, first_u, first_v, nodes_);
      const PlanePosition* second[3] = {q00, q11, q01};
      const double second_u[3] = {u0, u1, u0}, second_v[3] = {v0, v1, v1};
      Rasterise(grid, second, second_u, second_v, nodes_);
    }
  }
}

std::optional<Eigen::Vector2d> PixelLookup::Project(const Eigen::Vector3d& point_in_ahat) const {
  const Eigen::Vector3f p = point_in_ahat.cast<float>();
  const Position position = table().Lookup(p.x(), p.y(), p.z(), p.norm());
  if (!(position.u >= 0.0f && position.v >= 0.0f)) return std::nullopt;
  return Eigen::Vector2d(position.u, position.v);
}

}  // namespace tofnav
