// SPDX-License-Identifier: BSD-3-Clause
// Synthetic head CT: HU layers by depth below the skin, ventricles, partial volume, noise.
#include "tofnav/sim/synthetic_ct.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/random.hpp"
#include "tofnav/sim/voxelize.hpp"

namespace tofnav::sim {
namespace {

constexpr std::int64_t kMaxVoxels = std::int64_t{512} * 512 * 512;

double Ramp(double x) { return std::clamp(x + 0.5, 0.0, 1.0); }

// Share of a voxel inside either ventricle (linear in the approximate signed distance).
class VentricleShare {
 public:
  VentricleShare(const std::array<Ellipsoid, 2>& ventricles, double h) : h_(h) {
    for (std::size_t e = 0; e < 2; ++e) {
      for (int a = 0; a < 3; ++a) {
        centre_[e][static_cast<std::size_t>(a)] = ventricles[e].centre_in_image[a];
        inverse_axis_[e][static_cast<std::size_t>(a)] = 1.0 / ventricles[e].semi_axes_mm[a];
      }
      min_axis_[e] = ventricles[e].semi_axes_mm.minCoeff();
    }
  }
  double operator()(double x, double y, double z) const {
    double best = 0.0;
    for (std::size_t e = 0; e < 2; ++e) {
      const double dx = (x - centre_[e][0]) * inverse_axis_[e][0];
      const double dy = (y - centre_[e][1]) * inverse_axis_[e][1];
      const double dz = (z - centre_[e][2]) * inverse_axis_[e][2];
      const double signed_distance_mm =
          (std::sqrt(dx * dx + dy * dy + dz * dz) - 1.0) * min_axis_[e];
      best = std::max(best, Ramp(-signed_distance_mm / h_));
    }
    return best;
  }

 private:
  double h_;
  std::array<std::array<double, 3>, 2> centre_{}, inverse_axis_{};
  std::array<double, 2> min_axis_{};
};

}  // namespace

std::array<Ellipsoid, 2> HeadAnatomy::Ventricles() const {
  const Eigen::Vector3d& a = semi_axes_mm;
  const Eigen::Vector3d semi(0.11 * a.x(), 0.30 * a.y(), 0.09 * a.z());
  // LPS: right is -x, anterior is -y, superior is +z.
  const Eigen::Vector3d offset(0.17 * a.x(), -0.18 * a.y(), 0.18 * a.z());
  return {Ellipsoid{centre_in_image + Eigen::Vector3d(-offset.x(), offset.y(), offset.z()), semi},
          Ellipsoid{centre_in_image + offset, semi}};
}

HeadAnatomy AnatomyFromBounds(const TriangleMesh& skin_in_image) {
  Require(!skin_in_image.vertices.empty(), "AnatomyFromBounds: empty mesh");
  Eigen::Vector3d lo = skin_in_image.vertices.front(), hi = lo;
  for (const Eigen::Vector3d& p : skin_in_image.vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  HeadAnatomy anatomy;
  const Eigen::Vector3d half = 0.5 * (hi - lo);
  anatomy.semi_axes_mm = {half.x(), half.y(), 1.15 * half.y()};
  anatomy.centre_in_image = {0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()),
                             hi.z() - anatomy.semi_axes_mm.z()};
  return anatomy;
}

void SyntheticCtOptions::Check() const {
  Require(std::isfinite(spacing_mm) && spacing_mm >= 0.1,
          "SyntheticCtOptions.spacing_mm must be >= 0.1");
  Require(std::isfinite(margin_mm) && margin_mm >= 0.0,
          "SyntheticCtOptions.margin_mm must be >= 0");
  Require(subsamples >= 1 && subsamples <= 8, "SyntheticCtOptions.subsamples must lie in [1, 8]");
  Require(scalp_mm >= 0.0 && skull_mm > 0.0,
          "SyntheticCtOptions: scalp_mm must be >= 0 and skull_mm > 0");
  Require(std::isfinite(noise_sigma_hu) && noise_sigma_hu >= 0.0,
          "SyntheticCtOptions.noise_sigma_hu must be >= 0");
  for (const double hu :
       {air_hu, soft_tissue_hu, skull_table_hu, skull_diploe_hu, brain_hu, ventricle_hu}) {
    Require(std::isfinite(hu) && std::abs(hu) <= 30000.0,
            "SyntheticCtOptions: HU values must be finite and within +-30000");
  }
}

SyntheticCt SynthesizeHeadCt(const TriangleMesh& skin_in_image, const HeadAnatomy& anatomy,
                             const SyntheticCtOptions& options, std::uint64_t seed) {
  options.Check();
  Require(!skin_in_image.vertices.empty() && !skin_in_image.triangles.empty(),
          "SynthesizeHeadCt: empty mesh");
  skin_in_image.CheckConsistent();
  const VoxelGrid grid =
      GridAroundMesh(skin_in_image, options.spacing_mm, options.margin_mm, kMaxVoxels);
  const std::vector<float> fraction = MeshInsideFraction(skin_in_image, grid, options.subsamples);
  const std::vector<double> d2 = SquaredDistanceToOutside(fraction, grid);
  const VentricleShare ventricle_share(anatomy.Ventricles(), grid.spacing_mm);
  const SyntheticCtOptions& o = options;

  SyntheticCt ct;
  ct.dims = grid.dims;
  ct.values_hu.assign(grid.size(), 0.0f);
  ct.image_from_ijk.topLeftCorner<3, 3>() = grid.spacing_mm * Eigen::Matrix3d::Identity();
  ct.image_from_ijk.topRightCorner<3, 1>() = grid.origin;
  ParallelFor(0, grid.dims[2], [&](std::int64_t slice) {
    const int k = static_cast<int>(slice);
    std::mt19937_64 rng(StreamSeed(seed, SeedStream::kCtNoise, static_cast<std::uint64_t>(k)));
    std::normal_distribution<double> noise(0.0, 1.0);
    for (int j = 0; j < grid.dims[1]; ++j) {
      for (int i = 0; i < grid.dims[0]; ++i) {
        const std::size_t n = grid.Index(i, j, k);
        double value = o.air_hu;
        if (fraction[n] > 0.0f) {
          // Depth below the skin: distance to the nearest outside voxel centre less half a voxel.
          const double depth_mm = std::max(0.0, std::sqrt(d2[n]) - 0.5 * grid.spacing_mm);
          const double outer = Ramp((depth_mm - o.scalp_mm) / grid.spacing_mm);
          const double inner = Ramp((depth_mm - o.scalp_mm - o.skull_mm) / grid.spacing_mm);
          const double u = std::clamp((depth_mm - o.scalp_mm) / o.skull_mm, 0.0, 1.0);
          const double bone =
              o.skull_diploe_hu + (o.skull_table_hu - o.skull_diploe_hu) * std::abs(2.0 * u - 1.0);
          const double brain =
              o.brain_hu + (o.ventricle_hu - o.brain_hu) *
                               ventricle_share(grid.origin.x() + grid.spacing_mm * i,
                                               grid.origin.y() + grid.spacing_mm * j,
                                               grid.origin.z() + grid.spacing_mm * k);
          const double tissue =
              o.soft_tissue_hu * (1.0 - outer) + bone * (outer - inner) + brain * inner;
          value = o.air_hu + fraction[n] * (tissue - o.air_hu);
        }
        if (o.noise_sigma_hu > 0.0) value += o.noise_sigma_hu * noise(rng);
        ct.values_hu[n] = static_cast<float>(value);
      }
    }
  });
  return ct;
}

}  // namespace tofnav::sim
