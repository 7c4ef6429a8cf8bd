// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/volume/nifti.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/gzip.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;
constexpr double kExactMm = 1e-9;  // binary-exact float32 header numbers
constexpr double kQuatMm = 1e-5;   // quaternion components rounded to float32 (~6e-8 relative)

// The header fields our tests vary; the rest are zero as in a minimal NIfTI-1 file.
struct Fields {
  std::array<std::int16_t, 8> dim = {3, 3, 2, 2, 1, 1, 1, 1};
  std::int16_t datatype = 4;  // int16
  std::array<float, 8> pixdim = {1, 1, 1, 1, 1, 1, 1, 1};
  float vox_offset = 352, scl_slope = 0, scl_inter = 0;
  std::uint8_t xyzt_units = 2;  // mm
  std::int16_t qform_code = 0, sform_code = 0;
  std::array<float, 6> quatern = {0, 0, 0, 0, 0, 0};  // b c d, qoffset x y z
  std::array<float, 12> srow = {};
  std::string magic = std::string("n+1\0", 4);
  bool big_endian = false;
  std::int32_t sizeof_hdr = 348;
};

// Writes the 348-byte header field by field (nifti1.h layout), 4 extension bytes, then data.
std::vector<std::uint8_t> Nifti(const Fields& f, std::span<const std::uint8_t> data) {
  ByteWriter w;
  const auto put = [&](auto value) { f.big_endian ? w.Be(value) : w.Le(value); };
  put(f.sizeof_hdr);
  w.Bytes(std::vector<std::uint8_t>(36, 0));
  for (const auto d : f.dim) put(d);
  w.Bytes(std::vector<std::uint8_t>(14, 0));  // intent_p1..3, intent_code
  put(f.datatype);
  put(std::int16_t{16});  // bitpix
  put(std::int16_t{0});
  for (const float p : f.pixdim) put(p);
  put(f.vox_offset);
  put(f.scl_slope);
  put(f.scl_inter);
  w.Bytes(std::vector<std::uint8_t>{0, 0, 0, f.xyzt_units});  // slice_end, slice_code, units
  w.Bytes(std::vector<std::uint8_t>(24 + 80 + 24, 0));        // cal .. glmin, descrip, aux
  put(f.qform_code);
  put(f.sform_code);
  for (const float q : f.quatern) put(q);
  for (const float s : f.srow) put(s);
  w.Bytes(std::vector<std::uint8_t>(16, 0));
  w.Text(f.magic);
  w.Bytes(std::vector<std::uint8_t>(4, 0));
  w.Bytes(data);
  return w.Release();
}

std::vector<std::uint8_t> Samples(bool big_endian) {  // value 100 k + 10 j + i - 50
  ByteWriter w;
  for (int n = 0; n < 12; ++n) {
    const auto v = static_cast<std::int16_t>(100 * (n / 6) + 10 * (n / 3 % 2) + n % 3 - 50);
    big_endian ? w.Be(v) : w.Le(v);
  }
  return w.Release();
}

// LPS truth shared with the NRRD test: columns (0.5,0.5,0) (-0.75,0.75,0) (0,0,2.5), origin
// (-10,20.5,30); as a RAS sform the first two rows are negated.
Fields SformFields() {
  Fields f;
  f.sform_code = 2;
  f.srow = {-0.5f, 0.75f, 0, 10, -0.5f, -0.75f, 0, -20.5f, 0, 0, 2.5f, 30};
  f.qform_code = 1;  // identity qform: must lose against the sform
  return f;
}

void ExpectCentre(const CtVolume& v, int i, int j, int k, const Eigen::Vector3d& expected,
                  double tolerance_mm) {
  EXPECT_LT((v.VoxelCentre(i, j, k) - expected).norm(), tolerance_mm)
      << v.VoxelCentre(i, j, k).transpose() << " vs " << expected.transpose();
}

