// SPDX-License-Identifier: BSD-3-Clause
// NIfTI-1 reader/writer from the field layout and orientation rules of nifti1.h.
#include "tofnav/volume/nifti.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/gzip.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/volume/volume_samples.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kHeaderBytes = 348;
constexpr std::size_t kSingleFileVoxOffset = 352;  // header + 4-byte extension flag
const Eigen::Vector3d kRasToLps(-1.0, -1.0, 1.0);  // diagonal: negate the first two rows

std::optional<SampleType> SampleTypeOf(int datatype) {
  switch (datatype) {
    case 2:
      return SampleType::kUint8;
    case 4:
      return SampleType::kInt16;
    case 8:
      return SampleType::kInt32;
    case 16:
      return SampleType::kFloat32;
    case 64:
      return SampleType::kFloat64;
    case 256:
      return SampleType::kInt8;
    case 512:
      return SampleType::kUint16;
    case 768:
      return SampleType::kUint32;
    case 1024:
      return SampleType::kInt64;
    case 1280:
      return SampleType::kUint64;
    default:
      return std::nullopt;
  }
}

// Reads fields at fixed offsets of the 348-byte header in the detected byte order.
class HeaderReader {
 public:
  HeaderReader(std::span<const std::uint8_t> header, const std::filesystem::path& path,
               bool big_endian)
      : header_(header), path_(path), big_endian_(big_endian) {}
  template <typename T>
  T At(std::size_t offset, const char* what) const {
    ByteReader reader(header_, path_);
    reader.Skip(offset, what);
    return big_endian_ ? reader.Be<T>(what) : reader.Le<T>(what);
  }
  double Float(std::size_t offset, const char* what) const { return At<float>(offset, what); }
  [[noreturn]] void Fail(std::size_t offset, const std::string& message) const {
    throw IoError(path_, offset, message);
  }

 private:
  std::span<const std::uint8_t> header_;
  const std::filesystem::path& path_;
  bool big_endian_;
};

// nifti1.h, method 2: R(b, c, d) * diag(dx, dy, qfac * dz) with offsets (RAS).
Eigen::Matrix4d QformAffine(const HeaderReader& h) {
  Eigen::Vector3d bcd(h.Float(256, "quatern_b"), h.Float(260, "quatern_c"),
                      h.Float(264, "quatern_d"));
  double a = 1.0 - bcd.squaredNorm();
  if (a < 0.0) {  // nifti1_io: renormalise (b, c, d) and take a = 0
    bcd.normalize();
    a = 0.0;
  }
  const Eigen::Quaterniond q(std::sqrt(a), bcd.x(), bcd.y(), bcd.z());
  const double qfac = h.Float(76, "pixdim[0]") < 0.0 ? -1.0 : 1.0;  // 0 counts as 1
  Eigen::Vector3d step(h.Float(80, "pixdim[1]"), h.Float(84, "pixdim[2]"),
                       h.Float(88, "pixdim[3]"));
  if (!(step.array() > 0.0).all() || !step.allFinite()) h.Fail(80, "qform needs pixdim > 0");
  step.z() *= qfac;
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = q.toRotationMatrix() * step.asDiagonal();
  m.topRightCorner<3, 1>() = Eigen::Vector3d(h.Float(268, "qoffset_x"), h.Float(272, "qoffset_y"),
                                             h.Float(276, "qoffset_z"));
  return m;
}

// image_from_ijk (LPS, mm) and the rule used; the header's spatial unit is converted to mm.
Eigen::Matrix4d Geometry(const HeaderReader& h, std::string& source) {
  const int qform_code = h.At<std::int16_t>(252, "qform_code");
  const int sform_code = h.At<std::int16_t>(254, "sform_code");
  Eigen::Matrix4d ras = Eigen::Matrix4d::Identity();
  if (sform_code > 0) {
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 4; ++col) {
        ras(row, col) = h.Float(280 + static_cast<std::size_t>(16 * row + 4 * col), "srow");
      }
    }
    source = "nifti sform (code " + std::to_string(sform_code) + ")";
  } else if (qform_code > 0) {
    ras = QformAffine(h);
    source = "nifti qform (code " + std::to_string(qform_code) + ")";
  } else {  // nifti1.h method 1 (ANALYZE 7.5): pixdim scaling only, no origin
    for (int axis = 0; axis < 3; ++axis) {
      ras(axis, axis) = h.Float(80 + 4 * static_cast<std::size_t>(axis), "pixdim");
      if (!(ras(axis, axis) > 0.0) || !std::isfinite(ras(axis, axis))) {
        h.Fail(80, "pixdim must be > 0 without sform/qform");
      }
    }
    source = "nifti pixdim (no sform/qform)";
  }
  const int space_unit = h.At<std::uint8_t>(123, "xyzt_units") & 0x07;
  const double to_mm = space_unit == 1 ? 1000.0 : space_unit == 3 ? 0.001 : 1.0;  // m, um
  Eigen::Matrix4d lps = ras;
  lps.topRows<3>() = to_mm * kRasToLps.asDiagonal() * ras.topRows<3>();
  return lps;
}

}  // namespace

