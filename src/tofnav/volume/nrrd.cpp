// SPDX-License-Identifier: BSD-3-Clause
// NRRD reader/writer: our own parser of the fields listed in teem's format description.
#include "tofnav/volume/nrrd.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/gzip.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/volume/nrrd_header.hpp"
#include "tofnav/volume/volume_samples.hpp"

namespace tofnav {
namespace {

// image_from_ijk from space directions, else spacings, else unit steps (docs/openigtlink.md 5.2).
void SetGeometry(const NrrdHeader& h, const std::filesystem::path& path, CtVolume& volume) {
  const auto fail = [&](const std::string& message) { throw IoError(path, h.end_offset, message); };
  const std::size_t first = h.dimension == 4 ? 1 : 0;  // leading non-spatial axis (4-D)
  if (h.dimension == 4 && (h.sizes[0] != 1 || (h.directions && (*h.directions)[0]))) {
    fail("4-D NRRD is supported only with a leading non-spatial axis of size 1");
  }
  for (int a = 0; a < 3; ++a) volume.dims[a] = static_cast<int>(h.sizes[first + a]);
  Eigen::Matrix4d& m = volume.image_from_ijk;
  m.setIdentity();
  if (h.directions) {
    for (int a = 0; a < 3; ++a) {
      const auto& direction = (*h.directions)[first + static_cast<std::size_t>(a)];
      if (!direction) fail("space directions: a spatial axis has direction none");
      m.block<3, 1>(0, a) = *direction;
    }
    volume.geometry_source = "nrrd space directions (" + h.space_name + ")";
  } else if (!h.spacings.empty()) {
    for (int a = 0; a < 3; ++a) {
      const double spacing = h.spacings[first + static_cast<std::size_t>(a)];
      if (!std::isfinite(spacing) || spacing == 0.0) fail("spacings must be finite, non-zero");
      m(a, a) = spacing;
    }
    volume.geometry_source = "nrrd spacings (axis-aligned, " + h.space_name + ")";
  } else {
    volume.geometry_source = "nrrd without geometry (unit spacing, LPS)";
  }
  if (h.origin) m.block<3, 1>(0, 3) = *h.origin;
  if (h.to_lps) m.topRows<3>() = h.to_lps->asDiagonal() * m.topRows<3>();
  CtVolume probe;  // geometry only: Check() tests the affine
  probe.dims = {1, 1, 1};
  probe.values = {0.0f};
  probe.image_from_ijk = m;
  try {
    probe.Check();
  } catch (const PreconditionError& error) {
    fail(std::string("invalid geometry: ") + error.what());
  }
}

}  // namespace

CtVolume DecodeNrrd(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
                    const NrrdDecodeOptions& options) {
  const NrrdHeader h = ParseNrrdHeader(bytes, path);
  CtVolume volume;
  SetGeometry(h, path, volume);
  volume.name = path.stem().string();
  const std::size_t sample_size = SampleSize(h.type);
  const auto expected = CheckedVolumeBytes(h.sizes, sample_size);
  if (!expected) throw IoError(path, h.end_offset, "sizes overflow the addressable data size");

  // Locate the data: attached after the blank line, or a detached file.
  std::filesystem::path data_path = path;
  std::vector<std::uint8_t> detached;
  std::span<const std::uint8_t> region;
  std::uint64_t region_offset = 0;
  if (h.data_file.empty()) {
    if (!h.blank_line) throw IoError(path, h.end_offset, "expected a blank line, then data");
    region = bytes.subspan(h.end_offset);
    region_offset = h.end_offset;
  } else {
    if (options.data_folder.empty()) {
      throw IoError(path, h.end_offset, "detached data file not allowed for in-memory NRRD");
    }
    if (h.data_file.find('%') != std::string::npos || h.data_file.starts_with("LIST")) {
      throw IoError(path, h.end_offset, "multi-file NRRD data is not supported");
    }
    data_path = options.data_folder / h.data_file;
    detached = ReadFileBytes(data_path);
    region = detached;
  }
  std::size_t position = 0;
  for (std::int64_t line = 0; line < h.line_skip; ++line) {
    const auto newline = std::find(region.begin() + static_cast<std::ptrdiff_t>(position),
                                   region.end(), std::uint8_t{'\n'});
    if (newline == region.end())
      throw IoError(data_path, region_offset + region.size(), "line skip past end");
    position = static_cast<std::size_t>(newline - region.begin()) + 1;
  }
  const auto skip = static_cast<std::uint64_t>(std::max<std::int64_t>(h.byte_skip, 0));
  std::vector<std::uint8_t> inflated;
  std::span<const std::uint8_t> data;
  const std::uint64_t data_offset = region_offset + position;
  if (h.encoding == "raw") {
    const std::uint64_t available = region.size() - position;
    const std::uint64_t start =
        h.byte_skip == -1 ? available - std::min(available, *expected) : skip;
    if (available < start + *expected || (h.byte_skip != -1 && available > start + *expected)) {
      throw IoError(data_path, data_offset,
                    "expected exactly " + std::to_string(*expected) + " bytes of raw data after " +
                        std::to_string(start) + " skipped, found " + std::to_string(available));
    }
    data = region.subspan(position + start, *expected);
  } else {
    if (h.byte_skip == -1) throw IoError(path, h.end_offset, "byte skip -1 needs raw encoding");
    const auto compressed = region.subspan(position);
    if (*expected + skip > compressed.size() * kMaxDeflateRatio + 1024) {
      throw IoError(data_path, data_offset,
                    "gzip data of " + std::to_string(compressed.size()) + " bytes cannot hold " +
                        std::to_string(*expected));
    }
    inflated = InflateGzip(compressed, data_path, *expected + skip + 1, data_offset);
    if (inflated.size() != *expected + skip) {
      throw IoError(data_path, data_offset + compressed.size(),
                    "gzip data decompresses to " + std::to_string(inflated.size()) +
                        (inflated.size() > *expected + skip ? "+" : "") + " bytes, expected " +
                        std::to_string(*expected + skip));
    }
    data = std::span<const std::uint8_t>(inflated).subspan(skip);
  }
  volume.values.resize(*expected / sample_size);
  DecodeSamples(data, h.type, h.endian, volume.values);
  return volume;
}

CtVolume ReadNrrd(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  const std::filesystem::path folder = path.parent_path().empty() ? "." : path.parent_path();
  return DecodeNrrd(bytes, path, {.data_folder = folder});
}

std::vector<std::uint8_t> EncodeNrrd(const CtVolume& volume, const VolumeWriteOptions& options) {
  options.Check();
  volume.Check();
  // "(x,y,z)" with the shortest decimals that round-trip; appended piecewise (GCC 12 -O3 gives a
  // false -Wrestrict on literal + std::string chains).
  const auto vector = [](const Eigen::Vector3d& v) {
    std::string text = "(";
    for (int n = 0; n < 3; ++n) {
      std::array<char, 32> buffer{};
      const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), v[n]);
      text.append(buffer.data(), result.ptr).push_back(n < 2 ? ',' : ')');
    }
    return text;
  };
  const Eigen::Matrix4d& m = volume.image_from_ijk;
  std::string header =
      "NRRD0004\n# Complete NRRD file format specification at:\n"
      "# http://teem.sourceforge.net/nrrd/format.html\n";
  header += options.sample_type == VolumeSampleType::kInt16 ? "type: short\n" : "type: float\n";
  header += "dimension: 3\nspace: left-posterior-superior\n";
  header += "sizes: " + std::to_string(volume.nx()) + " " + std::to_string(volume.ny()) + " " +
            std::to_string(volume.nz()) + "\n";
  header += "space directions: " + vector(m.block<3, 1>(0, 0)) + " " + vector(m.block<3, 1>(0, 1)) +
            " " + vector(m.block<3, 1>(0, 2)) + "\n";
  header += "kinds: domain domain domain\nendian: little\n";
  header += options.gzip ? "encoding: gzip\n" : "encoding: raw\n";
  header += "space origin: " + vector(m.block<3, 1>(0, 3)) + "\n\n";
  std::vector<std::uint8_t> samples = EncodeSamples(volume.values, options.sample_type);
  if (options.gzip) samples = DeflateGzip(samples, options.gzip_level);
  std::vector<std::uint8_t> out(header.begin(), header.end());
  out.insert(out.end(), samples.begin(), samples.end());
  return out;
}

void WriteNrrd(const std::filesystem::path& path, const CtVolume& volume,
               const VolumeWriteOptions& options) {
  WriteFileAtomically(path, EncodeNrrd(volume, options));
}

}  // namespace tofnav
