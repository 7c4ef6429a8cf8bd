// SPDX-License-Identifier: BSD-3-Clause
// Incremental OpenIGTLink receiver: our own 58-byte header parse, CRC check, header-v2 slicing
// (docs/openigtlink.md section 3), so what 3D Slicer sends never desynchronises the stream.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tofnav/stream/igtl_codec.hpp"

namespace tofnav {

/// One received message with a good CRC.
struct IgtlFrame {
  IgtlHeader header;
  /// The v1 body, or the content slice of a v2 body; empty when the body was too large to keep
  /// (it was still CRC-checked and skipped).
  std::vector<std::uint8_t> content;
  std::vector<std::pair<std::string, std::string>> metadata;  // v2 only (MRMLNodeName, ...)
  bool content_kept = true;
};

/// The parts of a version-2 body.
struct IgtlV2Body {
  std::span<const std::uint8_t> content;
  std::vector<std::pair<std::string, std::string>> metadata;
  std::uint32_t message_id = 0;
};
/// Slices a v2 body (extended header, content, metadata header, metadata); IoError naming
/// `source` and `offset` when the sizes do not add up.
IgtlV2Body SliceIgtlV2Body(std::span<const std::uint8_t> body, const std::filesystem::path& source,
                           std::uint64_t offset);

struct IgtlReceiverOptions {
  std::uint64_t max_body_bytes = std::uint64_t{256} << 20;  // larger: framing error
  std::uint64_t max_kept_bytes = std::uint64_t{4} << 20;    // larger bodies are skipped
  void Check() const;
};

struct IgtlReceiverCounters {
  std::uint64_t bytes = 0;
  std::uint64_t frames = 0;     // delivered (CRC good)
  std::uint64_t v2_frames = 0;  // of which header version 2
  std::uint64_t crc_errors = 0;
  std::uint64_t malformed_v2 = 0;  // CRC good, but the v2 sizes do not add up (skipped)
};

/// Reassembles messages from arbitrary byte chunks. A frame with a bad CRC or an inconsistent
/// v2 body is counted and skipped, and the stream stays in sync (the header's BODY_SIZE is not
/// covered by the CRC, so only the header can break framing). A bad header (version not 1 or 2,
/// non-printable names, BODY_SIZE above the limit) throws IoError: the connection must close.
class IgtlReceiver {
 public:
  explicit IgtlReceiver(std::filesystem::path source, const IgtlReceiverOptions& options = {});

  void Feed(std::span<const std::uint8_t> bytes,
            const std::function<void(const IgtlFrame&)>& on_frame);
  const IgtlReceiverCounters& counters() const { return counters_; }

 private:
  void FinishBody(const std::function<void(const IgtlFrame&)>& on_frame);

  std::filesystem::path source_;
  IgtlReceiverOptions options_;
  IgtlReceiverCounters counters_;
  std::vector<std::uint8_t> header_bytes_;
  std::optional<IgtlHeader> header_;  // set while the body is read
  std::uint64_t header_offset_ = 0;
  std::uint64_t body_read_ = 0;
  std::uint64_t crc_ = 0;
  std::vector<std::uint8_t> body_;
};

}  // namespace tofnav
