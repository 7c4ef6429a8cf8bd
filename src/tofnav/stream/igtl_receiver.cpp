// SPDX-License-Identifier: BSD-3-Clause
// OpenIGTLink receiver: streaming CRC over the body, v2 slicing, skip on CRC errors.
#include "tofnav/stream/igtl_receiver.hpp"

#include <algorithm>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {

IgtlV2Body SliceIgtlV2Body(std::span<const std::uint8_t> body, const std::filesystem::path& source,
                           std::uint64_t offset) {
  ByteReader in(body, source, offset);
  const auto ext_bytes = in.Be<std::uint16_t>("extended header size");
  const auto meta_header_bytes = in.Be<std::uint16_t>("metadata header size");
  const auto meta_bytes = in.Be<std::uint32_t>("metadata size");
  IgtlV2Body out;
  out.message_id = in.Be<std::uint32_t>("message id");
  if (ext_bytes < 12 || ext_bytes > body.size()) {
    throw IoError(source, offset,
                  "extended header size " + std::to_string(ext_bytes) + " outside [12, body size " +
                      std::to_string(body.size()) + "]");
  }
  const std::uint64_t tail = std::uint64_t{meta_header_bytes} + meta_bytes;
  if (meta_header_bytes < 2 || tail > body.size() - ext_bytes) {
    throw IoError(source, offset + 2,
                  "metadata sizes " + std::to_string(meta_header_bytes) + " + " +
                      std::to_string(meta_bytes) + " exceed the body after the extended header");
  }
  const std::size_t content_bytes = body.size() - ext_bytes - static_cast<std::size_t>(tail);
  out.content = body.subspan(ext_bytes, content_bytes);
  const std::size_t meta_at = ext_bytes + content_bytes;
  ByteReader index(body.subspan(meta_at, meta_header_bytes), source, offset + meta_at);
  const auto count = index.Be<std::uint16_t>("metadata count");
  if (std::size_t{2} + 8 * std::size_t{count} != meta_header_bytes) {
    throw IoError(source, offset + meta_at,
                  "metadata header size " + std::to_string(meta_header_bytes) + " for " +
                      std::to_string(count) + " entries");
  }
  ByteReader values(body.subspan(meta_at + meta_header_bytes, meta_bytes), source,
                    offset + meta_at + meta_header_bytes);
  for (int i = 0; i < count; ++i) {
    const auto key_bytes = index.Be<std::uint16_t>("metadata key size");
    index.Be<std::uint16_t>("metadata value encoding");
    const auto value_bytes = index.Be<std::uint32_t>("metadata value size");
    const auto key = values.Take(key_bytes, "metadata key");
    const auto value = values.Take(value_bytes, "metadata value");
    out.metadata.emplace_back(std::string(key.begin(), key.end()),
                              std::string(value.begin(), value.end()));
  }
  if (values.remaining() != 0) {
    throw IoError(source, values.absolute_offset(), "metadata sizes do not add up");
  }
  return out;
}

void IgtlReceiverOptions::Check() const {
  Require(max_body_bytes > 0, "IgtlReceiverOptions.max_body_bytes must be > 0");
  Require(max_kept_bytes <= max_body_bytes,
          "IgtlReceiverOptions.max_kept_bytes must not exceed max_body_bytes");
}

IgtlReceiver::IgtlReceiver(std::filesystem::path source, const IgtlReceiverOptions& options)
    : source_(std::move(source)), options_(options) {
  options_.Check();
  header_bytes_.reserve(kIgtlHeaderBytes);
}

void IgtlReceiver::Feed(std::span<const std::uint8_t> bytes,
                        const std::function<void(const IgtlFrame&)>& on_frame) {
  while (!bytes.empty()) {
    if (!header_) {
      const std::size_t take = std::min(bytes.size(), kIgtlHeaderBytes - header_bytes_.size());
      header_bytes_.insert(header_bytes_.end(), bytes.begin(), bytes.begin() + take);
      bytes = bytes.subspan(take);
      counters_.bytes += take;
      if (header_bytes_.size() < kIgtlHeaderBytes) return;
      header_offset_ = counters_.bytes - kIgtlHeaderBytes;
      IgtlHeader h = DecodeIgtlHeader(
          std::span<const std::uint8_t, kIgtlHeaderBytes>(header_bytes_.data(), kIgtlHeaderBytes),
          source_, header_offset_);
      header_bytes_.clear();
      if (h.body_size > options_.max_body_bytes) {
        throw IoError(source_, header_offset_ + 42,
                      "body size " + std::to_string(h.body_size) + " exceeds the limit " +
                          std::to_string(options_.max_body_bytes));
      }
      header_ = std::move(h);
      body_read_ = 0;
      crc_ = 0;
      body_.clear();
      if (header_->body_size <= options_.max_kept_bytes) {
        body_.reserve(static_cast<std::size_t>(header_->body_size));
      }
      if (header_->body_size == 0) {
        FinishBody(on_frame);
        continue;
      }
    }
    const auto take = static_cast<std::size_t>(
        std::min<std::uint64_t>(bytes.size(), header_->body_size - body_read_));
    const auto chunk = bytes.first(take);
    crc_ = IgtlCrc64(chunk, crc_);
    if (header_->body_size <= options_.max_kept_bytes) {
      body_.insert(body_.end(), chunk.begin(), chunk.end());
    }
    body_read_ += take;
    counters_.bytes += take;
    bytes = bytes.subspan(take);
    if (body_read_ == header_->body_size) FinishBody(on_frame);
  }
}

void IgtlReceiver::FinishBody(const std::function<void(const IgtlFrame&)>& on_frame) {
  IgtlFrame frame;
  frame.header = std::move(*header_);
  header_.reset();
  if (crc_ != frame.header.crc) {
    ++counters_.crc_errors;
    return;
  }
  frame.content_kept = frame.header.body_size <= options_.max_kept_bytes;
  if (frame.header.version == 2 && frame.content_kept) {
    try {
      IgtlV2Body v2 = SliceIgtlV2Body(body_, source_, header_offset_ + kIgtlHeaderBytes);
      frame.content.assign(v2.content.begin(), v2.content.end());
      frame.metadata = std::move(v2.metadata);
    } catch (const IoError&) {
      ++counters_.malformed_v2;
      return;
    }
  } else {
    frame.content = std::move(body_);
  }
  body_.clear();
  ++counters_.frames;
  if (frame.header.version == 2) ++counters_.v2_frames;
  if (on_frame) on_frame(frame);
}

}  // namespace tofnav
