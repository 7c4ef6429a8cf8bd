// SPDX-License-Identifier: BSD-3-Clause
// Skin extraction: threshold, largest component, cavity fill, marching cubes, smoothing.
#include "tofnav/imaging/skin.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "tofnav/core/grid3.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/mesh_components.hpp"
#include "tofnav/imaging/skin_mask.hpp"
#include "tofnav/imaging/skin_mesh.hpp"

namespace tofnav {
namespace {

constexpr int kOtsuBins = 256;
constexpr double kAirBelowHu = -500.0;  // a volume reaching this low is taken for a CT in HU

/// The voxel axis closest to superior (LPS z): slices normal to it are axial.
int AxialAxis(const CtVolume& volume) {
  const Eigen::Matrix3d directions = volume.image_from_ijk.topLeftCorner<3, 3>();
  int best = 2;
  double best_cosine = -1.0;
  for (int a = 0; a < 3; ++a) {
    const double cosine = std::abs(directions(2, a)) / directions.col(a).norm();
    if (cosine > best_cosine + 1e-9) {
      best = a;
      best_cosine = cosine;
    }
  }
  return best;
}

std::pair<double, std::string> ChooseThreshold(const CtVolume& volume, const SkinOptions& options) {
  if (options.threshold) return {*options.threshold, "given"};
  bool is_ct = volume.modality == "CT";
  if (volume.modality.empty()) {
    float lowest = std::numeric_limits<float>::infinity();
    for (const float v : volume.values) {
      if (std::isfinite(v)) lowest = std::min(lowest, v);
    }
    is_ct = lowest <= kAirBelowHu;
  }
  if (is_ct) return {kCtSkinThresholdHu, "CT default"};
  const auto finite = std::find_if(volume.values.begin(), volume.values.end(),
                                   [](float v) { return std::isfinite(v); });
  Require(finite != volume.values.end() &&
              std::any_of(finite, volume.values.end(),
                          [&](float v) { return std::isfinite(v) && v != *finite; }),
          "ExtractSkin: the volume is empty (every value the same, or none finite): no skin");
  return {OtsuThreshold(volume.values), "Otsu"};
}

}  // namespace

void SkinOptions::Check() const {
  Require(!threshold || std::isfinite(*threshold), "SkinOptions: threshold must be finite");
  Require(smoothing_iterations >= 0, "SkinOptions: smoothing_iterations must be >= 0");
  Require(std::isfinite(decimation_cell_mm) && decimation_cell_mm >= 0.0,
          "SkinOptions: decimation_cell_mm must be >= 0");
  Require(std::isfinite(opening_radius_mm) && opening_radius_mm >= 0.0,
          "SkinOptions: opening_radius_mm must be >= 0");
}

double OtsuThreshold(std::span<const float> values) {
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (const float v : values) {
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  Require(lo < hi, "OtsuThreshold: needs at least two distinct finite values");
  const double width = (static_cast<double>(hi) - lo) / kOtsuBins;
  std::array<double, kOtsuBins> histogram{};
  for (const float v : values) {
    if (!std::isfinite(v)) continue;
    const auto bin = static_cast<int>((static_cast<double>(v) - lo) / width);
    ++histogram[static_cast<std::size_t>(std::clamp(bin, 0, kOtsuBins - 1))];
  }
  double total = 0.0, total_sum = 0.0;
  for (int b = 0; b < kOtsuBins; ++b) {
    total += histogram[static_cast<std::size_t>(b)];
    total_sum += b * histogram[static_cast<std::size_t>(b)];
  }
  // Between-class variance of each split; empty bins make plateaus: take the middle of the
  // first maximal one (the centre of the gap between two clean modes).
  std::array<double, kOtsuBins> variance{};
  double below = 0.0, below_sum = 0.0, best_variance = 0.0;
  for (int b = 0; b < kOtsuBins - 1; ++b) {  // class 0: bins 0..b, class 1: the rest
    below += histogram[static_cast<std::size_t>(b)];
    below_sum += b * histogram[static_cast<std::size_t>(b)];
    const double above = total - below;
    if (below == 0.0 || above == 0.0) continue;
    const double difference = below_sum / below - (total_sum - below_sum) / above;
    variance[static_cast<std::size_t>(b)] = below * above * difference * difference;
    best_variance = std::max(best_variance, variance[static_cast<std::size_t>(b)]);
  }
  constexpr double kPlateau = 1.0 - 1e-9;  // relative: equal up to round-off
  int first = 0;
  while (variance[static_cast<std::size_t>(first)] < kPlateau * best_variance) ++first;
  int last = first;
  while (last + 1 < kOtsuBins - 1 &&
         variance[static_cast<std::size_t>(last + 1)] >= kPlateau * best_variance) {
    ++last;
  }
  // Split after bin b: the threshold is the upper edge of bin b.
  return lo + (0.5 * (first + last) + 1.0) * width;
}

SkinResult ExtractSkin(const CtVolume& volume, const SkinOptions& options) {
  volume.Check();
  options.Check();
  SkinResult result;
  std::tie(result.threshold, result.threshold_source) = ChooseThreshold(volume, options);
  const auto threshold = static_cast<float>(result.threshold);

  VoxelMask mask{volume.dims, std::vector<std::uint8_t>(volume.values.size())};
  for (std::size_t v = 0; v < volume.values.size(); ++v) {
    mask.values[v] = volume.values[v] > threshold ? 1 : 0;  // NaN: background
  }
  result.mask_components = KeepOuterComponent(mask, ExteriorFaceSeeds(mask));
  Require(result.mask_components > 0, "ExtractSkin: no voxel above the threshold " +
                                          std::to_string(result.threshold) + " (empty mask)");
  if (!options.keep_largest_component) {
    for (std::size_t v = 0; v < volume.values.size(); ++v) {
      mask.values[v] = volume.values[v] > threshold ? 1 : 0;
    }
  }
  if (options.fill_cavities) {
    const std::vector<std::uint8_t> seeds = ExteriorFaceSeeds(mask);
    if (options.opening_radius_mm > 0.0) {
      const Eigen::Vector3d spacing = volume.spacing_mm();
      result.filled_voxels += FillUnreachableAir(mask, {spacing.x(), spacing.y(), spacing.z()},
                                                 options.opening_radius_mm, seeds);
    }
    result.filled_voxels += FillSliceCavities(mask, AxialAxis(volume), seeds);
  }
  result.kept_voxels =
      static_cast<std::size_t>(std::count(mask.values.begin(), mask.values.end(), 1));

  // The CT values keep the sub-voxel edge; voxels outside the mask are pushed just below the
  // threshold and filled ones just above it, so only the mask's boundary is meshed.
  const float margin = 1e-3f * std::max(1.0f, std::abs(threshold));
  std::vector<float> field(volume.values.size());
  for (std::size_t v = 0; v < field.size(); ++v) {
    const float value = std::isfinite(volume.values[v]) ? volume.values[v] : threshold - margin;
    field[v] = mask.values[v] != 0 ? std::max(value, threshold + margin)
                                   : std::min(value, threshold - margin);
  }
  const Grid3<float> grid(Eigen::Vector3i(volume.nx(), volume.ny(), volume.nz()), std::move(field),
                          volume.image_from_ijk);
  TriangleMesh mesh =
      ExtractIsoSurface(grid, {.iso_value = threshold, .outside = IsoSurfaceOutside::kBelow});
  Require(!mesh.triangles.empty(),
          "ExtractSkin: no skin surface at the threshold " + std::to_string(result.threshold) +
              ": the mask has no boundary inside the volume (it fills the field of view, or the "
              "volume is one voxel thin)");
  const std::size_t all_triangles = mesh.triangles.size();
  mesh = LargestConnectedComponent(mesh);
  result.dropped_triangles = all_triangles - mesh.triangles.size();
  SmoothTaubin(mesh, options.smoothing_iterations);
  if (options.decimation_cell_mm > 0.0) DecimateByClustering(mesh, options.decimation_cell_mm);
  mesh.vertex_normals = mesh.ComputeVertexNormals();
  result.mesh = std::move(mesh);
  return result;
}

TriangleMesh MeshLpsToRas(const TriangleMesh& mesh_in_lps) {
  TriangleMesh mesh = mesh_in_lps;  // a rotation by pi about z: winding and handedness kept
  for (Eigen::Vector3d& p : mesh.vertices) p.head<2>() = -p.head<2>();
  for (Eigen::Vector3d& n : mesh.vertex_normals) n.head<2>() = -n.head<2>();
  return mesh;
}

}  // namespace tofnav
