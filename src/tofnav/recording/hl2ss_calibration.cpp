// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT calibration: the `rm_depth_ahat/` folder and the Mode-2 blob (docs/ahat.md section 5).
#include "tofnav/recording/hl2ss_calibration.hpp"

#include <array>
#include <bit>
#include <cstring>
#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_matrix.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {
namespace {

static_assert(std::endian::native == std::endian::little, "hl2ss calibration files are LE f32");
static_assert(sizeof(Eigen::Vector2f) == 2 * sizeof(float), "tables are copied as (x, y) pairs");

constexpr std::size_t kPixels = kAhatPixels;
constexpr std::size_t kTableBytes = 2 * kPixels * sizeof(float);  // interleaved (x, y)
constexpr std::size_t kMatrixBytes = 16 * sizeof(float);
constexpr std::size_t kScalarBytes = sizeof(float);
// Mode-2 float offsets (docs/ahat.md section 5.1).
constexpr std::size_t kMode2X = 0;
constexpr std::size_t kMode2Y = kPixels;
constexpr std::size_t kMode2Extrinsics = 2 * kPixels;
constexpr std::size_t kMode2Scale = kMode2Extrinsics + 16;
constexpr std::size_t kMode2Alias = kMode2Scale + 1;
constexpr std::size_t kMode2MapX = kMode2Alias + 1;
constexpr std::size_t kMode2MapY = kMode2MapX + kPixels;
constexpr std::size_t kMode2K = kMode2MapY + kPixels;
static_assert((kMode2K + 4) * sizeof(float) == kHl2ssMode2Bytes);

/// The calibration fields as stored: f32, extrinsics rig -> camera (row-vector, metres).
struct StoredCalibration {
  Image<Eigen::Vector2f> uv2xy{kAhatWidth, kAhatHeight, Eigen::Vector2f::Zero()};
  Image<Eigen::Vector2f> undistort_map{kAhatWidth, kAhatHeight, Eigen::Vector2f::Zero()};
  DirectXMatrix rig_to_camera{};
  std::array<float, 4> fx_fy_cx_cy{};
  float scale = 0.0f;
  float alias_mm = 0.0f;
};

AhatCalibration FromStored(const StoredCalibration& stored, const std::filesystem::path& source,
                           std::uint64_t extrinsics_offset, std::optional<double> override_px) {
  AhatCalibration calibration;
  calibration.uv2xy = stored.uv2xy;
  calibration.undistort_map = stored.undistort_map;
  // E maps rig to camera (p_cam = [p_rig 1] E), so it is ahat_from_rig in column form.
  calibration.rig_from_ahat =
      RigidFromDirectX(stored.rig_to_camera, source, extrinsics_offset).Inverse();
  const auto& k = stored.fx_fy_cx_cy;
  calibration.pinhole_fx_fy_cx_cy = Eigen::Vector4f(k[0], k[1], k[2], k[3]).cast<double>();
  calibration.scale = stored.scale;
  calibration.alias_mm = stored.alias_mm;
  if (override_px) {
    Require(*override_px == 0.0 || *override_px == 0.5, "sample offset override must be 0 or 0.5");
    calibration.sample_offset_px = *override_px;
  } else {
    // Auto rule (docs/ahat.md 5.3): a square pinhole means hl2ss >= v1.0.37, sampled at (i, j).
    calibration.sample_offset_px = k[0] == k[1] ? 0.0 : 0.5;
  }
  return calibration;
}

StoredCalibration ToStored(const AhatCalibration& calibration) {
  Require(calibration.uv2xy.width() == kAhatWidth && calibration.uv2xy.height() == kAhatHeight,
          "hl2ss calibration needs a 512 x 512 uv2xy table");
  const bool has_map = !calibration.undistort_map.empty();
  Require(!has_map || (calibration.undistort_map.width() == kAhatWidth &&
                       calibration.undistort_map.height() == kAhatHeight),
          "the undistort map must be empty or 512 x 512");
  StoredCalibration stored;
  stored.uv2xy = calibration.uv2xy;
  stored.undistort_map =
      has_map ? calibration.undistort_map
              : Image<Eigen::Vector2f>(kAhatWidth, kAhatHeight, Eigen::Vector2f(-1.0f, -1.0f));
  stored.rig_to_camera = DirectXFromRigid(calibration.rig_from_ahat.Inverse());
  for (Eigen::Index i = 0; i < 4; ++i) {
    stored.fx_fy_cx_cy[static_cast<std::size_t>(i)] =
        static_cast<float>(calibration.pinhole_fx_fy_cx_cy[i]);
  }
  stored.scale = static_cast<float>(calibration.scale);
  stored.alias_mm = static_cast<float>(calibration.alias_mm);
  return stored;
}

std::span<const std::uint8_t> TableBytes(const Image<Eigen::Vector2f>& table) {
  return {reinterpret_cast<const std::uint8_t*>(table.data()), kTableBytes};
}

void CopyTable(std::span<const std::uint8_t> bytes, Image<Eigen::Vector2f>& table) {
  std::memcpy(static_cast<void*>(table.data()), bytes.data(), kTableBytes);
}

template <std::size_t kCount>
std::array<float, kCount> Floats(std::span<const std::uint8_t> bytes) {
  std::array<float, kCount> values;
  std::memcpy(values.data(), bytes.data(), sizeof(values));
  return values;
}

std::vector<std::uint8_t> ReadExactly(const std::filesystem::path& path, std::size_t bytes,
                                      const char* layout) {
  const RandomAccessFile file(path);
  if (file.size() != bytes) {
    throw IoError(path, std::nullopt,
                  "expected exactly " + std::to_string(bytes) + " bytes (" + layout + "), found " +
                      std::to_string(file.size()));
  }
  return file.ReadAt(0, bytes, layout);
}

std::filesystem::path CalibrationFolder(const std::filesystem::path& path) {
  if (std::filesystem::is_directory(path / "rm_depth_ahat")) return path / "rm_depth_ahat";
  if (std::filesystem::is_regular_file(path / "uv2xy.bin")) return path;
  throw IoError(path, std::nullopt,
                "expected an hl2ss calibration folder holding rm_depth_ahat/ or uv2xy.bin");
}

std::vector<std::uint8_t> FloatBytes(std::span<const float> values) {
  std::vector<std::uint8_t> bytes(values.size_bytes());
  std::memcpy(bytes.data(), values.data(), bytes.size());
  return bytes;
}

StoredCalibration ReadFolder(const std::filesystem::path& folder) {
  StoredCalibration stored;
  CopyTable(ReadExactly(folder / "uv2xy.bin", kTableBytes, "512 x 512 x 2 f32"), stored.uv2xy);
  CopyTable(ReadExactly(folder / "undistort_map.bin", kTableBytes, "512 x 512 x 2 f32"),
            stored.undistort_map);
  stored.rig_to_camera =
      Floats<16>(ReadExactly(folder / "extrinsics.bin", kMatrixBytes, "4 x 4 f32"));
  const auto intrinsics =
      Floats<16>(ReadExactly(folder / "intrinsics.bin", kMatrixBytes, "4 x 4 f32"));
  // Row-vector projection [[fx,0,0,0],[0,fy,0,0],[cx,cy,1,0],[0,0,0,1]].
  stored.fx_fy_cx_cy = {intrinsics[0], intrinsics[5], intrinsics[8], intrinsics[9]};
  stored.scale = Floats<1>(ReadExactly(folder / "scale.bin", kScalarBytes, "one f32"))[0];
  stored.alias_mm = Floats<1>(ReadExactly(folder / "alias.bin", kScalarBytes, "one f32"))[0];
  return stored;
}

void WriteFolder(const std::filesystem::path& folder, const StoredCalibration& stored) {
  const std::filesystem::path out = folder / "rm_depth_ahat";
  std::filesystem::create_directories(out);
  const auto& k = stored.fx_fy_cx_cy;
  const std::array<float, 16> intrinsics = {k[0], 0,    0, 0, 0, k[1], 0, 0,
                                            k[2], k[3], 1, 0, 0, 0,    0, 1};
  WriteFileAtomically(out / "uv2xy.bin", TableBytes(stored.uv2xy));
  WriteFileAtomically(out / "undistort_map.bin", TableBytes(stored.undistort_map));
  WriteFileAtomically(out / "extrinsics.bin", FloatBytes(stored.rig_to_camera));
  WriteFileAtomically(out / "intrinsics.bin", FloatBytes(intrinsics));
  WriteFileAtomically(out / "scale.bin", FloatBytes(std::span(&stored.scale, 1)));
  WriteFileAtomically(out / "alias.bin", FloatBytes(std::span(&stored.alias_mm, 1)));
}

StoredCalibration DecodeMode2(std::span<const std::uint8_t> bytes,
                              const std::filesystem::path& source) {
  if (bytes.size() != kHl2ssMode2Bytes) {
    throw IoError(source, std::min(bytes.size(), kHl2ssMode2Bytes),
                  "expected an AHAT Mode-2 calibration of exactly " +
                      std::to_string(kHl2ssMode2Bytes) + " bytes, found " +
                      std::to_string(bytes.size()));
  }
  std::vector<float> floats(kHl2ssMode2Bytes / sizeof(float));
  std::memcpy(floats.data(), bytes.data(), bytes.size());
  StoredCalibration stored;
  for (std::size_t i = 0; i < kPixels; ++i) {  // planar -> interleaved
    stored.uv2xy.data()[i] = {floats[kMode2X + i], floats[kMode2Y + i]};
    stored.undistort_map.data()[i] = {floats[kMode2MapX + i], floats[kMode2MapY + i]};
  }
  std::memcpy(stored.rig_to_camera.data(), &floats[kMode2Extrinsics], kMatrixBytes);
  stored.scale = floats[kMode2Scale];
  stored.alias_mm = floats[kMode2Alias];
  std::memcpy(stored.fx_fy_cx_cy.data(), &floats[kMode2K], sizeof(stored.fx_fy_cx_cy));
  return stored;
}

std::vector<std::uint8_t> EncodeMode2(const StoredCalibration& stored) {
  std::vector<float> floats(kHl2ssMode2Bytes / sizeof(float));
  for (std::size_t i = 0; i < kPixels; ++i) {  // interleaved -> planar
    floats[kMode2X + i] = stored.uv2xy.data()[i].x();
    floats[kMode2Y + i] = stored.uv2xy.data()[i].y();
    floats[kMode2MapX + i] = stored.undistort_map.data()[i].x();
    floats[kMode2MapY + i] = stored.undistort_map.data()[i].y();
  }
  std::memcpy(&floats[kMode2Extrinsics], stored.rig_to_camera.data(), kMatrixBytes);
  floats[kMode2Scale] = stored.scale;
  floats[kMode2Alias] = stored.alias_mm;
  std::memcpy(&floats[kMode2K], stored.fx_fy_cx_cy.data(), sizeof(stored.fx_fy_cx_cy));
  return FloatBytes(floats);
}

}  // namespace

