// SPDX-License-Identifier: BSD-3-Clause
// Live hl2ss AHAT client (port 3804, docs/ahat.md 6): configuration, packet framing, Mode 2.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/stream/frame_source.hpp"
#include "tofnav/stream/socket.hpp"

namespace tofnav {

/// Largest payload a client accepts: a SAME+RAW payload is 2 MiB + 16 bytes.
constexpr std::uint32_t kHl2ssMaxPayloadBytes = 16u << 20;

/// The configuration bytes a client sends (10 + 16 n, docs/ahat.md 3.2), also stored in recordings.
std::vector<std::uint8_t> EncodeHl2ssAhatConfig(const Hl2ssAhatConfig& config);
/// Decodes them (mode 0 or 1, known profiles); IoError naming `source` and the field offset.
Hl2ssAhatConfig DecodeHl2ssAhatConfig(std::span<const std::uint8_t> bytes,
                                      const std::string& source);

/// "hl2ss://HOST[:PORT]" -> host and port (default 3804); nullopt when `uri` has another scheme.
struct Hl2ssEndpoint {
  std::string host;
  int port = 3804;
};
std::optional<Hl2ssEndpoint> ParseHl2ssUri(const std::string& uri);
/// "hl2ss://HOST:PORT", the name of the peer in messages.
std::string Hl2ssUri(const Hl2ssEndpoint& endpoint);

/// Mode 2: the AHAT calibration blob as the device sends it (kHl2ssMode2Bytes; one connection,
/// closed by the server). NetworkError when the connection fails or ends early.
std::vector<std::uint8_t> DownloadHl2ssCalibrationBytes(const Hl2ssEndpoint& endpoint,
                                                        double timeout_s = 10.0);

/// Mode 2: downloads and decodes the AHAT calibration.
AhatCalibration DownloadHl2ssCalibration(const Hl2ssEndpoint& endpoint, double timeout_s = 10.0,
                                         std::optional<double> sample_offset_override = {});

/// Mode 0/1 stream: sends the configuration on construction, then decodes packets with the
/// recording decoder (every profile). Empty-AB packets are skipped, as hl2ss clients do. An H26x
/// unit that does not decode is a dropped frame, counted, never a stale one: the decoder restarts
/// at the next key frame and the units before it are dropped too.
class Hl2ssAhatClient : public FrameSource {
 public:
  /// NetworkError when the connection fails; PreconditionError for mode 2 (use the function
  /// above). `timeout_s` bounds the connection's handshake and every wait for data.
  Hl2ssAhatClient(const Hl2ssEndpoint& endpoint, const Hl2ssAhatConfig& config,
                  double timeout_s = 5.0);

  /// The next frame; nullopt when the server closes between packets. NetworkError on a truncated
  /// packet, a reset or a receive timeout; IoError on an oversized packet or a bad payload.
  std::optional<AhatFrame> Next() override;
  std::string description() const override;
  /// H26x frames dropped because a unit did not decode (or came before a key frame).
  std::int64_t dropped_frames() const { return dropped_frames_; }
  /// Why the last frame was dropped; empty when none was.
  const std::string& last_drop_reason() const { return last_drop_reason_; }

 private:
  Hl2ssEndpoint endpoint_;
  Hl2ssAhatConfig config_;
  SocketFd socket_;
  std::unique_ptr<Hl2ssVideoDecoder> video_;  // H26x profiles
  bool need_key_frame_ = true;
  std::int64_t dropped_frames_ = 0;
  std::string last_drop_reason_;
};

/// Decodes one received packet (12-byte header, payload, pose in mode 1) with the recording
/// decoder; nullopt for an empty-AB packet. H26x profiles need `video`, the stream's decoder,
/// fed every packet in order. Shared by the client and the fuzz targets.
std::optional<AhatFrame> DecodeHl2ssPacket(const Hl2ssAhatConfig& config,
                                           std::span<const std::uint8_t> packet,
                                           const std::string& source,
                                           Hl2ssVideoDecoder* video = nullptr);

}  // namespace tofnav
