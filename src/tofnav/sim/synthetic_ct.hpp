// SPDX-License-Identifier: BSD-3-Clause
// A pre-operative CT synthesised from a closed head mesh: HU layers, ventricles, partial volume,
// noise. The `image` frame is CT LPS [mm].
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav::sim {

/// An ellipsoid with axes along the image axes.
struct Ellipsoid {
  Eigen::Vector3d centre_in_image = Eigen::Vector3d::Zero();
  Eigen::Vector3d semi_axes_mm = Eigen::Vector3d::Ones();
};

/// Where the cranium lies in `image` (LPS: +x left, +y posterior, +z superior), for the
/// ventricles and the plan. Head meshes in image coordinates are assumed upright (CT convention).
struct HeadAnatomy {
  Eigen::Vector3d centre_in_image = Eigen::Vector3d::Zero();  // centre of the cranial ellipsoid
  Eigen::Vector3d semi_axes_mm = {75.0, 95.0, 110.0};         // L-R, A-P, I-S half extents
  double nasion_elevation_rad = 0.1;  // nasion direction above the centre's axial plane
  /// Lateral ventricles (right, x < centre, then left), in proportion to the cranium: each
  /// centred 0.17 a_x lateral, 0.18 a_y anterior, 0.18 a_z superior of the centre, with semi-axes
  /// (0.11 a_x, 0.30 a_y, 0.09 a_z); their anterior ends are the frontal horns.
  std::array<Ellipsoid, 2> Ventricles() const;
};

/// A rough anatomy from an upright head mesh in image coordinates (its bounding box): the
/// cranium spans the box in x and y and is 1.15 a_y high below the top of the box.
HeadAnatomy AnatomyFromBounds(const TriangleMesh& skin_in_image);

struct SyntheticCtOptions {
  double spacing_mm = 1.0;  // isotropic voxels, axes along LPS
  double margin_mm = 12.0;  // air around the mesh's bounding box
  int subsamples = 3;       // sub-rows per voxel along y and z for partial volume (x is exact)
  double air_hu = -1000.0;
  double soft_tissue_hu = 40.0;  // scalp
  double scalp_mm = 6.0;         // depth below the skin where the skull starts
  double skull_mm = 7.0;
  double skull_table_hu = 1500.0;   // inner and outer tables
  double skull_diploe_hu = 1000.0;  // the middle of the bone
  double brain_hu = 35.0;
  double ventricle_hu = 8.0;     // CSF
  double noise_sigma_hu = 12.0;  // white Gaussian noise per voxel
  void Check() const;            // throws PreconditionError naming the bad field
};

/// A CT volume as plain data (io/ turns it into a CtVolume): voxel (i, j, k) at
/// values_hu[i + nx * (j + ny * k)], image_from_ijk = origin + diag(spacing).
struct SyntheticCt {
  std::array<int, 3> dims = {0, 0, 0};
  std::vector<float> values_hu;
  Eigen::Matrix4d image_from_ijk = Eigen::Matrix4d::Identity();
};

/// Voxelises the closed mesh `skin_in_image` (exact coverage along x, subsamples^2 rows per
/// voxel) and fills it by depth below the skin (Euclidean distance transform, Felzenszwalb &
/// Huttenlocher 2012): scalp, skull (tables and diploe), brain, ventricles; then adds noise drawn
/// from `seed`. Deterministic for any thread count. Throws PreconditionError for an empty mesh or
/// a grid over 512^3 voxels.
SyntheticCt SynthesizeHeadCt(const TriangleMesh& skin_in_image, const HeadAnatomy& anatomy,
                             const SyntheticCtOptions& options, std::uint64_t seed);

}  // namespace tofnav::sim
