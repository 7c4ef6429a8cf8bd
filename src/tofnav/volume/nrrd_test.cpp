// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/volume/nrrd.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/gzip.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;
constexpr double kExactMm = 1e-12;  // binary-exact header numbers: rounding only

// Truth for the hand-made files: 3 x 2 x 2 voxels, an oblique in-plane rotation with anisotropic
// spacing (columns of LPS directions), value 100 k + 10 j + i - 50.
const Eigen::Vector3d kDirI(0.5, 0.5, 0.0), kDirJ(-0.75, 0.75, 0.0), kDirK(0.0, 0.0, 2.5);
const Eigen::Vector3d kOrigin(-10.0, 20.5, 30.0);

float TruthValue(int i, int j, int k) { return static_cast<float>(100 * k + 10 * j + i - 50); }

std::vector<std::uint8_t> Int16Samples(bool big_endian) {
  ByteWriter w;
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 3; ++i) {
        const auto v = static_cast<std::int16_t>(TruthValue(i, j, k));
        big_endian ? w.Be(v) : w.Le(v);
      }
    }
  }
  return w.Release();
}

std::vector<std::uint8_t> Join(const std::string& header, std::span<const std::uint8_t> data) {
  std::vector<std::uint8_t> out(header.begin(), header.end());
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

void ExpectTruth(const CtVolume& volume) {
  ASSERT_EQ(volume.dims, (std::array<int, 3>{3, 2, 2}));
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(volume.at(i, j, k), TruthValue(i, j, k));
        const Eigen::Vector3d expected = kOrigin + i * kDirI + j * kDirJ + k * kDirK;
        EXPECT_LT((volume.VoxelCentre(i, j, k) - expected).norm(), kExactMm) << i << j << k;
      }
    }
  }
}

const std::string kLpsHeader =
    "NRRD0004\n# hand-made\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
    "sizes: 3 2 2\nspace directions: (0.5,0.5,0) (-0.75, 0.75, 0) (0,0,2.5)\n"
    "kinds: domain domain domain\nendian: little\nencoding: raw\n"
    "space origin: (-10,20.5,30)\nmeta:=value: ignored\n\n";

TEST(Nrrd, RawLpsObliqueGivesKnownVoxelCentres) {
  const CtVolume volume = DecodeNrrd(Join(kLpsHeader, Int16Samples(false)), "lps.nrrd");
  ExpectTruth(volume);
  EXPECT_THAT(volume.geometry_source, HasSubstr("space directions"));
}

TEST(Nrrd, GzipRasBigEndianIsConvertedToLps) {
  // The same volume described in RAS: x and y of every direction and of the origin negated.
  const std::string header =
      "NRRD0005\r\ntype: int16\r\ndimension: 3\r\nspace: RAS\r\nsizes: 3 2 2\r\n"
      "space directions: (-0.5,-0.5,0) (0.75,-0.75,0) (0,0,2.5)\r\nendian: big\r\n"
      "encoding: gzip\r\nspace origin: (10,-20.5,30)\r\n\r\n";
  ExpectTruth(DecodeNrrd(Join(header, DeflateGzip(Int16Samples(true))), "ras.nrrd"));
}

TEST(Nrrd, FourDimensionalWithLeadingListAxisOfSizeOne) {
  const std::string header =
      "NRRD0004\ntype: short\ndimension: 4\nspace: LPS\nsizes: 1 3 2 2\n"
      "space directions: none (0.5,0.5,0) (-0.75,0.75,0) (0,0,2.5)\nkinds: list domain domain "
      "domain\nendian: little\nencoding: raw\nspace origin: (-10,20.5,30)\n\n";
  ExpectTruth(DecodeNrrd(Join(header, Int16Samples(false)), "4d.nrrd"));
  std::string three_components = header;
  three_components.replace(three_components.find("1 3 2 2"), 7, "3 1 2 2");
  EXPECT_THROW(DecodeNrrd(Join(three_components, Int16Samples(false)), "v.nrrd"), IoError);
}

TEST(Nrrd, SpacingsOnlyIsAxisAlignedWithOriginZero) {
  const std::string header =
      "NRRD0001\ntype: short\ndimension: 3\nsizes: 3 2 2\nspacings: 0.5 0.25 2\n"
      "endian: little\nencoding: raw\n\n";
  const CtVolume volume = DecodeNrrd(Join(header, Int16Samples(false)), "s.nrrd");
  EXPECT_LT((volume.VoxelCentre(2, 1, 1) - Eigen::Vector3d(1.0, 0.25, 2.0)).norm(), kExactMm);
  EXPECT_EQ(volume.at(2, 1, 1), TruthValue(2, 1, 1));
}

