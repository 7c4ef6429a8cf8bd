// SPDX-License-Identifier: BSD-3-Clause
// POSIX ustar index and writer (docs/ahat.md section 7.2).
#include "tofnav/io/tar.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr std::uint64_t kBlockBytes = 512;
using Block = std::array<std::uint8_t, kBlockBytes>;

// ustar header layout: offsets and sizes of the fields we read or write.
constexpr std::size_t kNameOffset = 0;
constexpr std::size_t kNameSize = 100;
constexpr std::size_t kModeOffset = 100;
constexpr std::size_t kUidOffset = 108;
constexpr std::size_t kGidOffset = 116;
constexpr std::size_t kSizeOffset = 124;
constexpr std::size_t kSizeSize = 12;
constexpr std::size_t kMtimeOffset = 136;
constexpr std::size_t kChecksumOffset = 148;
constexpr std::size_t kChecksumSize = 8;
constexpr std::size_t kTypeOffset = 156;
constexpr std::size_t kMagicOffset = 257;
constexpr std::size_t kVersionOffset = 263;
constexpr std::size_t kDevMajorOffset = 329;
constexpr std::size_t kDevMinorOffset = 337;
constexpr std::size_t kPrefixOffset = 345;
constexpr std::size_t kPrefixSize = 155;
constexpr std::uint64_t kMaxOctal11 = (std::uint64_t{1} << 33) - 1;  // 11 octal digits

struct Header {
  std::string name;
  std::uint64_t size = 0;
  bool regular = false;
};

// Field text up to its first NUL (a field may fill its whole width without one).
std::string FieldString(const Block& block, std::size_t offset, std::size_t size) {
  const auto* begin = block.data() + offset;
  const auto* end = std::find(begin, begin + size, std::uint8_t{0});
  return {begin, end};
}

// Octal numeric field: leading spaces, octal digits, then only NULs or spaces. An empty field
// reads as 0 when `allow_empty` (StreamRecorder writes an all-NUL size for empty files).
std::uint64_t ParseOctal(const Block& block, std::size_t offset, std::size_t size,
                         const char* field, bool allow_empty, const std::filesystem::path& source,
                         std::uint64_t header_offset) {
  const auto fail = [&](const std::string& what) {
    throw IoError(source, header_offset, std::string("tar header ") + field + " field: " + what);
  };
  if ((block[offset] & 0x80U) != 0) fail("GNU base-256 numbers are not supported");
  std::size_t i = offset;
  const std::size_t end = offset + size;
  while (i < end && block[i] == ' ') ++i;
  const std::size_t first_digit = i;
  std::uint64_t value = 0;
  for (; i < end && block[i] >= '0' && block[i] <= '7'; ++i) {
    if (value > (std::numeric_limits<std::uint64_t>::max() >> 3)) fail("octal value overflows");
    value = value * 8 + static_cast<std::uint64_t>(block[i] - '0');
  }
  if (i == first_digit && !allow_empty) fail("expected octal digits");
  for (; i < end; ++i) {
    if (block[i] != 0 && block[i] != ' ') {
      fail("expected octal digits, found byte " + std::to_string(block[i]) + " at field position " +
           std::to_string(i - offset));
    }
  }
  return value;
}

// The header checksum is the sum of all 512 bytes with the checksum field read as spaces. POSIX
// sums unsigned bytes; some historic writers summed signed chars, so both are accepted.
void CheckChecksum(const Block& block, const std::filesystem::path& source,
                   std::uint64_t header_offset) {
  const std::uint64_t stored =
      ParseOctal(block, kChecksumOffset, kChecksumSize, "checksum", false, source, header_offset);
  std::uint64_t unsigned_sum = 0;
  std::int64_t signed_sum = 0;
  for (std::size_t i = 0; i < kBlockBytes; ++i) {
    const bool in_field = i >= kChecksumOffset && i < kChecksumOffset + kChecksumSize;
    const std::uint8_t byte = in_field ? std::uint8_t{' '} : block[i];
    unsigned_sum += byte;
    signed_sum += static_cast<std::int8_t>(byte);
  }
  if (stored != unsigned_sum &&
      !(signed_sum >= 0 && stored == static_cast<std::uint64_t>(signed_sum))) {
    throw IoError(source, header_offset,
                  "tar header checksum mismatch: stored " + std::to_string(stored) + ", computed " +
                      std::to_string(unsigned_sum) + " (unsigned) or " +
                      std::to_string(signed_sum) + " (signed)");
  }
}

Header ParseHeader(const Block& block, const std::filesystem::path& source,
                   std::uint64_t header_offset) {
  CheckChecksum(block, source, header_offset);
  // POSIX "ustar\0" + version, or the old GNU "ustar  \0" (no prefix field).
  if (std::memcmp(block.data() + kMagicOffset, "ustar", 5) != 0 ||
      (block[kMagicOffset + 5] != 0 && block[kMagicOffset + 5] != ' ')) {
    throw IoError(source, header_offset, "expected the ustar magic at header byte 257");
  }
  const bool posix = block[kMagicOffset + 5] == 0;
  Header header;
  header.name = FieldString(block, kNameOffset, kNameSize);
  if (posix) {
    const std::string prefix = FieldString(block, kPrefixOffset, kPrefixSize);
    if (!prefix.empty()) header.name = prefix + "/" + header.name;
  }
  header.size = ParseOctal(block, kSizeOffset, kSizeSize, "size", true, source, header_offset);
  const std::uint8_t type = block[kTypeOffset];
  header.regular = type == '0' || type == 0 || type == '7';  // '7': contiguous file
  return header;
}

