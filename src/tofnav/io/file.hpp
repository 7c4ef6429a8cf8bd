// SPDX-License-Identifier: BSD-3-Clause
// File access for io/: whole-file reads, positioned reads without loading a file, and writes that
// never leave a half-written file behind (temporary name, then rename).
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace tofnav {

/// Whole file; IoError when it cannot be opened or read.
std::vector<std::uint8_t> ReadFileBytes(const std::filesystem::path& path);

/// Random-access reads from an open file (pread), so large recordings are never loaded whole.
class RandomAccessFile {
 public:
  explicit RandomAccessFile(const std::filesystem::path& path);  // IoError if it cannot open
  ~RandomAccessFile();
  RandomAccessFile(const RandomAccessFile&) = delete;
  RandomAccessFile& operator=(const RandomAccessFile&) = delete;
  RandomAccessFile(RandomAccessFile&& other) noexcept;
  RandomAccessFile& operator=(RandomAccessFile&& other) noexcept;

  std::uint64_t size() const { return size_; }
  const std::filesystem::path& path() const { return path_; }
  /// Reads exactly out.size() bytes at `offset`; IoError ("expected N bytes of <what>") if short.
  void ReadAt(std::uint64_t offset, std::span<std::uint8_t> out, const char* what) const;
  std::vector<std::uint8_t> ReadAt(std::uint64_t offset, std::size_t count, const char* what) const;

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

/// Streams bytes into `<path>.tmp-<pid>` and renames over `path` only on Commit(); destroyed
/// without Commit() it removes the temporary, so a failed write never damages an existing file.
class AtomicFileWriter {
 public:
  explicit AtomicFileWriter(std::filesystem::path path);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  void Write(std::span<const std::uint8_t> bytes);
  void Write(const std::string& text);
  /// Flushes, fsyncs and renames into place; IoError on failure.
  void Commit();

 private:
  std::filesystem::path path_;
  std::filesystem::path temporary_;
  std::FILE* file_ = nullptr;
  std::uint64_t written_ = 0;
};

/// Convenience: the whole buffer through an AtomicFileWriter.
void WriteFileAtomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
void WriteFileAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace tofnav
