// SPDX-License-Identifier: BSD-3-Clause
// gzip streams on zlib: inflate with automatic gzip header handling (windowBits 15 + 16).
#include "tofnav/io/gzip.hpp"

#include <zlib.h>

#include <algorithm>
#include <limits>
#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr int kGzipWindowBits = 15 + 16;  // 32 KiB window, gzip wrapper only
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;
// zlib's avail_in/avail_out are 32-bit: feed at most this much per call.
constexpr std::size_t kMaxZlibSpan = std::numeric_limits<unsigned>::max();

}  // namespace

struct GzipInflater::State {
  z_stream stream{};
  bool initialised = false;
  std::size_t input_position = 0;  // bytes of `compressed_` handed to zlib so far
};

bool HasGzipMagic(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b;
}

GzipInflater::GzipInflater(std::span<const std::uint8_t> compressed, std::filesystem::path path,
                           std::uint64_t base_offset)
    : state_(std::make_unique<State>()),
      compressed_(compressed),
      path_(std::move(path)),
      base_offset_(base_offset) {
  if (!HasGzipMagic(compressed)) throw IoError(path_, base_offset_, "expected gzip magic 1f 8b");
  if (inflateInit2(&state_->stream, kGzipWindowBits) != Z_OK) {
    throw IoError(path_, base_offset_, "zlib inflateInit2 failed");
  }
  state_->initialised = true;
}

GzipInflater::~GzipInflater() {
  if (state_ && state_->initialised) inflateEnd(&state_->stream);
}

std::uint64_t GzipInflater::compressed_offset() const {
  return base_offset_ + state_->input_position - state_->stream.avail_in;
}

std::size_t GzipInflater::Read(std::span<std::uint8_t> out) {
  z_stream& z = state_->stream;
  std::size_t filled = 0;
  while (filled < out.size() && !finished_) {
    if (z.avail_in == 0) {
      const std::size_t left = compressed_.size() - state_->input_position;
      if (left == 0) {
        throw IoError(path_, compressed_offset(),
                      "gzip stream truncated: expected more compressed data after " +
                          std::to_string(produced_) + " decompressed bytes");
      }
      const std::size_t feed = std::min(left, kMaxZlibSpan);
      // zlib's API takes a non-const pointer but never writes through next_in.
      z.next_in = const_cast<Bytef*>(compressed_.data() + state_->input_position);
      z.avail_in = static_cast<uInt>(feed);
      state_->input_position += feed;
    }
    const std::size_t want = std::min(out.size() - filled, kMaxZlibSpan);
    z.next_out = out.data() + filled;
    z.avail_out = static_cast<uInt>(want);
    const int status = inflate(&z, Z_NO_FLUSH);
    const std::size_t got = want - z.avail_out;
    filled += got;
    produced_ += got;
    if (status == Z_STREAM_END) {
      // Another member may follow (concatenated gzip); other trailing bytes (padding) are
      // ignored as gzip(1) does.
      const std::size_t consumed = state_->input_position - z.avail_in;
      if (HasGzipMagic(compressed_.subspan(consumed))) {
        inflateReset(&z);
      } else {
        finished_ = true;
      }
    } else if (status != Z_OK && !(status == Z_BUF_ERROR && got == 0 && z.avail_in == 0)) {
      const char* message = z.msg != nullptr ? z.msg : "unknown error";
      throw IoError(path_, compressed_offset(),
                    std::string("corrupt gzip stream (zlib: ") + message + ")");
    }
  }
  return filled;
}

std::vector<std::uint8_t> InflateGzip(std::span<const std::uint8_t> compressed,
                                      const std::filesystem::path& path, std::size_t max_output,
                                      std::uint64_t base_offset) {
  GzipInflater inflater(compressed, path, base_offset);
  std::vector<std::uint8_t> out;
  while (out.size() < max_output) {
    const std::size_t step = std::min(max_output - out.size(), kChunkBytes);
    const std::size_t old_size = out.size();
    out.resize(old_size + step);  // grows with real output only, never from a size field
    const std::size_t got = inflater.Read(std::span(out).subspan(old_size, step));
    out.resize(old_size + got);
    if (got < step) break;
  }
  return out;
}

std::vector<std::uint8_t> DeflateGzip(std::span<const std::uint8_t> bytes, int level) {
  Require(level >= 0 && level <= 9, "gzip level must be 0..9");
  z_stream z{};
  if (deflateInit2(&z, level, Z_DEFLATED, kGzipWindowBits, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw std::runtime_error("zlib deflateInit2 failed");
  }
  std::vector<std::uint8_t> out;
  std::size_t position = 0;
  int status = Z_OK;
  while (status != Z_STREAM_END) {
    if (z.avail_in == 0 && position < bytes.size()) {
      const std::size_t feed = std::min(bytes.size() - position, kMaxZlibSpan);
      z.next_in = const_cast<Bytef*>(bytes.data() + position);
      z.avail_in = static_cast<uInt>(feed);
      position += feed;
    }
    const std::size_t old_size = out.size();
    out.resize(old_size + kChunkBytes);
    z.next_out = out.data() + old_size;
    z.avail_out = static_cast<uInt>(kChunkBytes);
    status = deflate(&z, position == bytes.size() ? Z_FINISH : Z_NO_FLUSH);
    out.resize(old_size + kChunkBytes - z.avail_out);
    if (status == Z_STREAM_ERROR) {
      deflateEnd(&z);
      throw std::runtime_error("zlib deflate failed");
    }
  }
  deflateEnd(&z);
  return out;
}

}  // namespace tofnav
