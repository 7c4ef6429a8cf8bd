// SPDX-License-Identifier: BSD-3-Clause
// .inv3 reader: gunzip (gzip.hpp), the archive index (tar.hpp), main.plist (plist.hpp) and the
// int16 matrix.
#include "tofnav/volume/inv3.hpp"

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
#include "tofnav/io/tar.hpp"
#include "tofnav/volume/plist.hpp"
#include "tofnav/volume/volume_samples.hpp"

namespace tofnav {
namespace {

constexpr std::uint64_t kMaxPlistBytes = 1 << 20;  // main.plist is ~1.5 kB
// Refuse archives that inflate beyond this (a gzip bomb); a 512 x 512 x 2000 CT project with
// masks and surfaces stays far below.
constexpr std::size_t kMaxArchiveBytes = std::size_t{8} << 30;
constexpr int kAxialOrientation = 1;  // InVesalius' code for an axial stack

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

CtVolume BuildVolume(const PlistValue& root, std::span<const std::uint8_t> matrix,
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
  // The whole tar in memory (Cranium.inv3: 44 MB); it grows only with real decompressed output.
  const std::vector<std::uint8_t> tar = InflateGzip(bytes, path, kMaxArchiveBytes + 1);
  if (tar.size() > kMaxArchiveBytes) throw IoError(path, 0, "archive inflates beyond 8 GiB");
  const TarIndex index = IndexTar(tar, path, {.allow_truncated_tail = false});
  const auto find = [&index](std::string_view wanted) -> const TarEntry* {
    for (const TarEntry& entry : index.entries) {
      const std::size_t slash = entry.name.find_last_of('/');
      if (entry.name.substr(slash == std::string::npos ? 0 : slash + 1) == wanted) return &entry;
    }
    return nullptr;
  };
  const TarEntry* plist_entry = find("main.plist");
  if (plist_entry == nullptr) throw IoError(path, std::nullopt, "no main.plist in the archive");
  if (plist_entry->size > kMaxPlistBytes) {
    throw IoError(path, plist_entry->header_offset, "main.plist too large");
  }
  const auto plist_bytes = std::span(tar).subspan(plist_entry->data_offset, plist_entry->size);
  const PlistValue plist = ParsePlist(
      std::string_view(reinterpret_cast<const char*>(plist_bytes.data()), plist_bytes.size()), path,
      plist_entry->data_offset);
  if (plist.kind != PlistValue::Kind::kDict) {
    throw IoError(path, std::nullopt, "main.plist: not a dict");
  }
  const PlistValue* info = plist.Find("matrix");
  const std::string matrix_name = info != nullptr && !Text(info->Find("filename")).empty()
                                      ? Text(info->Find("filename"))
                                      : "matrix.dat";
  const TarEntry* matrix = find(matrix_name);
  if (matrix == nullptr) throw IoError(path, std::nullopt, "no " + matrix_name + " in the archive");
  return BuildVolume(plist, std::span(tar).subspan(matrix->data_offset, matrix->size),
                     matrix->data_offset, path);
}

CtVolume ReadInv3(const std::filesystem::path& path) {
  return DecodeInv3(ReadFileBytes(path), path);
}

}  // namespace tofnav
