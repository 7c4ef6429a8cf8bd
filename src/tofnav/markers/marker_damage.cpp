// SPDX-License-Identifier: BSD-3-Clause
// Blob shape moments and the ring of pixels around a blob (docs/tracking.md section 6).
#include "tofnav/markers/marker_damage.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

namespace tofnav {
namespace {

// The sensor's code for a pixel outside its illumination (raw frames; recordings write 0).
constexpr std::uint16_t kOutsideIlluminationCode = 4095;
// tan(55 deg): the steepest tool plate around a marker that the occluder margin allows for. Tape
// seen more obliquely than its retro-reflection cut-off (55 deg) reflects nothing, and spheres
// stand on posts in front of their plate.
constexpr double kSteepestPlateSlope = 1.4281480067421144;

// Chebyshev distance (capped at `cap`) of every pixel of a w x h box to the blob pixels marked in
// `mask` (distance 0), by the two-pass chamfer transform with unit 8-neighbour steps.
std::vector<int> ChebyshevDistance(const std::vector<char>& mask, int w, int h, int cap) {
  std::vector<int> d(mask.size());
  for (std::size_t i = 0; i < mask.size(); ++i) d[i] = mask[i] ? 0 : cap;
  const auto at = [&](int u, int v) -> int& { return d[static_cast<std::size_t>(v * w + u)]; };
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      int& x = at(u, v);
      if (u > 0) x = std::min(x, at(u - 1, v) + 1);
      if (v > 0) {
        for (int du = -1; du <= 1; ++du) {
          if (u + du >= 0 && u + du < w) x = std::min(x, at(u + du, v - 1) + 1);
        }
      }
    }
  }
  for (int v = h - 1; v >= 0; --v) {
    for (int u = w - 1; u >= 0; --u) {
      int& x = at(u, v);
      if (u + 1 < w) x = std::min(x, at(u + 1, v) + 1);
      if (v + 1 < h) {
        for (int du = -1; du <= 1; ++du) {
          if (u + du >= 0 && u + du < w) x = std::min(x, at(u + du, v + 1) + 1);
        }
      }
    }
  }
  return d;
}

}  // namespace

BlobShape MeasureBlobShape(std::span<const PixelRun> runs) {
  double n = 0.0, su = 0.0, sv = 0.0, suu = 0.0, svv = 0.0, suv = 0.0;
  for (const PixelRun& r : runs) {
    for (int u = r.u_begin; u < r.u_end; ++u) {
      n += 1.0;
      su += u;
      sv += r.v;
      suu += static_cast<double>(u) * u;
      svv += static_cast<double>(r.v) * r.v;
      suv += static_cast<double>(u) * r.v;
    }
  }
  BlobShape shape;
  if (n == 0.0) return shape;
  shape.mean = {su / n, sv / n};
  Eigen::Matrix2d cov;
  cov(0, 0) = suu / n - shape.mean.x() * shape.mean.x();
  cov(1, 1) = svv / n - shape.mean.y() * shape.mean.y();
  cov(0, 1) = cov(1, 0) = suv / n - shape.mean.x() * shape.mean.y();
  // A pixel is a unit square, not a point: its own variance 1/12 per axis.
  cov += Eigen::Matrix2d::Identity() / 12.0;
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvalues()(1);
  shape.length_px = 4.0 * std::sqrt(std::max(largest, 0.0));
  return shape;
}

// Fraction of the image's half-size within which the AHAT illumination is always lit.
constexpr double kLitFieldInnerFraction = 0.8;

bool TouchesFieldEdge(const AhatFrame& frame, const AhatCamera& camera,
                      std::span<const PixelRun> runs) {
  // An unlit pixel is the edge of the lit field only towards the image's rim: nearer the centre
  // it is a background beyond the range limit (an instrument held against the room), and a
  // marker against it is whole (docs/tracking.md section 6).
  const double cx = 0.5 * frame.ab.width(), cy = 0.5 * frame.ab.height();
  const double inner_radius_px = kLitFieldInnerFraction * std::min(cx, cy);
  const auto outside = [&](int u, int v) {
    if (!frame.ab.Contains(u, v) || !camera.IsValid(u, v)) return true;
    const double du = u - cx, dv = v - cy;
    if (du * du + dv * dv < inner_radius_px * inner_radius_px) return false;
    const std::uint16_t range = frame.range_mm(u, v);
    return range == kOutsideIlluminationCode || (range == 0 && frame.ab(u, v) == 0);
  };
  for (const PixelRun& r : runs) {
    for (int u = r.u_begin; u < r.u_end; ++u) {
      if (!camera.IsValid(u, r.v)) continue;  // inside a hole of the ray table: not an edge
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          if (outside(u + du, r.v + dv)) return true;
        }
      }
    }
  }
  return false;
}

MarkerDamage AssessRing(const AhatFrame& frame, const BrightBlob& blob,
                        std::span<const PixelRun> runs, double threshold, double surface_range_mm,
                        double pitch_mm, const MarkerDetectionOptions& options) {
  const int reach = std::max(options.occluder_ring_outer_px, options.near_blob_gap_px + 1);
  const int u0 = std::max(0, blob.u_min - reach), v0 = std::max(0, blob.v_min - reach);
  const int u1 = std::min(frame.ab.width() - 1, blob.u_max + reach);
  const int v1 = std::min(frame.ab.height() - 1, blob.v_max + reach);
  const int w = u1 - u0 + 1, h = v1 - v0 + 1;
  std::vector<char> mask(static_cast<std::size_t>(w * h), 0);
  for (const PixelRun& r : runs) {
    for (int u = r.u_begin; u < r.u_end; ++u) {
      mask[static_cast<std::size_t>((r.v - v0) * w + (u - u0))] = 1;
    }
  }
  const std::vector<int> distance = ChebyshevDistance(mask, w, h, reach + 1);
  MarkerDamage damage;
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      const int d = distance[static_cast<std::size_t>((v - v0) * w + (u - u0))];
      if (d == 0 || d > reach) continue;
      if (frame.ab(u, v) >= threshold) {  // another blob (8-connected pixels would be ours)
        if (d <= options.near_blob_gap_px + 1) damage.near_blob = true;
        continue;
      }
      if (d < options.occluder_ring_inner_px || d > options.occluder_ring_outer_px) continue;
      const std::uint16_t range = frame.range_mm(u, v);
      if (range == 0 || range >= kAhatInvalidRange) continue;
      ++damage.ring_px;
      const double margin_mm = options.occluder_margin_mm + d * pitch_mm * kSteepestPlateSlope;
      if (range < surface_range_mm - margin_mm) ++damage.occluder_px;
    }
  }
  damage.occluded = damage.occluder_px >= options.min_occluder_px;
  return damage;
}

}  // namespace tofnav