AhatCalibration ReadHl2ssCalibration(const std::filesystem::path& path,
                                     std::optional<double> sample_offset_override) {
  const std::filesystem::path folder = CalibrationFolder(path);
  return FromStored(ReadFolder(folder), folder / "extrinsics.bin", 0, sample_offset_override);
}

void WriteHl2ssCalibration(const std::filesystem::path& folder,
                           const AhatCalibration& calibration) {
  WriteFolder(folder, ToStored(calibration));
}

AhatCalibration DecodeHl2ssMode2(std::span<const std::uint8_t> bytes,
                                 const std::filesystem::path& source,
                                 std::optional<double> sample_offset_override) {
  return FromStored(DecodeMode2(bytes, source), source, kMode2Extrinsics * sizeof(float),
                    sample_offset_override);
}

std::vector<std::uint8_t> EncodeHl2ssMode2(const AhatCalibration& calibration) {
  return EncodeMode2(ToStored(calibration));
}

std::vector<std::uint8_t> ReadHl2ssCalibrationAsMode2(const std::filesystem::path& path) {
  return EncodeMode2(ReadFolder(CalibrationFolder(path)));
}

void WriteHl2ssMode2AsFolder(const std::filesystem::path& folder,
                             std::span<const std::uint8_t> bytes,
                             const std::filesystem::path& source) {
  WriteFolder(folder, DecodeMode2(bytes, source));
}

}  // namespace tofnav