CtVolume DecodeNifti(std::span<const std::uint8_t> bytes, const std::filesystem::path& path) {
  const bool gzip = HasGzipMagic(bytes);
  const std::string where = gzip ? " (decompressed stream offset)" : "";
  std::vector<std::uint8_t> inflated;
  std::span<const std::uint8_t> file = bytes;
  if (gzip) {
    inflated = InflateGzip(bytes, path, kHeaderBytes);
    file = inflated;
  }
  if (file.size() < kHeaderBytes) {
    throw IoError(path, file.size(), "expected a 348-byte NIfTI-1 header" + where);
  }
  ByteReader probe(file, path);
  const std::int32_t size_le = probe.Le<std::int32_t>("sizeof_hdr");
  const bool big_endian = size_le != 348;
  if (big_endian && ByteReader(file, path).Be<std::int32_t>("sizeof_hdr") != 348) {
    throw IoError(path, 0,
                  size_le == 540 ? "NIfTI-2 is not supported"
                                 : "expected sizeof_hdr 348 (NIfTI-1) in either byte order");
  }
  // A copy: `file` may point into a buffer that is re-inflated below.
  const std::vector<std::uint8_t> header(file.begin(), file.begin() + kHeaderBytes);
  const HeaderReader h(header, path, big_endian);
  const std::string magic(reinterpret_cast<const char*>(file.data()) + 344, 4);
  if (magic == std::string("ni1\0", 4)) h.Fail(344, "two-file NIfTI (.hdr/.img) is not supported");
  if (magic != std::string("n+1\0", 4)) h.Fail(344, "expected magic \"n+1\"");

  std::array<std::uint64_t, 3> sizes{};
  const int rank = h.At<std::int16_t>(40, "dim[0]");
  if (rank != 3 && !(rank == 4 && h.At<std::int16_t>(48, "dim[4]") == 1)) {
    h.Fail(40, "expected dim[0] = 3, or 4 with dim[4] = 1");
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const int size = h.At<std::int16_t>(42 + 2 * axis, "dim");
    if (size < 1) h.Fail(42 + 2 * axis, "dim[1..3] must be positive");
    sizes[axis] = static_cast<std::uint64_t>(size);
  }
  const int datatype = h.At<std::int16_t>(70, "datatype");
  const auto type = SampleTypeOf(datatype);
  if (!type) h.Fail(70, "unsupported datatype " + std::to_string(datatype));
  const double vox_offset = h.Float(108, "vox_offset");
  if (!(vox_offset >= static_cast<double>(kHeaderBytes)) || vox_offset > 1e12 ||
      vox_offset != std::floor(vox_offset)) {
    h.Fail(108, "vox_offset must be an integer >= 348");
  }
  const auto data_bytes = *CheckedVolumeBytes(sizes, SampleSize(*type));  // < 2^48: no overflow
  const auto data_offset = static_cast<std::uint64_t>(vox_offset);
  const std::uint64_t needed = data_offset + data_bytes;
  if (gzip) {
    if (needed > bytes.size() * kMaxDeflateRatio + 1024) {
      throw IoError(path, bytes.size(),
                    "gzip stream too short to hold " + std::to_string(needed) +
                        " bytes of header and voxels");
    }
    inflated = InflateGzip(bytes, path, needed);
    file = inflated;
  }
  if (file.size() < needed) {
    throw IoError(path, file.size(),
                  "vox_offset " + std::to_string(data_offset) + " + " + std::to_string(data_bytes) +
                      " voxel bytes runs past the end at " + std::to_string(file.size()) + where);
  }
  CtVolume volume;
  for (int axis = 0; axis < 3; ++axis) volume.dims[axis] = static_cast<int>(sizes[axis]);
  volume.image_from_ijk = Geometry(h, volume.geometry_source);
  volume.name = path.filename().string();
  volume.values.resize(data_bytes / SampleSize(*type));
  DecodeSamples(file.subspan(data_offset, data_bytes), *type,
                big_endian ? std::endian::big : std::endian::little, volume.values);
  const double slope = h.Float(112, "scl_slope");
  const double inter = h.Float(116, "scl_inter");
  if (slope != 0.0 && std::isfinite(slope)) {  // slope 0 (or NaN, as nibabel writes) = unscaled
    const double offset = std::isfinite(inter) ? inter : 0.0;
    for (float& value : volume.values) value = NarrowToFloat(slope * value + offset);
  }
  try {
    volume.Check();
  } catch (const PreconditionError& error) {
    h.Fail(252, std::string("invalid orientation: ") + error.what());
  }
  return volume;
}

