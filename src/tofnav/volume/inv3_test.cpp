// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/volume/inv3.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/gzip.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;
constexpr double kExactMm = 1e-12;

std::string Plist(const std::string& shape) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!DOCTYPE plist PUBLIC \"-//Apple//DTD PLIST "
         "1.0//EN\" \"http://www.apple.com/DTDs/PropertyList-1.0.dtd\">\n<plist version=\"1.0\">"
         "<dict><key>annotations</key><dict/><key>matrix</key><dict><key>dtype</key><string>int16"
         "</string><key>filename</key><string>matrix.dat</string><key>shape</key><array>" +
         shape +
         "</array></dict><key>modality</key><string>CT</string><key>name</key><string>A &amp; B"
         "</string><key>orientation</key><integer>1</integer><key>flag</key><true/>"
         "<key>spacing</key><array><real>0.5</real><real>0.75</real><real>2.0</real></array>"
         "</dict></plist>\n";
}

std::string Matrix(int count) {  // int16 LE samples 0, -1, 2, -3, ...
  ByteWriter w;
  for (int n = 0; n < count; ++n) w.Le(static_cast<std::int16_t>(n % 2 == 0 ? n : -n));
  return std::string(w.bytes().begin(), w.bytes().end());
}

using testing::AppendEntry;
using testing::HandHeader;
using testing::ToBytes;

// The layout of an InVesalius project: one folder holding main.plist, masks and the matrix.
std::vector<std::uint8_t> Project(const std::string& plist, const std::string& matrix) {
  std::vector<std::uint8_t> tar;
  AppendEntry(tar, HandHeader("tmpabc/", 0, '5'), {});
  AppendEntry(tar, HandHeader("tmpabc/main.plist", plist.size()), ToBytes(plist));
  AppendEntry(tar, HandHeader("tmpabc/mask_0.dat", 700), std::vector<std::uint8_t>(700, 1));
  AppendEntry(tar, HandHeader("tmpabc/matrix.dat", matrix.size()), ToBytes(matrix));
  testing::AppendEndBlocks(tar);
  return DeflateGzip(tar);
}

const std::string kShape = "<integer>2</integer><integer>3</integer><integer>4</integer>";

TEST(Inv3, TinyProjectReadsShapeZyxSpacingXyzAndRowsBottomUp) {
  const CtVolume v = DecodeInv3(Project(Plist(kShape), Matrix(24)), "tiny.inv3");
  ASSERT_EQ(v.dims, (std::array<int, 3>{4, 3, 2}));
  EXPECT_EQ(v.modality, "CT");
  EXPECT_EQ(v.name, "A & B");
  EXPECT_EQ(v.at(3, 2, 1), -23.0f);  // index 3 + 4 * (2 + 3 * 1)
  EXPECT_EQ(v.at(2, 1, 0), 6.0f);
  EXPECT_LT((v.VoxelCentre(3, 2, 1) - Eigen::Vector3d(1.5, -1.5, 2.0)).norm(), kExactMm);
}

void ExpectIoError(const std::vector<std::uint8_t>& bytes, const std::string& text) {
  EXPECT_THAT([&] { DecodeInv3(bytes, "bad.inv3"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr(text)));
}

TEST(Inv3, CorruptProjectsAreRefused) {
  ExpectIoError(Project(Plist(kShape), Matrix(23)), "shape needs 48");
  ExpectIoError(Project(Plist("<integer>2</integer>"), Matrix(24)), "3 values");
  ExpectIoError(Project("<plist><dict><key>x</key><strin>", Matrix(24)), "XML plist");
  std::vector<std::uint8_t> tar;
  AppendEntry(tar, HandHeader("main.plist", Plist(kShape).size()), ToBytes(Plist(kShape)));
  tar[150] ^= 1;  // checksum digit
  ExpectIoError(DeflateGzip(tar), "checksum");
  std::vector<std::uint8_t> cut = Project(Plist(kShape), Matrix(24));
  cut.resize(cut.size() / 2);
  ExpectIoError(cut, "truncated");
  std::vector<std::uint8_t> no_matrix;
  AppendEntry(no_matrix, HandHeader("main.plist", Plist(kShape).size()), ToBytes(Plist(kShape)));
  ExpectIoError(DeflateGzip(no_matrix), "no matrix.dat");
}

TEST(Inv3, DebianCraniumIsAnAnatomicallyOrientedHeadCt) {
  const std::filesystem::path path = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "invesalius-examples not installed";
  const CtVolume v = ReadInv3(path);
  ASSERT_EQ(v.dims, (std::array<int, 3>{256, 256, 108}));
  EXPECT_TRUE(v.spacing_mm().isApprox(Eigen::Vector3d(0.9570312, 0.9570312, 1.5), 1e-7));
  EXPECT_EQ(v.modality, "CT");
  const auto [low, high] = std::minmax_element(v.values.begin(), v.values.end());
  EXPECT_EQ(*low, -1024.0f);
  EXPECT_GT(*high, 2500.0f);  // main.plist says 3033; the stored maximum is 2986
  EXPECT_LT(*high, 3100.0f);
  // Anatomy: tooth enamel (>= 2000 HU) lies anterior (-y in LPS) and inferior (-z) of the
  // centroid of all other soft tissue and bone (> -300 HU).
  // Plain index sums over every other voxel per axis (fast enough unoptimised).
  std::array<double, 4> tissue{}, teeth{};  // sum i, sum j, sum k, count
  for (int k = 0; k < v.nz(); k += 2) {
    for (int j = 0; j < v.ny(); j += 2) {
      for (int i = 0; i < v.nx(); i += 2) {
        const float hu = v.values[v.Index(i, j, k)];
        std::array<double, 4>* sums = hu >= 2000.0f ? &teeth : hu > -300.0f ? &tissue : nullptr;
        if (sums == nullptr) continue;
        (*sums)[0] += i, (*sums)[1] += j, (*sums)[2] += k, (*sums)[3] += 1.0;
      }
    }
  }
  ASSERT_GT(teeth[3], 20.0);
  const auto centre = [&v](const std::array<double, 4>& sums) {
    const Eigen::Vector3d ijk(sums[0] / sums[3], sums[1] / sums[3], sums[2] / sums[3]);
    return Eigen::Vector3d(v.image_from_ijk.topLeftCorner<3, 3>() * ijk +
                           v.image_from_ijk.topRightCorner<3, 1>());
  };
  const Eigen::Vector3d tissue_in_image = centre(tissue), teeth_in_image = centre(teeth);
  EXPECT_LT(teeth_in_image.y(), tissue_in_image.y() - 50.0);  // well anterior [mm]
  EXPECT_LT(teeth_in_image.z(), tissue_in_image.z() - 40.0);  // well inferior [mm]
}

}  // namespace
}  // namespace tofnav
