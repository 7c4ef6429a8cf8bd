// SPDX-License-Identifier: BSD-3-Clause
// POSIX ustar archives: an index of the entries read header by header (never the whole archive),
// and a writer.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tofnav/io/file.hpp"

namespace tofnav {

/// One regular file of the archive; its bytes are [data_offset, data_offset + size).
struct TarEntry {
  std::string name;  // ustar prefix + "/" + name when the prefix is set
  std::uint64_t header_offset = 0;
  std::uint64_t data_offset = 0;
  std::uint64_t size = 0;  // [bytes]
};

/// How the walk over the headers ended.
enum class TarEnd {
  kEndBlocks,        // an all-zero block (a complete archive)
  kEndOfFile,        // EOF at a header boundary: no end blocks (recorder killed between entries)
  kTruncatedHeader,  // EOF inside a header block; the partial header is ignored
  kTruncatedEntry,   // EOF inside an entry's data; that entry is dropped (see dropped_name)
};

struct TarIndexOptions {
  /// Accept an archive whose last entry runs past EOF (a recorder killed mid-write) by dropping
  /// that entry; false makes it an IoError at the entry's header offset.
  bool allow_truncated_tail = true;
};

struct TarIndex {
  std::vector<TarEntry> entries;  // regular files in archive order
  TarEnd end = TarEnd::kEndBlocks;
  std::uint64_t end_offset = 0;     // offset of the end block, of EOF, or of the cut header
  std::string dropped_name;         // the truncated entry's name (kTruncatedEntry only)
  std::size_t skipped_entries = 0;  // non-regular entries (directories, links, pax, ...)
};

/// Indexes the archive with positioned 512-byte header reads. Throws IoError naming the file and
/// the header offset on a bad checksum, a missing ustar magic or a malformed size field.
TarIndex IndexTar(const RandomAccessFile& file, const TarIndexOptions& options = {});

/// The same over an archive held in memory (fuzzing, small archives); `source` names it in errors.
TarIndex IndexTar(std::span<const std::uint8_t> bytes,
                  const std::filesystem::path& source = "<tar>",
                  const TarIndexOptions& options = {});

/// Streams a ustar archive through an AtomicFileWriter: nothing appears under `path` until Close().
/// Headers carry mode 0644, uid/gid 0, the given mtime and a correct checksum; data is padded to
/// 512 bytes and Close() appends the two all-zero end blocks.
class TarWriter {
 public:
  explicit TarWriter(const std::filesystem::path& path);

  /// Appends one regular file. PreconditionError when `name` is empty, longer than 99 bytes or
  /// holds a NUL, or when the data exceeds the 8 GiB ustar limit.
  void Add(std::string_view name, std::span<const std::uint8_t> data, std::uint64_t mtime_s = 0);
  /// Writes the end blocks and renames the archive into place; IoError on failure.
  void Close();

 private:
  AtomicFileWriter file_;
  bool closed_ = false;
};

}  // namespace tofnav