CtVolume ReadNifti(const std::filesystem::path& path) {
  return DecodeNifti(ReadFileBytes(path), path);
}

std::vector<std::uint8_t> EncodeNifti(const CtVolume& volume, const VolumeWriteOptions& options) {
  options.Check();
  volume.Check();
  Require(volume.nx() <= 32767 && volume.ny() <= 32767 && volume.nz() <= 32767,
          "NIfTI-1 dimensions must fit in int16");
  Eigen::Matrix4d ras = volume.image_from_ijk;
  ras.topRows<3>() = kRasToLps.asDiagonal() * volume.image_from_ijk.topRows<3>();  // self-inverse
  const Eigen::Vector3d spacing = volume.spacing_mm();
  Eigen::Matrix3d rotation = ras.topLeftCorner<3, 3>() * spacing.cwiseInverse().asDiagonal();
  const double qfac = rotation.determinant() < 0.0 ? -1.0 : 1.0;
  rotation.col(2) *= qfac;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Quaterniond q(Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose()));
  if (q.w() < 0.0) q.coeffs() *= -1.0;  // nifti1.h needs a >= 0

  const bool int16 = options.sample_type == VolumeSampleType::kInt16;
  ByteWriter w;
  const auto f32 = [&w](double value) { w.Le<float>(static_cast<float>(value)); };
  w.Le<std::int32_t>(348);
  w.Bytes(std::vector<std::uint8_t>(36, 0));  // data_type .. dim_info: unused in NIfTI-1
  for (const int dim : {3, volume.nx(), volume.ny(), volume.nz(), 1, 1, 1, 1}) {
    w.Le<std::int16_t>(static_cast<std::int16_t>(dim));
  }
  for (int n = 0; n < 3; ++n) f32(0.0);  // intent_p1..3
  w.Le<std::int16_t>(0);                 // intent_code
  w.Le<std::int16_t>(int16 ? 4 : 16);    // datatype
  w.Le<std::int16_t>(int16 ? 16 : 32);   // bitpix
  w.Le<std::int16_t>(0);                 // slice_start
  for (const double pixdim : {qfac, spacing.x(), spacing.y(), spacing.z(), 1.0, 1.0, 1.0, 1.0}) {
    f32(pixdim);
  }
  f32(static_cast<double>(kSingleFileVoxOffset));
  f32(1.0);                              // scl_slope
  f32(0.0);                              // scl_inter
  w.Le<std::int16_t>(0);                 // slice_end
  w.Le<std::uint8_t>(0);                 // slice_code
  w.Le<std::uint8_t>(2);                 // xyzt_units: mm
  for (int n = 0; n < 4; ++n) f32(0.0);  // cal_max, cal_min, slice_duration, toffset
  w.Le<std::int32_t>(0);                 // glmax
  w.Le<std::int32_t>(0);                 // glmin
  std::string descrip = "tofnav " + volume.modality + " " + volume.name;
  descrip.resize(80, '\0');
  w.Text(descrip);
  w.Bytes(std::vector<std::uint8_t>(24, 0));  // aux_file
  w.Le<std::int16_t>(1);                      // qform_code: scanner
  w.Le<std::int16_t>(1);                      // sform_code: scanner
  for (const double value : {q.x(), q.y(), q.z(), ras(0, 3), ras(1, 3), ras(2, 3)}) f32(value);
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) f32(ras(row, col));
  }
  w.Bytes(std::vector<std::uint8_t>(16, 0));  // intent_name
  w.Text(std::string("n+1\0", 4));
  w.Bytes(std::vector<std::uint8_t>(4, 0));  // extension flag: none
  w.Bytes(EncodeSamples(volume.values, options.sample_type));
  return w.Release();
}

void WriteNifti(const std::filesystem::path& path, const CtVolume& volume,
                const VolumeWriteOptions& options) {
  std::vector<std::uint8_t> bytes = EncodeNifti(volume, options);
  if (path.extension() == ".gz") bytes = DeflateGzip(bytes, options.gzip_level);
  WriteFileAtomically(path, bytes);
}

}  // namespace tofnav
