// SPDX-License-Identifier: BSD-3-Clause
// .inv3 reader: streaming gunzip, a minimal ustar walk (private here; to be shared if another
// reader needs tar), main.plist through plist.hpp.
#include "tofnav/io/inv3.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/io/gzip.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/plist.hpp"
#include "tofnav/io/volume_samples.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kTarBlock = 512;
constexpr std::uint64_t kMaxPlistBytes = 1 << 20;  // main.plist is ~1.5 kB
constexpr std::size_t kChunkBytes = 1 << 20;
constexpr int kAxialOrientation = 1;  // InVesalius' code for an axial stack

// A numeric tar header field: octal digits (space/NUL padded) or GNU base-256 (high bit set).
std::optional<std::uint64_t> TarNumber(std::span<const std::uint8_t> field) {
  std::uint64_t value = 0;
  if ((field[0] & 0x80u) != 0) {
    if ((field[0] & 0x7fu) != 0 || field[1] != 0 || field[2] != 0 || field[3] != 0) {
      return std::nullopt;  // beyond 2^64 or negative
    }
    for (std::size_t n = 4; n < field.size(); ++n) value = (value << 8) | field[n];
    return value;
  }
  std::size_t n = 0;
  while (n < field.size() && field[n] == ' ') ++n;
  const std::size_t first_digit = n;
  for (; n < field.size() && field[n] >= '0' && field[n] <= '7'; ++n) {
    value = value * 8 + static_cast<std::uint64_t>(field[n] - '0');
  }
  for (std::size_t rest = n; rest < field.size(); ++rest) {
    if (field[rest] != ' ' && field[rest] != 0) return std::nullopt;
  }
  if (n == first_digit) return std::nullopt;
  return value;
}

// The next `size` bytes of the tar stream, grown chunk by chunk as data really arrives.
std::vector<std::uint8_t> ReadMember(GzipInflater& in, std::uint64_t size,
                                     const std::filesystem::path& path, const std::string& name) {
  std::vector<std::uint8_t> data;
  const std::uint64_t start = in.produced();
  while (data.size() < size) {
    const auto step =
        static_cast<std::size_t>(std::min<std::uint64_t>(size - data.size(), kChunkBytes));
    const std::size_t old_size = data.size();
    data.resize(old_size + step);
    if (in.Read(std::span(data).subspan(old_size, step)) != step) {
      throw IoError(path, start,
                    "tar member " + name + " truncated: expected " + std::to_string(size) +
                        " bytes (decompressed tar offset)");
    }
  }
  return data;
}

double Number(const PlistValue* value, const std::filesystem::path& path, const char* what) {
  double number = 0.0;
  if (value != nullptr && value->kind == PlistValue::Kind::kNumber) {
    const std::string& t = value->text;
    const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), number);
    if (error == std::errc() && end == t.data() + t.size() && std::isfinite(number)) return number;
  }
  throw IoError(path, std::nullopt, std::string("main.plist: expected a number for ") + what);
}

std::array<double, 3> Triple(const PlistValue* array, const std::filesystem::path& path,
                             const char* what) {
  if (array == nullptr || array->kind != PlistValue::Kind::kArray || array->items.size() != 3) {
    throw IoError(path, std::nullopt, std::string("main.plist: expected 3 values in ") + what);
  }
  return {Number(&array->items[0], path, what), Number(&array->items[1], path, what),
          Number(&array->items[2], path, what)};
}

std::string Text(const PlistValue* value) {
  return value != nullptr && value->kind == PlistValue::Kind::kString ? value->text : "";
}

