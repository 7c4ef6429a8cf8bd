// SPDX-License-Identifier: BSD-3-Clause
// How hl2ss packs AHAT depth and AB into the 8-bit 4:2:0 pictures its H.264/H.265 profiles encode,
// and how its clients recover them (docs/ahat.md 3.6): the AB -> 8-bit code through IEEE half
// floats, the SAME and ZDEPTH packings, and the client-side recovery.
#pragma once

#include <cstdint>

#include "tofnav/core/image.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

/// One 512 x 512 picture in planar 4:2:0 (what libavcodec decodes to): Y 512 x 512, U and V
/// 256 x 256, 8-bit codes read as they are (no colour conversion).
struct Yuv420Picture {
  Image<std::uint8_t> y{kAhatWidth, kAhatHeight};
  Image<std::uint8_t> u{kAhatWidth / 2, kAhatHeight / 2};
  Image<std::uint8_t> v{kAhatWidth / 2, kAhatHeight / 2};
  bool operator==(const Yuv420Picture&) const = default;
};

/// The server's AB -> 8-bit code A(x): x converted to IEEE half (round to nearest even, x >= 65520
/// is +inf), its half-precision square root, truncated to u16 (saturating), the low 8 bits. About
/// floor(sqrt(x)), one higher for 3214 of the 65536 inputs (docs/ahat.md 3.6.1).
std::uint8_t Hl2ssAbCode(std::uint16_t ab);

/// SAME + H26x: Y = the low 8 bits of (range >> 2) (range >= 4090 taken as 0), the chroma planes
/// hold A(AB) of the even columns, two AB rows per chroma row (docs/ahat.md 3.6.2).
Yuv420Picture PackHl2ssSamePicture(const Image<std::uint16_t>& range_mm,
                                   const Image<std::uint16_t>& ab);
/// ZDEPTH + H26x: Y = A(AB) at full resolution, U = V = 128 (docs/ahat.md 3.6.3).
Yuv420Picture PackHl2ssZdepthPicture(const Image<std::uint16_t>& ab);

/// What an hl2ss client recovers from a decoded SAME picture: range = 4 Y [mm], AB = code^2 of
/// each even column, written to it and its odd neighbour.
void UnpackHl2ssSamePicture(const Yuv420Picture& picture, Image<std::uint16_t>& range_mm,
                            Image<std::uint16_t>& ab);
/// ... and from a ZDEPTH picture: AB = Y^2.
Image<std::uint16_t> UnpackHl2ssZdepthAb(const Yuv420Picture& picture);

}  // namespace tofnav
