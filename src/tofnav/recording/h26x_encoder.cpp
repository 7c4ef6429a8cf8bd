// SPDX-License-Identifier: BSD-3-Clause
// libx264 / libx265 through FFmpeg's libavcodec, set up as the headset's encoder (docs/ahat.md
// 3.6.4).
#include "tofnav/recording/h26x_codec.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/frame.h>
#include <libavutil/opt.h>
}

#include <cstring>
#include <stdexcept>

#include "tofnav/recording/h26x_libav.hpp"

namespace tofnav {
namespace {

using h26x_libav::ContextPtr;
using h26x_libav::ErrorText;
using h26x_libav::FramePtr;
using h26x_libav::PacketPtr;

void FillPlane(const Image<std::uint8_t>& in, int plane, AVFrame& frame) {
  for (int row = 0; row < in.height(); ++row) {
    std::memcpy(frame.data[plane] + static_cast<std::ptrdiff_t>(row) * frame.linesize[plane],
                &in(0, row), static_cast<std::size_t>(in.width()));
  }
}

}  // namespace

struct H26xEncoder::State {
  ContextPtr context;
  FramePtr frame{av_frame_alloc()};
  PacketPtr packet{av_packet_alloc()};
};

void H26xEncoderOptions::Check() const {
  if (bitrate_bps < 10000)
    throw std::invalid_argument("H26xEncoderOptions.bitrate_bps < 10 kbit/s");
  if (gop_frames < 1) throw std::invalid_argument("H26xEncoderOptions.gop_frames must be >= 1");
  if (divisor < 1) throw std::invalid_argument("H26xEncoderOptions.divisor must be >= 1");
}

H26xEncoder::H26xEncoder(const H26xEncoderOptions& options)
    : options_(options), state_(std::make_unique<State>()) {
  options.Check();
  h26x_libav::InstallLogCallback();
  const bool h265 = options.codec == H26xCodec::kH265;
  const char* name = h265 ? "libx265" : "libx264";
  const AVCodec* encoder = avcodec_find_encoder_by_name(name);
  if (encoder == nullptr || !state_->frame || !state_->packet) {
    throw std::runtime_error(std::string("libavcodec has no ") + name +
                             " encoder (Debian's libavcodec59 has both)");
  }
  state_->context.reset(avcodec_alloc_context3(encoder));
  AVCodecContext& context = *state_->context;
  context.width = kAhatWidth;
  context.height = kAhatHeight;
  context.pix_fmt = AV_PIX_FMT_YUV420P;
  context.time_base = AVRational{options.divisor, 45};
  context.framerate = AVRational{45, options.divisor};
  context.bit_rate = options.bitrate_bps;
  context.rc_max_rate = options.bitrate_bps;
  context.rc_buffer_size = static_cast<int>(options.bitrate_bps);  // a one-second buffer
  context.gop_size = options.gop_frames;
  context.keyint_min = options.gop_frames;
  context.max_b_frames = 0;
  context.thread_count = 1;
  // No AV_CODEC_FLAG_GLOBAL_HEADER: the parameter sets go in-band, before every key frame.
  AVDictionary* settings = nullptr;
  const std::string gop = std::to_string(options.gop_frames);
  // The headset's hardware encoder's own settings are not documented (docs/ahat.md 3.6.4): a
  // fast preset with no look-ahead stands in for it.
  if (h265) {
    av_dict_set(&settings, "preset", "superfast", 0);
    av_dict_set(&settings, "tune", "zerolatency", 0);
    av_dict_set(&settings, "x265-params",
                ("log-level=error:keyint=" + gop + ":min-keyint=" + gop +
                 ":scenecut=0:open-gop=0:bframes=0:rc-lookahead=0:frame-threads=1:pools=none:"
                 "repeat-headers=1")
                    .c_str(),
                0);
  } else {
    static constexpr const char* kProfiles[] = {"baseline", "main", "high"};
    av_dict_set(&settings, "profile", kProfiles[static_cast<int>(options.h264_profile)], 0);
    av_dict_set(&settings, "preset", "veryfast", 0);
    av_dict_set(&settings, "tune", "zerolatency", 0);
    av_dict_set(&settings, "x264-params",
                ("aud=1:keyint=" + gop + ":min-keyint=" + gop +
                 ":scenecut=0:bframes=0:rc-lookahead=0:sliced-threads=0:repeat-headers=1")
                    .c_str(),
                0);
  }
  h26x_libav::LastThreadError().clear();
  const int opened = avcodec_open2(&context, encoder, &settings);
  av_dict_free(&settings);
  if (opened < 0) {
    throw std::runtime_error(std::string("libavcodec: cannot open ") + name + ": " +
                             ErrorText(opened) + " " + h26x_libav::LastThreadError());
  }
  AVFrame& frame = *state_->frame;
  frame.format = AV_PIX_FMT_YUV420P;
  frame.width = kAhatWidth;
  frame.height = kAhatHeight;
  if (av_frame_get_buffer(&frame, 0) < 0) throw std::bad_alloc();
}

H26xEncoder::~H26xEncoder() = default;

std::vector<std::uint8_t> H26xEncoder::Encode(const Yuv420Picture& picture) {
  State& s = *state_;
  if (av_frame_make_writable(s.frame.get()) < 0) throw std::bad_alloc();
  FillPlane(picture.y, 0, *s.frame);
  FillPlane(picture.u, 1, *s.frame);
  FillPlane(picture.v, 2, *s.frame);
  s.frame->pts = next_pts_++;
  const int sent = avcodec_send_frame(s.context.get(), s.frame.get());
  if (sent < 0) throw std::runtime_error("libavcodec: encoding failed: " + ErrorText(sent));
  const int received = avcodec_receive_packet(s.context.get(), s.packet.get());
  if (received < 0) {
    throw std::runtime_error("libavcodec: the encoder gave no access unit for picture " +
                             std::to_string(next_pts_ - 1) + ": " + ErrorText(received));
  }
  std::vector<std::uint8_t> unit(s.packet->data, s.packet->data + s.packet->size);
  av_packet_unref(s.packet.get());
  return unit;
}

}  // namespace tofnav
