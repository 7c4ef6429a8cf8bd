// SPDX-License-Identifier: BSD-3-Clause
// Volume format dispatch: content first (magic numbers), extension second.
#include "tofnav/volume/volume_io.hpp"

#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/gzip.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/volume/dicom.hpp"
#include "tofnav/volume/inv3.hpp"
#include "tofnav/volume/nifti.hpp"
#include "tofnav/volume/nrrd.hpp"

namespace tofnav {
namespace {

bool StartsWith(std::span<const std::uint8_t> bytes, std::size_t offset, std::string_view text) {
  return bytes.size() >= offset + text.size() &&
         std::equal(text.begin(), text.end(), bytes.begin() + static_cast<std::ptrdiff_t>(offset));
}

bool IsNiftiHeader(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 4) return false;
  ByteReader le(bytes, "");
  ByteReader be(bytes, "");
  return le.Le<std::int32_t>("sizeof_hdr") == 348 || be.Be<std::int32_t>("sizeof_hdr") == 348;
}

bool EndsWith(const std::filesystem::path& path, std::string_view suffix) {
  const std::string name = path.filename().string();
  return name.size() >= suffix.size() &&
         name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

void VolumeWriteOptions::Check() const {
  Require(gzip_level >= 0 && gzip_level <= 9, "VolumeWriteOptions::gzip_level must be 0..9");
}

CtVolume ReadVolume(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return ReadDicomSeries(path);
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  const std::filesystem::path folder = path.parent_path().empty() ? "." : path.parent_path();
  if (StartsWith(bytes, 0, "NRRD000")) return DecodeNrrd(bytes, path, {.data_folder = folder});
  if (HasGzipMagic(bytes)) {
    const std::vector<std::uint8_t> head = InflateGzip(bytes, path, 512);
    if (StartsWith(head, 257, "ustar") || EndsWith(path, ".inv3")) return DecodeInv3(bytes, path);
    if (IsNiftiHeader(head) || EndsWith(path, ".nii.gz")) return DecodeNifti(bytes, path);
  } else if (IsNiftiHeader(bytes)) {
    return DecodeNifti(bytes, path);
  } else if (StartsWith(bytes, 128, "DICM")) {
    throw IoError(path, 128, "a single DICOM file: pass its folder to read the series");
  }
  throw IoError(path, 0, "unrecognised volume format (expected NRRD, NIfTI-1, .inv3 or a folder)");
}

void WriteVolume(const std::filesystem::path& path, const CtVolume& volume,
                 const VolumeWriteOptions& options) {
  options.Check();
  volume.Check();
  if (EndsWith(path, ".nrrd")) return WriteNrrd(path, volume, options);
  if (EndsWith(path, ".nii") || EndsWith(path, ".nii.gz")) return WriteNifti(path, volume, options);
  throw IoError(path, std::nullopt, "cannot write this extension (.nrrd, .nii, .nii.gz)");
}

}  // namespace tofnav
