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
};

/// A strict decoder: a unit that does not decode cleanly into exactly one 512 x 512 4:2:0 picture
/// throws IoError naming the place, and so does a first unit that is not a key frame. After an
/// error the decoder must be Reset() (and fed from a key frame) before it is used again.
class H26xDecoder {
 public:
  explicit H26xDecoder(H26xCodec codec);
  ~H26xDecoder();
  H26xDecoder(const H26xDecoder&) = delete;
  H26xDecoder& operator=(const H26xDecoder&) = delete;

  Yuv420Picture Decode(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place);
  /// Forgets every reference picture: the next unit must be a key frame.
  void Reset();
  H26xCodec codec() const { return codec_; }

 private:
  struct State;
  H26xCodec codec_;
  std::unique_ptr<State> state_;
  bool started_ = false;
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
