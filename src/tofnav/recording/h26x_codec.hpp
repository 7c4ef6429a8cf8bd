// SPDX-License-Identifier: BSD-3-Clause
// H.264 / H.265 access units <-> 512 x 512 4:2:0 pictures, through FFmpeg's libavcodec (libx264
// and libx265 for encoding), set up as hl2ss streams them (docs/ahat.md 3.6). One access unit in,
// one picture out: the streams have no B-frames and no reordering.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_video_planes.hpp"

namespace tofnav {

enum class H26xCodec : std::uint8_t { kH264, kH265 };
enum class H264Profile : std::uint8_t { kBaseline, kMain, kHigh };

/// True when the access unit holds a picture a decoder can start from (H.264 IDR, H.265 IDR, CRA
/// or BLA). Scans Annex B start codes only; never reads past the span.
bool H26xIsKeyFrame(H26xCodec codec, std::span<const std::uint8_t> access_unit);

/// Where a decode error happened, for the message: the file (or stream) and byte offset of the
/// access unit and the frame's index.
struct H26xUnitPlace {
  std::filesystem::path source;
  std::uint64_t offset = 0;
  std::size_t frame = 0;
  std::size_t bytes = 0;  // the unit's size (set by H26xDecoder::Send)
};

/// A strict decoder: a unit that does not decode cleanly into exactly one 512 x 512 4:2:0 picture
/// throws IoError naming the place, and so does a first unit that is not a key frame. After an
/// error the decoder must be Reset() (and fed from a key frame) before it is used again.
///
/// With `frame_threads` > 1 libavcodec decodes that many units at once (a recording read ahead:
/// 1.5 times the pictures per second on two cores, docs/benchmarks.md) and a picture comes out
/// up to frame_threads - 1 units after its own: Send units, Receive pictures (oldest first), and
/// SendEnd at the stream's end to get the last ones. An error names the oldest unit in flight,
/// whose picture it is. One thread: Decode, or Send then Receive, gives each picture at once (a
/// live stream's latency).
class H26xDecoder {
 public:
  explicit H26xDecoder(H26xCodec codec, int frame_threads = 1);
  ~H26xDecoder();
  H26xDecoder(const H26xDecoder&) = delete;
  H26xDecoder& operator=(const H26xDecoder&) = delete;

  Yuv420Picture Decode(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place);
  /// The same into `picture`, whose planes are reused when they have the picture's size (a
  /// decoder fed 45 pictures a second allocates nothing per picture; docs/benchmarks.md).
  void Decode(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place,
              Yuv420Picture& picture);
  void Send(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place);
  /// No unit follows: the pictures in flight come out of Receive. Send again only after Reset.
  void SendEnd();
  /// The oldest unit's picture into `picture` (planes reused); false while none is ready (send
  /// the next unit, or SendEnd) or none is in flight.
  bool Receive(Yuv420Picture& picture);
  /// Units sent whose pictures have not come out.
  std::size_t in_flight() const;
  /// Forgets every reference picture and every unit in flight: the next unit must be a key frame.
  void Reset();
  H26xCodec codec() const { return codec_; }
  int frame_threads() const { return frame_threads_; }

 private:
  struct State;
  IoError Failure(const H26xUnitPlace& place, std::size_t bytes, const std::string& what) const;
  [[noreturn]] void Fail(const std::string& what);
  H26xCodec codec_;
  int frame_threads_;
  std::unique_ptr<State> state_;
  bool started_ = false;
  bool ended_ = false;
};

struct H26xEncoderOptions {
  H26xCodec codec = H26xCodec::kH265;
  H264Profile h264_profile = H264Profile::kMain;  // H.264 only (H.265 is always Main)
  std::uint32_t bitrate_bps = 943718;             // the hl2ss client's ZDEPTH + H.265 default
  int gop_frames = 45;                            // a key frame every 45 frames, as hl2ss
  int divisor = 1;                                // frame rate 45 / divisor
  void Check() const;                             // throws std::invalid_argument
};

/// libx264 / libx265 in place of the headset's hardware encoder: no B-frames, no look-ahead (one
/// unit out per picture in), a key frame every gop_frames, parameter sets in-band at every key
/// frame, H.264 units starting with an access unit delimiter (00 00 00 01 09 ..), constant
/// bitrate within a one-second buffer, one thread (deterministic output).
class H26xEncoder {
 public:
  explicit H26xEncoder(const H26xEncoderOptions& options);
  ~H26xEncoder();
  H26xEncoder(const H26xEncoder&) = delete;
  H26xEncoder& operator=(const H26xEncoder&) = delete;

  /// Encodes the next picture into one access unit.
  std::vector<std::uint8_t> Encode(const Yuv420Picture& picture);

 private:
  struct State;
  H26xEncoderOptions options_;
  std::unique_ptr<State> state_;
  std::int64_t next_pts_ = 0;
};

}  // namespace tofnav
