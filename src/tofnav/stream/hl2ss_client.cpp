// SPDX-License-Identifier: BSD-3-Clause
// hl2ss client: config bytes, packet reassembly, decoding through the io/ recording reader.
#include "tofnav/stream/hl2ss_client.hpp"

#include <array>
#include <cstring>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_format.hpp"

namespace tofnav {
namespace {

/// The bytes a recording file holds before its first packet, for this configuration.
std::vector<std::uint8_t> FilePrefix(const Hl2ssAhatConfig& config) {
  ByteWriter out;
  out.Bytes({reinterpret_cast<const std::uint8_t*>(kHl2ssMagic), kHl2ssMagicBytes});
  out.Le(kHl2ssAhatPort);
  out.Le(std::uint32_t{0});  // user_len
  out.Bytes(EncodeHl2ssAhatConfig(config));
  return out.Release();
}

}  // namespace

std::vector<std::uint8_t> EncodeHl2ssAhatConfig(const Hl2ssAhatConfig& config) {
  Require(config.encoder_options.size() <= 255, "hl2ss config: more than 255 encoder options");
  ByteWriter out;
  out.Le(config.mode);
  out.Le(config.divisor);
  out.Le(static_cast<std::uint8_t>(config.profile_z));
  out.Le(static_cast<std::uint8_t>(config.profile_ab));
  out.Le(config.level);
  out.Le(config.bitrate_bps);
  out.Le(static_cast<std::uint8_t>(config.encoder_options.size()));
  for (const Hl2ssEncoderOption& o : config.encoder_options) {
    out.Le(o.key);
    out.Le(o.value);
  }
  return out.Release();
}

Hl2ssAhatConfig DecodeHl2ssAhatConfig(std::span<const std::uint8_t> bytes,
                                      const std::string& source) {
  ByteReader in(bytes, source);
  Hl2ssAhatConfig c;
  c.mode = in.Le<std::uint8_t>("mode");
  if (c.mode > 1) throw IoError(source, 0, "mode must be 0 or 1, found " + std::to_string(c.mode));
  c.divisor = in.Le<std::uint8_t>("divisor");
  if (c.divisor == 0) throw IoError(source, 1, "divisor must be >= 1");
  const auto profile_z = in.Le<std::uint8_t>("profile_z");
  if (profile_z > 1) throw IoError(source, 2, "profile_z must be 0 or 1");
  c.profile_z = static_cast<Hl2ssDepthProfile>(profile_z);
  const auto profile_ab = in.Le<std::uint8_t>("profile_ab");
  if (profile_ab > 3 && profile_ab != 255)
    throw IoError(source, 3, "profile_ab must be 0..3 or 255");
  c.profile_ab = static_cast<Hl2ssVideoProfile>(profile_ab);
  c.level = in.Le<std::uint8_t>("level");
  c.bitrate_bps = in.Le<std::uint32_t>("bitrate");
  const auto count = in.Le<std::uint8_t>("n_options");
  for (int i = 0; i < count; ++i) {
    const auto key = in.Le<std::uint64_t>("option key");
    c.encoder_options.push_back({key, in.Le<std::uint64_t>("option value")});
  }
  if (in.remaining() != 0) throw IoError(source, in.absolute_offset(), "bytes after the config");
  return c;
}

std::optional<Hl2ssEndpoint> ParseHl2ssUri(const std::string& uri) {
  constexpr std::string_view kScheme = "hl2ss://";
  if (uri.rfind(kScheme, 0) != 0) return std::nullopt;
  Hl2ssEndpoint e;
  const std::string rest = uri.substr(kScheme.size());
  const std::size_t colon = rest.rfind(':');
  e.host = rest.substr(0, colon);
  if (colon != std::string::npos) {
    const std::string port = rest.substr(colon + 1);
    Require(!port.empty() && port.size() <= 5 &&
                port.find_first_not_of("0123456789") == std::string::npos,
            "bad port in '" + uri + "'");
    e.port = std::stoi(port);
    Require(e.port >= 1 && e.port <= 65535, "port outside 1..65535 in '" + uri + "'");
  }
  Require(!e.host.empty(), "no host in '" + uri + "'");
  return e;
}

std::string Hl2ssUri(const Hl2ssEndpoint& endpoint) {
  return "hl2ss://" + endpoint.host + ":" + std::to_string(endpoint.port);
}

std::vector<std::uint8_t> DownloadHl2ssCalibrationBytes(const Hl2ssEndpoint& endpoint,
                                                        double timeout_s) {
  const std::string source = Hl2ssUri(endpoint) + " (mode 2)";
  const SocketFd socket = ConnectTcp(endpoint.host, endpoint.port, timeout_s);
  SetTimeouts(socket, timeout_s);
  const std::array<std::uint8_t, 1> mode = {2};
  WriteAll(socket, mode, source);
  std::vector<std::uint8_t> blob(kHl2ssMode2Bytes);
  if (!ReadExact(socket, blob, source, "calibration")) {
    throw NetworkError(source, NetworkFailure::kClosed,
                       "receiving the calibration: the server closed without sending it");
  }
  return blob;
}

AhatCalibration DownloadHl2ssCalibration(const Hl2ssEndpoint& endpoint, double timeout_s,
                                         std::optional<double> sample_offset_override) {
  return DecodeHl2ssMode2(DownloadHl2ssCalibrationBytes(endpoint, timeout_s),
                          Hl2ssUri(endpoint) + " (mode 2)", sample_offset_override);
}

std::optional<AhatFrame> DecodeHl2ssPacket(const Hl2ssAhatConfig& config,
                                           std::span<const std::uint8_t> packet,
                                           const std::string& source, Hl2ssVideoDecoder* video) {
  const bool raw = config.profile_ab == Hl2ssVideoProfile::kRaw;
  Require(raw || video != nullptr, "DecodeHl2ssPacket: an H26x profile needs the stream's decoder");
  std::vector<std::uint8_t> file = FilePrefix(config);
  file.insert(file.end(), packet.begin(), packet.end());
  const Hl2ssRecording one(std::move(file), source);
  if (one.truncated_tail()) throw IoError(source, 0, "truncated packet");
  if (one.frame_count() == 0) return std::nullopt;  // empty AB blob (encoder hiccup)
  return raw ? one.ReadFrame(0) : one.ReadFrameWith(0, *video);
}

Hl2ssAhatClient::Hl2ssAhatClient(const Hl2ssEndpoint& endpoint, const Hl2ssAhatConfig& config,
                                 double timeout_s)
    : endpoint_(endpoint), config_(config) {
  Require(config.mode <= 1, "Hl2ssAhatClient: mode must be 0 or 1 (mode 2: calibration)");
  if (config.profile_ab != Hl2ssVideoProfile::kRaw) {
    video_ = std::make_unique<Hl2ssVideoDecoder>(config);
  }
  socket_ = ConnectTcp(endpoint.host, endpoint.port, timeout_s);
  SetTimeouts(socket_, timeout_s);
  WriteAll(socket_, EncodeHl2ssAhatConfig(config), Hl2ssUri(endpoint));
}

std::optional<AhatFrame> Hl2ssAhatClient::Next() {
  const std::string source = Hl2ssUri(endpoint_);
  while (true) {
    std::vector<std::uint8_t> packet(kHl2ssPacketHeaderBytes);
    if (!ReadExact(socket_, packet, source, "packet header")) return std::nullopt;
    std::uint32_t payload_bytes;
    std::memcpy(&payload_bytes, packet.data() + 8, sizeof(payload_bytes));
    if (payload_bytes > kHl2ssMaxPayloadBytes) {
      throw IoError(source, std::nullopt,
                    "payload size " + std::to_string(payload_bytes) + " exceeds the limit " +
                        std::to_string(kHl2ssMaxPayloadBytes) + " (stream out of sync)");
    }
    const std::size_t rest = payload_bytes + (config_.mode == 1 ? kHl2ssPoseBytes : 0);
    packet.resize(kHl2ssPacketHeaderBytes + rest);
    if (!ReadExact(socket_, std::span(packet).subspan(kHl2ssPacketHeaderBytes), source,
                   "packet payload")) {
      throw NetworkError(source, NetworkFailure::kTruncated,
                         "receiving the packet payload: the peer closed the connection inside it");
    }
    if (!video_) {
      std::optional<AhatFrame> frame = DecodeHl2ssPacket(config_, packet, source);
      if (frame) return frame;  // else an empty-AB packet: skipped
      continue;
    }
    // H26x: a unit that does not decode drops its frame and every frame up to the next key
    // frame (their references are gone), never shows a stale or damaged picture.
    try {
      if (need_key_frame_) video_->Reset();
      std::optional<AhatFrame> frame = DecodeHl2ssPacket(config_, packet, source, video_.get());
      if (!frame) continue;
      need_key_frame_ = false;
      return frame;
    } catch (const IoError& e) {
      ++dropped_frames_;
      last_drop_reason_ = e.what();
      need_key_frame_ = true;
    }
  }
}

std::string Hl2ssAhatClient::description() const {
  return Hl2ssUri(endpoint_) + " " + Hl2ssProfileName(config_);
}

}  // namespace tofnav