TEST(Nifti, SformWinsOverQformAndConvertsRasToLps) {
  const CtVolume v = DecodeNifti(Nifti(SformFields(), Samples(false)), "s.nii");
  EXPECT_EQ(v.geometry_source, "nifti sform (code 2)");
  ExpectCentre(v, 0, 0, 0, {-10, 20.5, 30}, kExactMm);
  ExpectCentre(v, 2, 1, 1,
               Eigen::Vector3d(-10, 20.5, 30) + Eigen::Vector3d(1, 1, 0) +
                   Eigen::Vector3d(-0.75, 0.75, 0) + Eigen::Vector3d(0, 0, 2.5),
               kExactMm);
  EXPECT_EQ(v.at(2, 1, 1), 100 + 10 + 2 - 50);
  // Same file gzip-compressed.
  const CtVolume gz = DecodeNifti(DeflateGzip(Nifti(SformFields(), Samples(false))), "s.nii.gz");
  EXPECT_EQ(gz.values, v.values);
  EXPECT_EQ(gz.image_from_ijk, v.image_from_ijk);
}

TEST(Nifti, QformWithNegativeQfac) {
  Fields f;
  f.qform_code = 1;
  const float s = static_cast<float>(std::sqrt(0.5));  // 90 degrees about z: a = d = sqrt(1/2)
  f.quatern = {0, 0, s, 10, -20.5f, 30};
  f.pixdim = {-1, 0.5f, 0.75f, 2.5f, 1, 1, 1, 1};
  const CtVolume v = DecodeNifti(Nifti(f, Samples(false)), "q.nii");
  EXPECT_EQ(v.geometry_source, "nifti qform (code 1)");
  // RAS columns R_z(90) diag(0.5, 0.75, -2.5): (0,0.5,0) (-0.75,0,0) (0,0,-2.5); LPS negates x, y.
  ExpectCentre(v, 0, 0, 0, {-10, 20.5, 30}, kQuatMm);
  ExpectCentre(v, 1, 0, 0, {-10, 20.0, 30}, kQuatMm);
  ExpectCentre(v, 0, 1, 0, {-9.25, 20.5, 30}, kQuatMm);
  ExpectCentre(v, 0, 0, 1, {-10, 20.5, 27.5}, kQuatMm);
}

TEST(Nifti, PixdimOnlyBigEndianWithScaling) {
  Fields f;
  f.big_endian = true;
  f.pixdim = {0, 0.5f, 0.75f, 2.5f, 1, 1, 1, 1};
  f.scl_slope = 2.0f;
  f.scl_inter = -1024.0f;
  const CtVolume v = DecodeNifti(Nifti(f, Samples(true)), "p.nii");
  EXPECT_EQ(v.geometry_source, "nifti pixdim (no sform/qform)");
  ExpectCentre(v, 2, 1, 1, {-1.0, -0.75, 2.5}, kExactMm);
  EXPECT_EQ(v.at(2, 1, 1), 2.0f * (100 + 10 + 2 - 50) - 1024.0f);
}

TEST(Nifti, MetreUnitsAreConvertedToMm) {
  Fields f = SformFields();
  f.xyzt_units = 1;  // metres
  for (float& value : f.srow) value /= 1000.0f;
  const CtVolume v = DecodeNifti(Nifti(f, Samples(false)), "m.nii");
  ExpectCentre(v, 0, 0, 1, {-10, 20.5, 32.5}, 1e-5);  // mm values through float32 / 1000
}

void ExpectIoError(const std::vector<std::uint8_t>& bytes, std::uint64_t offset,
                   const std::string& text) {
  try {
    DecodeNifti(bytes, "bad.nii");
    ADD_FAILURE() << "no IoError for: " << text;
  } catch (const IoError& error) {
    EXPECT_EQ(error.offset(), offset) << error.what();
    EXPECT_THAT(error.what(), HasSubstr(text));
  }
}

