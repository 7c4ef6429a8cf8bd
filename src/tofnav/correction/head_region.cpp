// SPDX-License-Identifier: BSD-3-Clause
// Automatic head region of one AHAT range image: large planes and flat or small parts removed.
#include "tofnav/correction/head_region.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"

namespace tofnav {
namespace {

struct GridPoint {
  Eigen::Vector3f p;
  int u = 0, v = 0;
};

struct Plane {
  Eigen::Vector3f n = Eigen::Vector3f::UnitZ();    // unit
  float d = 0.0f;                                  // n . p + d = 0
  Eigen::Vector3f seed = Eigen::Vector3f::Zero();  // the hypothesis' first point
  float Distance(const Eigen::Vector3f& p) const { return std::abs(n.dot(p) + d); }
};

// Solid angle of one pixel near the image centre [sr]: area of a pixel at range r ~ r^2 omega.
double PixelSolidAngle(const AhatCamera& camera) {
  const int u = camera.width() / 2, v = camera.height() / 2;
  if (!camera.IsValid(u, v) || !camera.IsValid(u + 1, v) || !camera.IsValid(u, v + 1)) {
    return 1.0 / (220.0 * 220.0);
  }
  const Eigen::Vector3f r = camera.PixelRay(u, v);
  return static_cast<double>((camera.PixelRay(u + 1, v) - r).norm() *
                             (camera.PixelRay(u, v + 1) - r).norm());
}

// Least-squares plane through points (PCA).
std::optional<Plane> FitPlane(const std::vector<Eigen::Vector3f>& points) {
  if (points.size() < 3) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) mean += p.cast<double>();
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d d = p.cast<double>() - mean;
    cov += d * d.transpose();
  }
  const auto eig = DecomposeSymmetric(cov);
  const Eigen::Vector3d n = eig.vectors.col(0);
  return Plane{n.cast<float>(), static_cast<float>(-n.dot(mean))};
}

// Small deterministic generator (the same sequence on every platform).
struct Lcg {
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  std::size_t Next(std::size_t n) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<std::size_t>((state >> 33) % n);
  }
};

struct PlaneSearch {
  double tolerance_mm, min_area_mm2, min_flat_ratio;
  int iterations;
  double ball_mm;  // > 0: judged and removed within this distance of the seed point only
};

// The flat plane with the most grid points within the tolerance, its points within 3 x tolerance
// being mostly within tolerance (a slab through a curved surface is not), covering min_area_mm2;
// or nullopt. Hypotheses from a point and two grid neighbours (a plate is a small share of the
// frame: three points drawn anywhere would rarely all lie on it).
std::optional<Plane> FindFlatPlane(const std::vector<GridPoint>& grid, const Image<int>& index,
                                   int stride, double cell_omega, const PlaneSearch& search,
                                   Lcg& rng) {
  if (grid.size() < 50) return std::nullopt;
  const auto tol = static_cast<float>(search.tolerance_mm);
  constexpr int kReachCells = 6;
  auto neighbour = [&](const GridPoint& g) -> const GridPoint* {
    for (int tries = 0; tries < 8; ++tries) {
      const int u = g.u / stride + static_cast<int>(rng.Next(2 * kReachCells + 1)) - kReachCells;
      const int v = g.v / stride + static_cast<int>(rng.Next(2 * kReachCells + 1)) - kReachCells;
      if (index.Contains(u, v) && index(u, v) >= 0)
        return &grid[static_cast<std::size_t>(index(u, v))];
    }
    return nullptr;
  };
  const auto ball_sq = static_cast<float>(search.ball_mm * search.ball_mm);
  auto in_ball = [&](const Plane& plane, const Eigen::Vector3f& p) {
    return ball_sq <= 0.0f || (p - plane.seed).squaredNorm() <= ball_sq;
  };
  auto score = [&](const Plane& plane, std::size_t& near, std::size_t& wide) {
    near = wide = 0;
    for (const GridPoint& g : grid) {
      if (!in_ball(plane, g.p)) continue;
      const float dist = plane.Distance(g.p);
      near += dist <= tol ? 1u : 0u;
      wide += dist <= 3.0f * tol ? 1u : 0u;
    }
    return static_cast<double>(near) >= search.min_flat_ratio * static_cast<double>(wide);
  };
  std::optional<Plane> best;
  std::size_t best_count = 0;
  for (int it = 0; it < search.iterations; ++it) {
    const GridPoint& a = grid[rng.Next(grid.size())];
    const GridPoint* b = neighbour(a);
    const GridPoint* c = neighbour(a);
    if (b == nullptr || c == nullptr) continue;
    const Eigen::Vector3f n = (b->p - a.p).cross(c->p - a.p);
    if (!(n.norm() > 0.1f * (b->p - a.p).norm() * (c->p - a.p).norm())) continue;
    const Plane plane{n.normalized(), -n.normalized().dot(a.p), a.p};
    std::size_t near = 0, wide = 0;
    if (score(plane, near, wide) && near > best_count) best_count = near, best = plane;
  }
  if (!best) return std::nullopt;
  std::vector<Eigen::Vector3f> inliers;
  for (const GridPoint& g : grid) {
    if (best->Distance(g.p) <= tol && in_ball(*best, g.p)) inliers.push_back(g.p);
  }
  if (std::optional<Plane> refined = FitPlane(inliers)) {
    refined->seed = best->seed;
    best = refined;
  }
  std::size_t near = 0, wide = 0;
  if (!score(*best, near, wide)) return std::nullopt;
  double area = 0.0;
  for (const GridPoint& g : grid) {
    if (best->Distance(g.p) <= tol && in_ball(*best, g.p)) {
      area += static_cast<double>(g.p.squaredNorm()) * cell_omega;
    }
  }
  if (area < search.min_area_mm2) return std::nullopt;
  return best;
}

