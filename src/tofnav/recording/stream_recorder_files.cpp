// SPDX-License-Identifier: BSD-3-Clause
// StreamRecorder LUT and text matrices. Device files store metres; mm from here on.
#include "tofnav/recording/stream_recorder_files.hpp"

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kLutBytes = kStreamRecorderLutBytes;
static_assert(kLutBytes == std::size_t{kAhatPixels} * 3 * sizeof(float));
/// The recorder prints 6 significant digits, so a stored rotation is orthonormal only to ~1e-5;
/// FromMatrix re-orthonormalises within this tolerance (dimensionless).
constexpr double kRotationTolerance = 1e-4;
constexpr int kWrittenDigits = 9;  // float-exact (max_digits10 of float)

struct Line {
  std::string_view text;  // without the line break
  std::uint64_t offset = 0;
};

// Non-blank lines with their byte offsets; "\r\n" endings (Windows text mode) are accepted.
std::vector<Line> SplitLines(std::string_view text) {
  std::vector<Line> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find_first_not_of(" \t") != std::string_view::npos) lines.push_back({line, start});
    start = end + 1;
  }
  return lines;
}

float LoadLeFloat(const std::uint8_t* bytes) {
  std::uint32_t bits = 0;
  for (int i = 3; i >= 0; --i) bits = (bits << 8) | bytes[i];
  return std::bit_cast<float>(bits);
}

void StoreLeFloat(std::uint8_t* bytes, float value) {
  auto bits = std::bit_cast<std::uint32_t>(value);
  for (int i = 0; i < 4; ++i, bits >>= 8) bytes[i] = static_cast<std::uint8_t>(bits & 0xFFU);
}

std::string_view Trim(std::string_view field) {
  const std::size_t first = field.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return field.substr(first, field.find_last_not_of(" \t") - first + 1);
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(Trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

[[noreturn]] void Fail(const std::filesystem::path& source, const Line& line,
                       const std::string& message) {
  throw IoError(source, line.offset, message);
}

double ParseNumber(std::string_view field, std::size_t index, const std::filesystem::path& source,
                   const Line& line) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (error != std::errc{} || end != field.data() + field.size() || !std::isfinite(value)) {
    Fail(source, line,
         "expected a finite number in field " + std::to_string(index + 1) + ", found '" +
             std::string(field) + "'");
  }
  return value;
}

// 16 numbers, read row-major: the column-vector matrix (the recorder wrote the row-vector
// DirectX matrix column by column, docs/ahat.md 7.5), translation converted from m to mm.
Rigid3d ParseMatrix(std::span<const std::string_view> fields, std::size_t first,
                    const std::filesystem::path& source, const Line& line) {
  Eigen::Matrix4d matrix;
  for (int i = 0; i < 16; ++i) {
    const std::size_t index = first + static_cast<std::size_t>(i);
    matrix(i / 4, i % 4) = ParseNumber(fields[index], index, source, line);
  }
  matrix.topRightCorner<3, 1>() *= kMmPerMetre;
  if (!matrix.allFinite()) Fail(source, line, "translation overflows when converted to mm");
  try {
    return Rigid3d::FromMatrix(matrix, kRotationTolerance);
  } catch (const PreconditionError& error) {
    Fail(source, line, std::string("expected a rigid transform: ") + error.what());
  }
}

std::string FormatNumber(double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                    std::chars_format::general, kWrittenDigits);
  return {buffer.data(), result.ptr};
}

std::string FormatMatrix(const Rigid3d& b_from_a) {
  Eigen::Matrix4d matrix = b_from_a.ToMatrix();
  matrix.topRightCorner<3, 1>() /= kMmPerMetre;
  std::string text;
  for (int i = 0; i < 16; ++i) {
    if (i > 0) text += ',';
    text += FormatNumber(matrix(i / 4, i % 4));
  }
  return text;
}

}  // namespace