TEST(Nifti, CorruptInputsNameTheOffset) {
  const auto data = Samples(false);
  Fields beyond = SformFields();
  beyond.vox_offset = 400;  // 400 + 24 data bytes > 352 + 24 file bytes
  ExpectIoError(Nifti(beyond, data), 376, "vox_offset 400");
  Fields fractional = SformFields();
  fractional.vox_offset = 352.5f;
  ExpectIoError(Nifti(fractional, data), 108, "vox_offset");
  Fields wrong_size = SformFields();
  wrong_size.sizeof_hdr = 349;
  ExpectIoError(Nifti(wrong_size, data), 0, "sizeof_hdr");
  Fields nifti2 = SformFields();
  nifti2.sizeof_hdr = 540;
  ExpectIoError(Nifti(nifti2, data), 0, "NIfTI-2");
  Fields pair = SformFields();
  pair.magic = std::string("ni1\0", 4);
  ExpectIoError(Nifti(pair, data), 344, "two-file");
  Fields rgb = SformFields();
  rgb.datatype = 128;
  ExpectIoError(Nifti(rgb, data), 70, "datatype 128");
  Fields five_d = SformFields();
  five_d.dim[0] = 5;
  ExpectIoError(Nifti(five_d, data), 40, "dim[0]");
  Fields singular = SformFields();
  singular.srow[10] = 0.0f;  // k column zero
  ExpectIoError(Nifti(singular, data), 252, "invalid orientation");
  ExpectIoError(std::vector<std::uint8_t>(100, 0), 100, "348-byte");
  std::vector<std::uint8_t> cut = DeflateGzip(Nifti(SformFields(), data));
  cut.resize(cut.size() - 12);  // drops the end of the deflate data and the trailer
  try {
    DecodeNifti(cut, "cut.nii.gz");
    FAIL();
  } catch (const IoError& error) {
    EXPECT_EQ(error.offset(), cut.size());
    EXPECT_THAT(error.what(), HasSubstr("truncated"));
  }
}

TEST(Nifti, WriterSformAndQformBothReproduceTheAffine) {
  for (const double flip : {1.0, -1.0}) {  // right- and left-handed index frames (qfac -1)
    CtVolume volume = DecodeNifti(Nifti(SformFields(), Samples(false)), "s.nii");
    volume.image_from_ijk.col(2) *= flip;
    volume.values[3] = 0.5f;
    std::vector<std::uint8_t> bytes = EncodeNifti(volume);
    const CtVolume by_sform = DecodeNifti(bytes, "w.nii");
    EXPECT_EQ(by_sform.values, volume.values);
    EXPECT_TRUE(by_sform.image_from_ijk.isApprox(volume.image_from_ijk, 1e-7));
    bytes[254] = 0;  // sform_code 0: the reader must fall back to the qform
    const CtVolume by_qform = DecodeNifti(bytes, "w.nii");
    EXPECT_EQ(by_qform.geometry_source, "nifti qform (code 1)");
    EXPECT_LT((by_qform.image_from_ijk - volume.image_from_ijk).cwiseAbs().maxCoeff(), kQuatMm);
  }
}

TEST(Nifti, Colin27IsSformOnlyWithMniOrigin) {
  const std::filesystem::path ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  if (!std::filesystem::exists(ch2)) GTEST_SKIP() << "mricron-data not installed";
  const CtVolume v = ReadNifti(ch2);
  EXPECT_EQ(v.dims, (std::array<int, 3>{181, 217, 181}));
  EXPECT_EQ(v.geometry_source, "nifti sform (code 4)");
  ExpectCentre(v, 0, 0, 0, {90.0, 125.0, -71.0}, 1e-4);  // RAS (-90, -125, -71)
  EXPECT_TRUE(v.spacing_mm().isApprox(Eigen::Vector3d::Ones(), 1e-6));
}

}  // namespace
}  // namespace tofnav