TEST(Nrrd, DetachedDataWithLineSkipAndByteSkipMinusOne) {
  const testing::TempDir temp("nrrd_test");
  const std::filesystem::path& folder = temp.path();
  const auto data = Int16Samples(false);
  WriteFileAtomically(folder / "vol.raw", Join("two lines\nof text\nXYZ", data));
  std::string header = kLpsHeader;
  header.replace(header.find("encoding: raw\n"), 14,
                 "encoding: raw\ndata file: vol.raw\nline skip: 2\nbyte skip: -1\n");
  WriteFileAtomically(folder / "vol.nhdr", header.substr(0, header.size() - 1));  // no blank
  ExpectTruth(ReadNrrd(folder / "vol.nhdr"));
  // In memory (no data folder) a detached file is refused.
  EXPECT_THROW(DecodeNrrd(Join(header, {}), "mem.nhdr"), IoError);
}

// Asserts that decoding throws IoError at `offset` with `text` in the message.
void ExpectIoError(const std::vector<std::uint8_t>& bytes, std::uint64_t offset,
                   const std::string& text) {
  try {
    DecodeNrrd(bytes, "bad.nrrd");
    ADD_FAILURE() << "no IoError for: " << text;
  } catch (const IoError& error) {
    EXPECT_EQ(error.offset(), offset) << error.what();
    EXPECT_THAT(error.what(), HasSubstr(text));
    EXPECT_THAT(error.what(), HasSubstr("bad.nrrd"));
  }
}

TEST(Nrrd, CorruptInputsNameTheOffset) {
  const auto data = Int16Samples(false);
  const std::uint64_t data_start = kLpsHeader.size();
  ExpectIoError(Join("NRRD0009\n", {}), 0, "magic");
  // Wrong sizes: more voxels than data, and fewer.
  std::string bigger = kLpsHeader;
  bigger.replace(bigger.find("sizes: 3 2 2"), 12, "sizes: 3 2 3");
  ExpectIoError(Join(bigger, data), data_start, "expected exactly 36 bytes");
  std::string smaller = kLpsHeader;
  smaller.replace(smaller.find("sizes: 3 2 2"), 12, "sizes: 3 2 1");
  ExpectIoError(Join(smaller, data), data_start, "expected exactly 12 bytes");
  // Bad fields: the offset is the start of the offending line.
  const std::string::size_type line = kLpsHeader.find("space:");
  std::string bad_space = kLpsHeader;
  bad_space.replace(line, 30, "space: scanner-xyz");
  ExpectIoError(Join(bad_space, data), line, "unsupported space");
  std::string bad_vector = kLpsHeader;
  bad_vector.replace(bad_vector.find("(0,0,2.5)"), 9, "(0,0)");
  ExpectIoError(Join(bad_vector, data), kLpsHeader.find("space directions"), "3 components");
  std::string bad_type = kLpsHeader;
  bad_type.replace(bad_type.find("type: short"), 11, "type: block");
  ExpectIoError(Join(bad_type, data), kLpsHeader.find("type:"), "unsupported NRRD type");
  std::string no_endian = kLpsHeader;
  no_endian.erase(no_endian.find("endian: little\n"), 15);
  ExpectIoError(Join(no_endian, data), no_endian.size(), "endian");
  std::string five_d = kLpsHeader;
  five_d.replace(five_d.find("dimension: 3"), 12, "dimension: 5");
  ExpectIoError(Join(five_d, data), kLpsHeader.find("dimension:"), "dimension 3 or 4");
  std::string coplanar = kLpsHeader;
  coplanar.replace(coplanar.find("(0,0,2.5)"), 9, "(1,1,0.0)");
  ExpectIoError(Join(coplanar, data), kLpsHeader.size(), "invalid geometry");
}

TEST(Nrrd, TruncatedGzipNamesTheCompressedOffset) {
  std::string header = kLpsHeader;
  header.replace(header.find("encoding: raw"), 13, "encoding: gzip");
  std::vector<std::uint8_t> compressed = DeflateGzip(Int16Samples(false));
  compressed.resize(compressed.size() / 2);
  try {
    DecodeNrrd(Join(header, compressed), "cut.nrrd");
    FAIL();
  } catch (const IoError& error) {
    EXPECT_EQ(error.offset(), header.size() + compressed.size());
    EXPECT_THAT(error.what(), HasSubstr("truncated"));
  }
}

TEST(Nrrd, WriterRoundTripsFloatAndInt16) {
  CtVolume volume = DecodeNrrd(Join(kLpsHeader, Int16Samples(false)), "lps.nrrd");
  volume.values[4] = 12.25f;  // not representable as int16: float output keeps it
  for (const bool gzip : {true, false}) {
    const CtVolume back = DecodeNrrd(EncodeNrrd(volume, {.gzip = gzip}), "float.nrrd");
    EXPECT_EQ(back.values, volume.values);
    EXPECT_EQ(back.image_from_ijk, volume.image_from_ijk);  // shortest round-trip decimal text
  }
  const CtVolume rounded =
      DecodeNrrd(EncodeNrrd(volume, {.sample_type = VolumeSampleType::kInt16}), "short.nrrd");
  EXPECT_EQ(rounded.values[4], 12.0f);
  EXPECT_EQ(rounded.values[5], volume.values[5]);
  volume.values[0] = 40000.0f;
  EXPECT_THROW(EncodeNrrd(volume, {.sample_type = VolumeSampleType::kInt16}), PreconditionError);
}

}  // namespace
}  // namespace tofnav