bool AllZero(std::span<const std::uint8_t> bytes) {
  return std::all_of(bytes.begin(), bytes.end(), [](std::uint8_t b) { return b == 0; });
}

// Walks the headers; `read(offset, out)` fills `out` from the archive (bounds already checked).
template <typename ReadFn>
TarIndex Walk(std::uint64_t file_size, const ReadFn& read, const std::filesystem::path& source,
              const TarIndexOptions& options) {
  TarIndex index;
  Block block{};
  std::uint64_t offset = 0;
  while (true) {
    index.end_offset = offset;
    if (offset >= file_size) {
      index.end = TarEnd::kEndOfFile;
      return index;
    }
    const std::uint64_t remaining = file_size - offset;
    if (remaining < kBlockBytes) {  // a cut header, or cut end blocks when all zero
      const std::span<std::uint8_t> partial(block.data(), static_cast<std::size_t>(remaining));
      read(offset, partial);
      index.end = AllZero(partial) ? TarEnd::kEndBlocks : TarEnd::kTruncatedHeader;
      return index;
    }
    read(offset, std::span<std::uint8_t>(block));
    if (AllZero(block)) {
      index.end = TarEnd::kEndBlocks;
      return index;
    }
    Header header = ParseHeader(block, source, offset);
    const std::uint64_t data_offset = offset + kBlockBytes;
    const std::uint64_t available = file_size - data_offset;
    if (header.size > available) {
      if (!options.allow_truncated_tail) {
        throw IoError(source, offset,
                      "tar entry '" + header.name + "' declares " + std::to_string(header.size) +
                          " bytes, but the file ends " + std::to_string(available) +
                          " bytes after its header");
      }
      index.end = TarEnd::kTruncatedEntry;
      index.dropped_name = std::move(header.name);
      return index;
    }
    if (header.regular) {
      index.entries.push_back({std::move(header.name), offset, data_offset, header.size});
    } else {
      ++index.skipped_entries;
    }
    // The size is at most 12 octal digits (2^36), so the padding cannot overflow.
    const std::uint64_t padded = (header.size + kBlockBytes - 1) / kBlockBytes * kBlockBytes;
    offset = data_offset + std::min(padded, available);  // missing padding reads as EOF
  }
}

void WriteOctal(Block& block, std::size_t offset, std::size_t size, std::uint64_t value) {
  // size - 1 zero-padded digits and a NUL terminator.
  for (std::size_t i = size - 1; i-- > 0; value >>= 3) {
    block[offset + i] = static_cast<std::uint8_t>('0' + (value & 7U));
  }
  block[offset + size - 1] = 0;
}

}  // namespace

TarIndex IndexTar(const RandomAccessFile& file, const TarIndexOptions& options) {
  const auto read = [&file](std::uint64_t offset, std::span<std::uint8_t> out) {
    file.ReadAt(offset, out, "tar header");
  };
  return Walk(file.size(), read, file.path(), options);
}

TarIndex IndexTar(std::span<const std::uint8_t> bytes, const std::filesystem::path& source,
                  const TarIndexOptions& options) {
  const auto read = [bytes](std::uint64_t offset, std::span<std::uint8_t> out) {
    std::memcpy(out.data(), bytes.data() + offset, out.size());
  };
  return Walk(bytes.size(), read, source, options);
}

TarWriter::TarWriter(const std::filesystem::path& path) : file_(path) {}

void TarWriter::Add(std::string_view name, std::span<const std::uint8_t> data,
                    std::uint64_t mtime_s) {
  Require(!closed_, "TarWriter::Add after Close");
  Require(!name.empty() && name.size() < kNameSize && name.find('\0') == std::string_view::npos,
          "tar entry names must have 1 to 99 bytes and no NUL");
  Require(data.size() <= kMaxOctal11 && mtime_s <= kMaxOctal11,
          "tar entry size and mtime must fit 11 octal digits");
  Block header{};
  std::memcpy(header.data() + kNameOffset, name.data(), name.size());
  WriteOctal(header, kModeOffset, 8, 0644);
  WriteOctal(header, kUidOffset, 8, 0);
  WriteOctal(header, kGidOffset, 8, 0);
  WriteOctal(header, kSizeOffset, kSizeSize, data.size());
  WriteOctal(header, kMtimeOffset, 12, mtime_s);
  header[kTypeOffset] = '0';
  std::memcpy(header.data() + kMagicOffset, "ustar", 6);  // with its NUL
  std::memcpy(header.data() + kVersionOffset, "00", 2);
  WriteOctal(header, kDevMajorOffset, 8, 0);
  WriteOctal(header, kDevMinorOffset, 8, 0);
  std::fill_n(header.data() + kChecksumOffset, kChecksumSize, std::uint8_t{' '});
  std::uint64_t checksum = 0;
  for (const std::uint8_t byte : header) checksum += byte;
  WriteOctal(header, kChecksumOffset, 7, checksum);  // 6 digits, NUL, then the space kept
  file_.Write(header);
  file_.Write(data);
  const Block zeros{};
  const std::size_t tail = data.size() % kBlockBytes;
  if (tail != 0) file_.Write(std::span(zeros.data(), kBlockBytes - tail));
}

void TarWriter::Close() {
  Require(!closed_, "TarWriter::Close called twice");
  const Block zeros{};
  file_.Write(zeros);
  file_.Write(zeros);
  file_.Commit();
  closed_ = true;
}

}  // namespace tofnav
