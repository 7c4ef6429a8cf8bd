// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/imaging/ct_volume.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kExactMm = 1e-12;  // affine arithmetic on small numbers: rounding only

CtVolume ObliqueVolume() {
  CtVolume volume;
  volume.dims = {4, 3, 2};
  volume.values.resize(24);
  for (std::size_t n = 0; n < volume.values.size(); ++n) volume.values[n] = static_cast<float>(n);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  volume.image_from_ijk.topLeftCorner<3, 3>() =
      rotation * Eigen::Vector3d(0.5, 0.75, 2.0).asDiagonal();
  volume.image_from_ijk.topRightCorner<3, 1>() = Eigen::Vector3d(-10.0, 20.0, 5.0);
  return volume;
}

TEST(CtVolume, VoxelCentresFollowTheAffineColumns) {
  const CtVolume volume = ObliqueVolume();
  volume.Check();
  EXPECT_EQ(volume.voxel_count(), 24u);
  EXPECT_TRUE(volume.spacing_mm().isApprox(Eigen::Vector3d(0.5, 0.75, 2.0), kExactMm));
  EXPECT_TRUE(volume.VoxelCentre(0, 0, 0).isApprox(Eigen::Vector3d(-10.0, 20.0, 5.0), kExactMm));
  const Eigen::Vector3d step_k = volume.VoxelCentre(1, 2, 1) - volume.VoxelCentre(1, 2, 0);
  EXPECT_NEAR(step_k.norm(), 2.0, kExactMm);
  EXPECT_NEAR(step_k.dot(volume.VoxelCentre(1, 0, 0) - volume.VoxelCentre(0, 0, 0)), 0.0, kExactMm);
  const Eigen::Vector3d ijk = volume.PointToIjk(volume.VoxelCentre(3, 1, 1));
  EXPECT_LT((ijk - Eigen::Vector3d(3.0, 1.0, 1.0)).norm(), 1e-12);
}

TEST(CtVolume, IndexIsIFastest) {
  CtVolume volume = ObliqueVolume();
  EXPECT_EQ(volume.at(1, 0, 0), 1.0f);
  EXPECT_EQ(volume.at(0, 1, 0), 4.0f);
  EXPECT_EQ(volume.at(0, 0, 1), 12.0f);
  EXPECT_EQ(volume.at(3, 2, 1), 23.0f);
  volume.at(2, 1, 1) = -5.0f;
  EXPECT_EQ(volume.values[2 + 4 * (1 + 3 * 1)], -5.0f);
  EXPECT_THROW(volume.at(4, 0, 0), PreconditionError);
  EXPECT_THROW(volume.at(0, -1, 0), PreconditionError);
}

TEST(CtVolume, CheckRejectsBrokenVolumes) {
  CtVolume wrong_size = ObliqueVolume();
  wrong_size.values.pop_back();
  EXPECT_THROW(wrong_size.Check(), PreconditionError);

  CtVolume zero_dim = ObliqueVolume();
  zero_dim.dims[2] = 0;
  EXPECT_THROW(zero_dim.Check(), PreconditionError);

  CtVolume nan_affine = ObliqueVolume();
  nan_affine.image_from_ijk(1, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(nan_affine.Check(), PreconditionError);

  CtVolume coplanar = ObliqueVolume();
  coplanar.image_from_ijk.col(2).head<3>() = 2.0 * coplanar.image_from_ijk.col(0).head<3>();
  EXPECT_THROW(coplanar.Check(), PreconditionError);

  CtVolume projective = ObliqueVolume();
  projective.image_from_ijk(3, 0) = 0.1;
  EXPECT_THROW(projective.Check(), PreconditionError);
}

}  // namespace
}  // namespace tofnav