CtVolume BuildVolume(const PlistValue& root, std::vector<std::uint8_t> matrix,
                     std::uint64_t matrix_offset, const std::filesystem::path& path) {
  const PlistValue* info = root.Find("matrix");
  if (info == nullptr || Text(info->Find("dtype")) != "int16") {
    throw IoError(path, std::nullopt, "main.plist: expected matrix.dtype int16");
  }
  if (const PlistValue* orientation = root.Find("orientation");
      orientation != nullptr && Number(orientation, path, "orientation") != kAxialOrientation) {
    throw IoError(path, std::nullopt, "only axial InVesalius projects (orientation 1) supported");
  }
  const std::array<double, 3> shape = Triple(info->Find("shape"), path, "matrix.shape");  // z y x
  const std::array<double, 3> spacing = Triple(root.Find("spacing"), path, "spacing");    // x y z
  CtVolume volume;
  for (int axis = 0; axis < 3; ++axis) {
    const double size = shape[static_cast<std::size_t>(2 - axis)];
    const double step = spacing[static_cast<std::size_t>(axis)];
    if (!(size >= 1.0 && size <= 65535.0) || size != std::floor(size) || !(step > 0.0)) {
      throw IoError(path, std::nullopt, "main.plist: bad matrix.shape or spacing");
    }
    volume.dims[axis] = static_cast<int>(size);
    volume.image_from_ijk(axis, axis) = step;
  }
  volume.image_from_ijk(1, 1) = -spacing[1];  // rows are stored bottom-up: j -> anterior (-y)
  volume.geometry_source = "inv3 (no orientation stored: origin 0, i->L, j->A, k->S assumed)";
  volume.modality = Text(root.Find("modality"));
  volume.name = Text(root.Find("name"));
  if (matrix.size() != volume.voxel_count() * sizeof(std::int16_t)) {
    throw IoError(path, matrix_offset,
                  "matrix data holds " + std::to_string(matrix.size()) + " bytes, shape needs " +
                      std::to_string(volume.voxel_count() * 2) + " (decompressed tar offset)");
  }
  volume.values.resize(volume.voxel_count());
  DecodeSamples(matrix, SampleType::kInt16, std::endian::little, volume.values);
  return volume;
}

}  // namespace

CtVolume DecodeInv3(std::span<const std::uint8_t> bytes, const std::filesystem::path& path) {
  GzipInflater in(bytes, path);
  std::optional<PlistValue> plist;
  std::optional<std::vector<std::uint8_t>> matrix;
  std::uint64_t matrix_offset = 0;
  std::string matrix_name = "matrix.dat", long_name;
  std::array<std::uint8_t, kTarBlock> block{};
  while (true) {
    const std::uint64_t header_offset = in.produced();
    const std::size_t got = in.Read(block);
    if (got == 0 || std::all_of(block.begin(), block.end(), [](auto b) { return b == 0; })) break;
    if (got != kTarBlock) throw IoError(path, header_offset, "truncated tar header");
    std::uint64_t sum = 0;
    for (std::size_t n = 0; n < kTarBlock; ++n) sum += n >= 148 && n < 156 ? ' ' : block[n];
    const auto checksum = TarNumber(std::span(block).subspan(148, 8));
    const auto size = TarNumber(std::span(block).subspan(124, 12));
    if (!checksum || *checksum != sum || !size || *size > (std::uint64_t{1} << 40)) {
      throw IoError(path, header_offset, "bad tar header (checksum or size; decompressed offset)");
    }
    const char type = static_cast<char>(block[156]);
    std::string name(reinterpret_cast<const char*>(block.data()), 100);
    name.resize(name.find('\0') == std::string::npos ? name.size() : name.find('\0'));
    if (!long_name.empty()) name = std::exchange(long_name, "");
    const std::string base =
        name.substr(name.find_last_of('/') == std::string::npos ? 0 : name.find_last_of('/') + 1);
    const std::uint64_t padding = (kTarBlock - *size % kTarBlock) % kTarBlock;
    const bool regular = type == '0' || type == '\0';
    if (type == 'L' && *size <= 4096) {  // GNU long name of the next member
      const auto data = ReadMember(in, *size, path, "long name");
      long_name.assign(data.begin(), std::find(data.begin(), data.end(), std::uint8_t{0}));
    } else if (regular && base == "main.plist") {
      if (*size > kMaxPlistBytes) throw IoError(path, header_offset, "main.plist too large");
      const std::uint64_t data_offset = in.produced();
      const auto data = ReadMember(in, *size, path, name);
      const std::string_view text(reinterpret_cast<const char*>(data.data()), data.size());
      plist = ParsePlist(text, path, data_offset);
      if (const auto* info = plist->Find("matrix");
          info != nullptr && !Text(info->Find("filename")).empty()) {
        matrix_name = Text(info->Find("filename"));
      }
    } else if (regular && base == matrix_name) {
      matrix_offset = in.produced();
      matrix = ReadMember(in, *size, path, name);
    } else if (in.Skip(*size) != *size) {
      throw IoError(path, in.produced(), "tar member " + name + " truncated");
    }
    if (in.Skip(padding) != padding) throw IoError(path, in.produced(), "tar padding truncated");
  }
  if (!plist || plist->kind != PlistValue::Kind::kDict || !matrix) {
    throw IoError(path, std::nullopt, "expected main.plist and " + matrix_name + " in the archive");
  }
  return BuildVolume(*plist, std::move(*matrix), matrix_offset, path);
}

CtVolume ReadInv3(const std::filesystem::path& path) {
  return DecodeInv3(ReadFileBytes(path), path);
}

}  // namespace tofnav
