// SPDX-License-Identifier: BSD-3-Clause
// Fast point -> pixel lookup for the TSDF kernel: a dense inverse of the AHAT ray table.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "tofnav/core/image.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

/// The inverse of the camera's pixel rays as a table, for the one loop that projects a million
/// voxels per frame. AhatCamera::Project inverts the calibration table by Newton iterations
/// (about a microsecond per point); here a projection is a division, a bounds check and a bilinear
/// fetch of four table nodes, which keeps fusion at a few ns per voxel. This is the only camera
/// code outside sensor/, and it is built from the camera's own pixel rays.
///
/// Nodes lie on the stereographic plane (x, y) / (z + |p|) = tan(theta / 2) (cos phi, sin phi),
/// where a fisheye's pixels are nearly uniform (spacing within 1.4x from centre to edge) and the
/// coordinate needs no trigonometry, only |p|, which the kernel computes anyway. Each node holds
/// the sub-pixel position (u, v) that sees it, from a piecewise-linear inverse of the pixel-ray
/// mesh (two triangles per square of four valid pixels); NaN outside the valid region.
class PixelLookup {
 public:
  struct Position {  // sub-pixel (u, v) [px]; NaN when no valid pixel sees the point
    float u;
    float v;
  };
  static constexpr float kNaN = __builtin_nanf("");

  /// @param node_step_px  node spacing in pixels at the image centre (dimensionless)
  explicit PixelLookup(const AhatCamera& camera, double node_step_px = 1.0);

  /// The table as plain values, to copy into a hot loop's locals (a member read after every
  /// store through another pointer would have to be reloaded).
  struct Table {
    const Position* nodes;
    int stride;          // nodes per row
    float min_a, min_b;  // plane coordinates of node (0, 0)
    float inverse_step;  // nodes per unit of the plane
    float max_a, max_b;  // node grid width - 1 and height - 1

    /// Sub-pixel position that sees the point (x, y, z) in `ahat` with norm `range_mm`.
    /// Positions are within [0, width - 1] x [0, height - 1]; test validity with `u >= 0`.
    Position Lookup(float x, float y, float z, float range_mm) const {
      const float s = 1.0f / (z + range_mm);
      const float a = (x * s - min_a) * inverse_step;
      const float b = (y * s - min_b) * inverse_step;
      // The comparisons are false for NaN and infinity (a point at the origin or behind it).
      if (!(a >= 0.0f && b >= 0.0f && a < max_a && b < max_b)) return {kNaN, kNaN};
      const int ia = static_cast<int>(a);
      const int ib = static_cast<int>(b);
      const float fa = a - static_cast<float>(ia);
      const float fb = b - static_cast<float>(ib);
      const Position* n = nodes + ib * stride + ia;
      const Position* m = n + stride;
      const float u0 = n[0].u + fa * (n[1].u - n[0].u);
      const float u1 = m[0].u + fa * (m[1].u - m[0].u);
      const float v0 = n[0].v + fa * (n[1].v - n[0].v);
      const float v1 = m[0].v + fa * (m[1].v - m[0].v);
      return {u0 + fb * (u1 - u0), v0 + fb * (v1 - v0)};
    }
  };
  Table table() const {
    return {nodes_.data(), nodes_.width(), min_a_,      min_b_,
            inverse_step_, max_index_a_,   max_index_b_};
  }

  /// Convenience form of Lookup for one point (tests, diagnostics); nullopt outside.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point_in_ahat) const;

 private:
  Image<Position> nodes_;
  int image_width_ = 0;
  int image_height_ = 0;
  float min_a_ = 0.0f;
  float min_b_ = 0.0f;
  float inverse_step_ = 1.0f;  // nodes per unit of the stereographic plane
  float max_index_a_ = 0.0f;   // width - 1 of the node grid: a must stay below it
  float max_index_b_ = 0.0f;
};

}  // namespace tofnav
