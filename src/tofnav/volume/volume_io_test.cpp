// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/volume/volume_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <fstream>
#include <string>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;
// Acceptance: the same volume from independent writers gives the same LPS voxel centres. NIfTI
// stores float32 (~1e-6 mm here), DICOM 16-character decimal strings (~1e-10 mm).
constexpr double kCrossFormatMm = 1e-4;

CtVolume SmallOblique() {
  CtVolume v;
  v.dims = {3, 4, 2};
  for (int n = 0; n < 24; ++n) v.values.push_back(static_cast<float>(n * n) - 100.0f);
  v.image_from_ijk.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(-1, 0.5, 2).normalized()).toRotationMatrix() *
      Eigen::Vector3d(0.9, 1.1, 2.0).asDiagonal();
  v.image_from_ijk.topRightCorner<3, 1>() = Eigen::Vector3d(12.0, -7.5, 101.0);
  return v;
}

TEST(VolumeIo, WriteVolumeThenReadVolumeByContentAndExtension) {
  const testing::TempDir temp("volume_io_roundtrip");
  const std::filesystem::path& dir = temp.path();
  const CtVolume v = SmallOblique();
  for (const char* name : {"a.nrrd", "b.nii", "c.nii.gz"}) {
    WriteVolume(dir / name, v, {.sample_type = VolumeSampleType::kInt16});
    const CtVolume back = ReadVolume(dir / name);
    EXPECT_EQ(back.values, v.values) << name;
    EXPECT_LT((back.image_from_ijk - v.image_from_ijk).cwiseAbs().maxCoeff(), 1e-5) << name;
  }
  // Content wins over a misleading name.
  std::filesystem::rename(dir / "a.nrrd", dir / "a.nii");
  EXPECT_THAT(ReadVolume(dir / "a.nii").geometry_source, HasSubstr("nrrd"));
  EXPECT_THROW(WriteVolume(dir / "x.mha", v), IoError);
  WriteFileAtomically(dir / "junk.nrrd", std::string("hello world"));
  EXPECT_THAT([&] { ReadVolume(dir / "junk.nrrd"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("unrecognised volume format")));
}

struct Truth {
  std::array<int, 3> dims{};
  Eigen::Matrix4d image_from_ijk;
  std::vector<float> values;
};

Truth ReadTruth(const std::filesystem::path& path) {
  std::ifstream in(path);
  Truth t;
  in >> t.dims[0] >> t.dims[1] >> t.dims[2];
  for (int n = 0; n < 16; ++n) in >> t.image_from_ijk(n / 4, n % 4);
  for (float value; in >> value;) t.values.push_back(value);
  return t;
}

TEST(VolumeIo, NiftiDicomAndNrrdFromIndependentWritersAgree) {
  const testing::TempDir temp("volume_io_oracle");
  const std::filesystem::path& dir = temp.path();
  const std::string command =
      "/usr/bin/python3 " TOFNAV_TESTS_DIR "/volume_oracle.py " + dir.string();
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << command;
  if (WEXITSTATUS(status) == 77) GTEST_SKIP() << "python3-nibabel/pydicom/numpy missing";
  ASSERT_EQ(WEXITSTATUS(status), 0) << command;
  const Truth truth = ReadTruth(dir / "truth.txt");
  ASSERT_EQ(truth.values.size(), 7u * 6u * 5u);
  // Sources: nibabel sform+qform (.nii.gz), nibabel qform only (.nii), pydicom, hand NRRD (RAS).
  for (const char* name : {"oblique.nii.gz", "oblique_qform.nii", "dicom", "oblique.nrrd"}) {
    SCOPED_TRACE(name);
    const CtVolume v = ReadVolume(dir / name);
    ASSERT_EQ(v.dims, truth.dims);
    EXPECT_EQ(v.values, truth.values);
    double worst_mm = 0.0;
    for (int k = 0; k < v.nz(); ++k) {
      for (int j = 0; j < v.ny(); ++j) {
        for (int i = 0; i < v.nx(); ++i) {
          const Eigen::Vector3d expected =
              (truth.image_from_ijk * Eigen::Vector4d(i, j, k, 1)).head<3>();
          worst_mm = std::max(worst_mm, (v.VoxelCentre(i, j, k) - expected).norm());
        }
      }
    }
    EXPECT_LT(worst_mm, kCrossFormatMm) << v.geometry_source;
    RecordProperty(std::string("worst_mm_") + name, ::testing::PrintToString(worst_mm));
  }
}

}  // namespace
}  // namespace tofnav