// Removes (sets to 0) the pixels of up to max_planes flat planes found on a grid of `stride`.
int RemovePlanes(Image<float>& range, const AhatCamera& camera, int stride, double pixel_omega,
                 const PlaneSearch& search, int max_planes, Lcg& rng) {
  const int w = range.width(), h = range.height();
  std::vector<GridPoint> grid;
  Image<int> index((w + stride - 1) / stride, (h + stride - 1) / stride, -1);
  auto build = [&] {
    grid.clear();
    std::fill(index.data(), index.data() + index.size(), -1);
    for (int v = 0; v < h; v += stride) {
      for (int u = 0; u < w; u += stride) {
        if (!(range(u, v) > 0.0f)) continue;
        index(u / stride, v / stride) = static_cast<int>(grid.size());
        grid.push_back({camera.PixelRay(u, v) * range(u, v), u, v});
      }
    }
  };
  const auto tol = static_cast<float>(search.tolerance_mm);
  int removed = 0;
  for (; removed < max_planes; ++removed) {
    build();
    const std::optional<Plane> plane =
        FindFlatPlane(grid, index, stride, pixel_omega * stride * stride, search, rng);
    if (!plane) break;
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        if (!(range(u, v) > 0.0f)) continue;
        const Eigen::Vector3f p = camera.PixelRay(u, v) * range(u, v);
        if (plane->Distance(p) <= tol &&
            (search.ball_mm <= 0.0 || (p - plane->seed).norm() <= 1.5 * search.ball_mm)) {
          range(u, v) = 0.0f;
        }
      }
    }
  }
  return removed;
}

bool Continuous(float a, float b, const HeadRegionOptions& options) {
  return b > 0.0f && std::abs(a - b) <=
                         std::max(options.edge_abs_mm, options.edge_rel * static_cast<double>(a));
}

// Keeps the component's pixels when it is large enough and not flat.
bool KeepComponent(const std::vector<int>& pixels, const Image<float>& range,
                   const AhatCamera& camera, double pixel_omega, const HeadRegionOptions& options) {
  const int w = range.width();
  double area = 0.0;
  for (int i : pixels) {
    const double r = range.data()[static_cast<std::size_t>(i)];
    area += r * r * pixel_omega;
  }
  if (area < options.min_component_area_mm2) return false;
  const std::size_t step = std::max<std::size_t>(1, pixels.size() / 2000);
  std::vector<Eigen::Vector3f> points;
  for (std::size_t k = 0; k < pixels.size(); k += step) {
    const int u = pixels[k] % w, v = pixels[k] / w;
    points.push_back(camera.PixelRay(u, v) * range(u, v));
  }
  const std::optional<Plane> plane = FitPlane(points);
  if (!plane) return false;
  std::vector<float> dist;
  for (const Eigen::Vector3f& p : points) dist.push_back(plane->Distance(p));
  const auto mid = dist.begin() + static_cast<std::ptrdiff_t>(dist.size() / 2);
  std::nth_element(dist.begin(), mid, dist.end());
  return *mid > options.flat_median_mm;
}

