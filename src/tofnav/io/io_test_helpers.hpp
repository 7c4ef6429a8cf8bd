// SPDX-License-Identifier: BSD-3-Clause
// Test-only helpers for the io/ suites: temporary folders and ustar headers built field by field.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace tofnav::testing {

using Bytes = std::vector<std::uint8_t>;

/// A fresh folder under the system temporary directory, removed with its contents.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(std::filesystem::temp_directory_path() /
              ("tofnav_" + tag + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline Bytes ToBytes(std::string_view text) { return Bytes(text.begin(), text.end()); }

/// Writes `text` at `offset` of a header (no terminator added).
inline void SetField(Bytes& header, std::size_t offset, std::string_view text) {
  std::memcpy(header.data() + offset, text.data(), text.size());
}

/// Recomputes the POSIX checksum by hand: the unsigned (or, for old writers, signed) sum of all
/// 512 bytes with the 8-byte field at 148 taken as spaces, stored as 6 octal digits, NUL, space.
inline void Reseal(Bytes& header, bool signed_sum = false) {
  std::memset(header.data() + 148, ' ', 8);
  long long sum = 0;
  for (const std::uint8_t byte : header) {
    sum += signed_sum ? static_cast<long long>(static_cast<std::int8_t>(byte)) : byte;
  }
  char digits[32];
  std::snprintf(digits, sizeof(digits), "%06llo", sum);
  SetField(header, 148, std::string_view(digits, 6));
  header[154] = 0;
  header[155] = ' ';
}

/// A ustar header as StreamRecorder's Tar.cpp lays it out, every field set explicitly.
/// `mode` is the 7-digit octal text (the recorder writes "0100777", our writer "0000644").
inline Bytes HandHeader(std::string_view name, std::uint64_t size, char type = '0',
                        std::string_view mode = "0000644", std::uint64_t mtime_s = 0) {
  Bytes header(512, 0);
  SetField(header, 0, name);         // name[100]
  SetField(header, 100, mode);       // mode[8]: 7 digits + NUL
  SetField(header, 108, "0000000");  // uid[8]
  SetField(header, 116, "0000000");  // gid[8]
  char octal[32];
  std::snprintf(octal, sizeof(octal), "%011llo", static_cast<unsigned long long>(size));
  SetField(header, 124, octal);  // size[12]: 11 digits + NUL
  std::snprintf(octal, sizeof(octal), "%011llo", static_cast<unsigned long long>(mtime_s));
  SetField(header, 136, octal);                           // mtime[12]
  header[156] = static_cast<std::uint8_t>(type);          // typeflag
  SetField(header, 257, std::string_view("ustar\0", 6));  // magic[6]
  SetField(header, 263, "00");                            // version[2]
  SetField(header, 329, "0000000");                       // devmajor[8]
  SetField(header, 337, "0000000");                       // devminor[8]
  Reseal(header);
  return header;
}

/// Appends header + data + zero padding to a multiple of 512.
inline void AppendEntry(Bytes& tar, const Bytes& header, const Bytes& data) {
  tar.insert(tar.end(), header.begin(), header.end());
  tar.insert(tar.end(), data.begin(), data.end());
  tar.resize(tar.size() + (512 - data.size() % 512) % 512, 0);
}

inline void AppendEndBlocks(Bytes& tar) { tar.resize(tar.size() + 1024, 0); }

inline void WriteBytes(const std::filesystem::path& path, const Bytes& bytes) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) throw std::runtime_error("cannot write " + path.string());
  std::fwrite(bytes.data(), 1, bytes.size(), file);
  std::fclose(file);
}

}  // namespace tofnav::testing