Image<Eigen::Vector2f> DecodeStreamRecorderLut(std::span<const std::uint8_t> bytes,
                                               const std::filesystem::path& source) {
  if (bytes.size() != kLutBytes) {
    throw IoError(source, std::min(bytes.size(), kLutBytes),
                  "expected " + std::to_string(kLutBytes) +
                      " bytes (512 x 512 x 3 float32), found " + std::to_string(bytes.size()));
  }
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  Image<Eigen::Vector2f> uv2xy(kAhatWidth, kAhatHeight, Eigen::Vector2f(kNaN, kNaN));
  const std::uint8_t* ray = bytes.data();
  for (Eigen::Vector2f& xy : uv2xy.pixels()) {  // raster order, as stored
    const auto x = static_cast<double>(LoadLeFloat(ray));
    const auto y = static_cast<double>(LoadLeFloat(ray + 4));
    const auto z = static_cast<double>(LoadLeFloat(ray + 8));
    ray += 12;
    if (!(z > 0.0) || !std::isfinite(z)) continue;  // z == 0: the API call failed
    const double x_over_z = x / z;
    const double y_over_z = y / z;
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    if (std::abs(x_over_z) <= kFloatMax && std::abs(y_over_z) <= kFloatMax) {  // false for NaN
      xy = Eigen::Vector2f(static_cast<float>(x_over_z), static_cast<float>(y_over_z));
    }
  }
  return uv2xy;
}

std::vector<std::uint8_t> EncodeStreamRecorderLut(const Image<Eigen::Vector2f>& uv2xy) {
  Require(uv2xy.width() == kAhatWidth && uv2xy.height() == kAhatHeight,
          "the StreamRecorder LUT needs a 512 x 512 table");
  std::vector<std::uint8_t> bytes(kLutBytes);
  std::uint8_t* ray = bytes.data();
  for (const Eigen::Vector2f& xy : uv2xy.pixels()) {
    const auto x = static_cast<double>(xy.x());
    const auto y = static_cast<double>(xy.y());
    const double norm = std::sqrt(x * x + y * y + 1.0);
    const bool valid = std::isfinite(norm);  // invalid entries: z = 0, as the recorder writes
    StoreLeFloat(ray, valid ? static_cast<float>(x / norm) : 0.0F);
    StoreLeFloat(ray + 4, valid ? static_cast<float>(y / norm) : 0.0F);
    StoreLeFloat(ray + 8, valid ? static_cast<float>(1.0 / norm) : 0.0F);
    ray += 12;
  }
  return bytes;
}

Rigid3d ParseStreamRecorderExtrinsics(std::string_view text, const std::filesystem::path& source) {
  const std::vector<Line> lines = SplitLines(text);
  if (lines.size() != 1) {
    const Line where = lines.empty() ? Line{} : lines[1];
    Fail(source, where,
         "expected one line of 16 comma-separated numbers, found " + std::to_string(lines.size()) +
             " lines");
  }
  const std::vector<std::string_view> fields = SplitFields(lines[0].text);
  if (fields.size() != 16) {
    Fail(source, lines[0],
         "expected 16 comma-separated numbers, found " + std::to_string(fields.size()) + " fields");
  }
  const Rigid3d ahat_from_rig = ParseMatrix(fields, 0, source, lines[0]);  // stored rig -> camera
  return ahat_from_rig.Inverse();
}

std::string FormatStreamRecorderExtrinsics(const Rigid3d& rig_from_ahat) {
  return FormatMatrix(rig_from_ahat.Inverse()) + "\n";
}

std::map<std::uint64_t, Rigid3d> ParseStreamRecorderRig2World(std::string_view text,
                                                              const std::filesystem::path& source) {
  std::map<std::uint64_t, Rigid3d> world_from_rig;
  for (const Line& line : SplitLines(text)) {
    const std::vector<std::string_view> fields = SplitFields(line.text);
    if (fields.size() != 17) {
      Fail(source, line,
           "expected a timestamp and 16 comma-separated numbers, found " +
               std::to_string(fields.size()) + " fields");
    }
    std::uint64_t filetime = 0;
    const std::string_view ts = fields[0];
    const auto [end, error] = std::from_chars(ts.data(), ts.data() + ts.size(), filetime);
    if (error != std::errc{} || end != ts.data() + ts.size()) {
      Fail(source, line, "expected an unsigned 64-bit timestamp, found '" + std::string(ts) + "'");
    }
    const Rigid3d pose = ParseMatrix(fields, 1, source, line);
    if (!world_from_rig.emplace(filetime, pose).second) {
      Fail(source, line, "duplicate timestamp " + std::to_string(filetime));
    }
  }
  return world_from_rig;
}

std::string FormatStreamRecorderRig2WorldLine(std::uint64_t filetime,
                                              const Rigid3d& world_from_rig) {
  return std::to_string(filetime) + "," + FormatMatrix(world_from_rig) + "\n";
}

}  // namespace tofnav