// Depth-continuous components (4-connected) of the range, kept when large and not flat.
Image<std::uint8_t> KeepComponents(const Image<float>& range, const AhatCamera& camera,
                                   double pixel_omega, const HeadRegionOptions& options,
                                   HeadRegion& counts) {
  const int w = range.width(), h = range.height();
  Image<std::uint8_t> mask(w, h);
  Image<std::uint8_t> seen(w, h);
  std::vector<int> stack, pixels;
  counts.components_kept = counts.components_dropped = 0;
  for (int start = 0; start < w * h; ++start) {
    if (range.data()[static_cast<std::size_t>(start)] <= 0.0f ||
        seen.data()[static_cast<std::size_t>(start)] != 0) {
      continue;
    }
    pixels.clear();
    stack.assign(1, start);
    seen.data()[static_cast<std::size_t>(start)] = 1;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      pixels.push_back(i);
      const int u = i % w, v = i / w;
      const float r = range(u, v);
      const int nu[4] = {u - 1, u + 1, u, u}, nv[4] = {v, v, v - 1, v + 1};
      for (int k = 0; k < 4; ++k) {
        if (nu[k] < 0 || nv[k] < 0 || nu[k] >= w || nv[k] >= h) continue;
        if (seen(nu[k], nv[k]) != 0 || !Continuous(r, range(nu[k], nv[k]), options)) continue;
        seen(nu[k], nv[k]) = 1;
        stack.push_back(nv[k] * w + nu[k]);
      }
    }
    if (!KeepComponent(pixels, range, camera, pixel_omega, options)) {
      ++counts.components_dropped;
      continue;
    }
    ++counts.components_kept;
    for (int i : pixels) mask.data()[static_cast<std::size_t>(i)] = 1;
  }
  return mask;
}

}  // namespace

void HeadRegionOptions::Check() const {
  if (!(plane_tolerance_mm > 0.0) || !(min_plane_area_mm2 >= 0.0) || !(min_flat_ratio >= 0.0) ||
      min_flat_ratio > 1.0 || max_planes < 0 || ransac_iterations < 1 || sample_stride_px < 1 ||
      !(edge_abs_mm > 0.0) || !(edge_rel >= 0.0) || !(min_component_area_mm2 >= 0.0) ||
      !(flat_median_mm >= 0.0) || !(plate_tolerance_mm > 0.0) || !(min_plate_area_mm2 >= 0.0) ||
      !(min_plate_flat_ratio >= 0.0) || min_plate_flat_ratio > 1.0) {
    throw std::invalid_argument(
        "HeadRegionOptions: need tolerances > 0, areas >= 0, flat ratios in [0, 1], "
        "max_planes >= 0, ransac_iterations >= 1, sample_stride_px >= 1");
  }
}

HeadRegion SelectHeadRegion(const Image<float>& range_mm, const AhatCamera& camera,
                            const HeadRegionOptions& options) {
  options.Check();
  const int w = camera.width(), h = camera.height();
  if (range_mm.width() != w || range_mm.height() != h) {
    throw std::invalid_argument("SelectHeadRegion: range image and camera sizes differ");
  }
  HeadRegion out;
  out.mask = Image<std::uint8_t>(w, h);
  Image<float> range = range_mm;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (!camera.IsValid(u, v) || !(range(u, v) > 0.0f)) range(u, v) = 0.0f;
    }
  }
  if (!options.enabled) {
    for (std::size_t i = 0; i < range.size(); ++i) {
      out.mask.data()[i] = range.data()[i] > 0.0f ? 1 : 0;
      out.pixels += out.mask.data()[i];
    }
    return out;
  }
  const double pixel_omega = PixelSolidAngle(camera);
  Lcg rng;
  // 1. Large flat planes (board, table) on a coarse grid of the whole frame.
  out.planes_removed = RemovePlanes(range, camera, options.sample_stride_px, pixel_omega,
                                    {options.plane_tolerance_mm, options.min_plane_area_mm2,
                                     options.min_flat_ratio, options.ransac_iterations, 0.0},
                                    options.max_planes, rng);
  // 2. Components; 3. plates touching the head (flat, plate-sized) on a finer grid of what is
  // kept; 4. components again (what is left of a plate is a fragment).
  out.mask = KeepComponents(range, camera, pixel_omega, options, out);
  for (std::size_t i = 0; i < range.size(); ++i) {
    if (out.mask.data()[i] == 0) range.data()[i] = 0.0f;
  }
  out.planes_removed += RemovePlanes(
      range, camera, std::max(1, options.sample_stride_px / 2), pixel_omega,
      {options.plate_tolerance_mm, options.min_plate_area_mm2, options.min_plate_flat_ratio,
       options.ransac_iterations, options.plate_radius_mm},
      options.max_planes, rng);
  out.mask = KeepComponents(range, camera, pixel_omega, options, out);
  out.pixels = 0;
  for (std::size_t i = 0; i < range.size(); ++i) out.pixels += out.mask.data()[i];
  return out;
}

}  // namespace tofnav
