// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT H.264 / H.265 packets -> range and AB, as hl2ss's clients recover them
// (docs/ahat.md 3.6).
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav {
Hl2ssVideoDecoder::Hl2ssVideoDecoder(const Hl2ssAhatConfig& config, int frame_threads)
    : profile_z_(config.profile_z), decoder_(Hl2ssVideoCodec(config.profile_ab), frame_threads) {}

void Hl2ssVideoDecoder::Decode(std::span<const std::uint8_t> access_unit,
                               const H26xUnitPlace& place) {
  decoder_.Decode(access_unit, place, picture_);
}

void Hl2ssVideoDecoder::FillFrame(std::span<const std::uint8_t> zdepth, std::uint64_t zdepth_offset,
                                  const std::filesystem::path& source, AhatFrame& frame) const {
  frame.ab_lossy = true;
  if (profile_z_ == Hl2ssDepthProfile::kSame) {
    UnpackHl2ssSamePicture(picture_, frame.range_mm, frame.ab);
    frame.depth_step_mm = 4.0;  // and lossy: docs/ahat.md 3.6.2
    frame.ab_half_res = true;
    return;
  }
  frame.ab = UnpackHl2ssZdepthAb(picture_);
  frame.range_mm = DecodeZdepth(zdepth, source, zdepth_offset);
  if (frame.range_mm.width() != kAhatWidth || frame.range_mm.height() != kAhatHeight) {
    throw IoError(source, zdepth_offset,
                  "expected a 512 x 512 Zdepth frame, found " +
                      std::to_string(frame.range_mm.width()) + " x " +
                      std::to_string(frame.range_mm.height()));
  }
  frame.depth_step_mm = 2.0;  // exact at 201..749 mm, 2 mm steps above (docs/ahat.md 4.5)
}

}  // namespace tofnav
