// SPDX-License-Identifier: BSD-3-Clause
// gzip (RFC 1952) inflate/deflate on zlib for the volume readers and writers (NRRD gzip encoding,
// .nii.gz, .inv3). Every failure is an IoError at the compressed byte offset.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

namespace tofnav {

/// True when `bytes` starts with the gzip magic 1f 8b.
bool HasGzipMagic(std::span<const std::uint8_t> bytes);

/// Incremental gzip decoder over an in-memory stream (concatenated members allowed). Output is
/// produced only as the caller asks, so memory never depends on a size field of the stream.
class GzipInflater {
 public:
  /// `compressed` must outlive the inflater; `base_offset` is its position in `path` (errors).
  GzipInflater(std::span<const std::uint8_t> compressed, std::filesystem::path path,
               std::uint64_t base_offset = 0);
  ~GzipInflater();
  GzipInflater(const GzipInflater&) = delete;
  GzipInflater& operator=(const GzipInflater&) = delete;

  /// Fills `out` and returns out.size(), or fewer bytes only at the clean end of the stream.
  /// IoError on corrupt or truncated input (offset = compressed bytes consumed).
  std::size_t Read(std::span<std::uint8_t> out);
  /// Absolute offset in `path` of the next compressed byte (for callers' error messages).
  std::uint64_t compressed_offset() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  std::span<const std::uint8_t> compressed_;
  std::filesystem::path path_;
  std::uint64_t base_offset_ = 0;
  std::uint64_t produced_ = 0;
  bool finished_ = false;
};

/// Deflate cannot expand data by more than about 1032:1: a gzip block shorter than
/// expected / kMaxDeflateRatio cannot hold the data (checked before inflating).
inline constexpr std::uint64_t kMaxDeflateRatio = 1032;

/// The first min(max_output, total) decompressed bytes; bytes after max_output are not decoded.
std::vector<std::uint8_t> InflateGzip(std::span<const std::uint8_t> compressed,
                                      const std::filesystem::path& path, std::size_t max_output,
                                      std::uint64_t base_offset = 0);

/// One gzip member; `level` 0..9 (zlib), throws PreconditionError outside.
std::vector<std::uint8_t> DeflateGzip(std::span<const std::uint8_t> bytes, int level = 6);

}  // namespace tofnav
