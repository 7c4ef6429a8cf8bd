// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/io/file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

std::string ErrnoText() { return std::strerror(errno); }

}  // namespace

std::vector<std::uint8_t> ReadFileBytes(const std::filesystem::path& path) {
  const RandomAccessFile file(path);
  return file.ReadAt(0, static_cast<std::size_t>(file.size()), "file contents");
}

RandomAccessFile::RandomAccessFile(const std::filesystem::path& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw IoError(path, std::nullopt, "cannot open for reading: " + ErrnoText());
  struct stat info {};
  if (::fstat(fd_, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    throw IoError(path, std::nullopt, "not a regular file");
  }
  size_ = static_cast<std::uint64_t>(info.st_size);
}

RandomAccessFile::~RandomAccessFile() {
  if (fd_ >= 0) ::close(fd_);
}

RandomAccessFile::RandomAccessFile(RandomAccessFile&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)), size_(other.size_) {}

RandomAccessFile& RandomAccessFile::operator=(RandomAccessFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    size_ = other.size_;
  }
  return *this;
}

void RandomAccessFile::ReadAt(std::uint64_t offset, std::span<std::uint8_t> out,
                              const char* what) const {
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t n =
        ::pread(fd_, out.data() + done, out.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError(path_, offset + done, std::string("read failed: ") + ErrnoText());
    if (n == 0) {
      throw IoError(path_, offset + done,
                    "expected " + std::to_string(out.size()) + " bytes of " + what +
                        ", the file ends after " + std::to_string(done));
    }
    done += static_cast<std::size_t>(n);
  }
}

std::vector<std::uint8_t> RandomAccessFile::ReadAt(std::uint64_t offset, std::size_t count,
                                                   const char* what) const {
  std::vector<std::uint8_t> out(count);
  ReadAt(offset, out, what);
  return out;
}

AtomicFileWriter::AtomicFileWriter(std::filesystem::path path) : path_(std::move(path)) {
  temporary_ = path_;
  temporary_ += ".tmp-" + std::to_string(::getpid());
  file_ = std::fopen(temporary_.c_str(), "wb");
  if (file_ == nullptr) {
    throw IoError(path_, std::nullopt, "cannot create " + temporary_.string() + ": " + ErrnoText());
  }
}

AtomicFileWriter::~AtomicFileWriter() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::error_code ignored;
    std::filesystem::remove(temporary_, ignored);
  }
}

void AtomicFileWriter::Write(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw IoError(temporary_, written_, "write failed: " + ErrnoText());
  }
  written_ += bytes.size();
}

void AtomicFileWriter::Write(const std::string& text) {
  Write(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

void AtomicFileWriter::Commit() {
  const bool flushed = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  std::error_code error;
  if (flushed && closed) std::filesystem::rename(temporary_, path_, error);
  if (!flushed || !closed || error) {
    std::filesystem::remove(temporary_, error);
    throw IoError(path_, std::nullopt, "could not complete the write: " + ErrnoText());
  }
}

void WriteFileAtomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
  AtomicFileWriter writer(path);
  writer.Write(bytes);
  writer.Commit();
}

void WriteFileAtomically(const std::filesystem::path& path, const std::string& text) {
  AtomicFileWriter writer(path);
  writer.Write(text);
  writer.Commit();
}

}  // namespace tofnav
