// SPDX-License-Identifier: BSD-3-Clause
// H.264 / H.265 through FFmpeg's libavcodec (docs/ahat.md 3.6): a strict decoder for hl2ss's
// access units and libx264 / libx265 set up as the headset's encoder.
#include "tofnav/recording/h26x_codec.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
}

#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

// libavcodec reports why a unit failed through its log, not its return codes: the last error
// line of this thread is kept for the message, and nothing is printed.
thread_local std::string last_library_error;

void LogCallback(void* /*context*/, int level, const char* format, va_list arguments) {
  if (level > AV_LOG_ERROR) return;
  char line[512];
  std::vsnprintf(line, sizeof(line), format, arguments);
  std::string text(line);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  if (!text.empty()) last_library_error = text;
}

void InstallLogCallback() {
  static std::once_flag once;
  std::call_once(once, [] { av_log_set_callback(LogCallback); });
}

std::string ErrorText(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof(text));
  return text;
}

std::string CodecName(H26xCodec codec) { return codec == H26xCodec::kH264 ? "H.264" : "H.265"; }

/// The NAL unit types of the access unit's Annex B stream, in order.
template <typename Visit>
void ForEachNalHeader(std::span<const std::uint8_t> bytes, Visit visit) {
  std::size_t zeros = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (bytes[i] == 0) {
      ++zeros;
      continue;
    }
    if (bytes[i] == 1 && zeros >= 2 && i + 1 < bytes.size()) visit(bytes.subspan(i + 1));
    zeros = 0;
  }
}

struct CodecContextDeleter {
  void operator()(AVCodecContext* context) const { avcodec_free_context(&context); }
};
struct FrameDeleter {
  void operator()(AVFrame* frame) const { av_frame_free(&frame); }
};
struct PacketDeleter {
  void operator()(AVPacket* packet) const { av_packet_free(&packet); }
};
using ContextPtr = std::unique_ptr<AVCodecContext, CodecContextDeleter>;
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;

void CopyPlane(const AVFrame& frame, int plane, Image<std::uint8_t>& out) {
  for (int row = 0; row < out.height(); ++row) {
    std::memcpy(&out(0, row),
                frame.data[plane] + static_cast<std::ptrdiff_t>(row) * frame.linesize[plane],
                static_cast<std::size_t>(out.width()));
  }
}

void FillPlane(const Image<std::uint8_t>& in, int plane, AVFrame& frame) {
  for (int row = 0; row < in.height(); ++row) {
    std::memcpy(frame.data[plane] + static_cast<std::ptrdiff_t>(row) * frame.linesize[plane],
                &in(0, row), static_cast<std::size_t>(in.width()));
  }
}

}  // namespace

bool H26xIsKeyFrame(H26xCodec codec, std::span<const std::uint8_t> access_unit) {
  bool key = false;
  ForEachNalHeader(access_unit, [&](std::span<const std::uint8_t> nal) {
    if (codec == H26xCodec::kH264) {
      key = key || (nal[0] & 0x1F) == 5;  // IDR slice
    } else {
      const int type = (nal[0] >> 1) & 0x3F;
      key = key || (type >= 16 && type <= 21);  // BLA, IDR, CRA
    }
  });
  return key;
}

// ---------------------------------------------------------------------------------------------
// Decoder

struct H26xDecoder::State {
  ContextPtr context;
  FramePtr frame{av_frame_alloc()};
  PacketPtr packet{av_packet_alloc()};
  std::vector<std::uint8_t> padded;  // libavcodec reads up to 64 bytes past the unit's end
};

H26xDecoder::H26xDecoder(H26xCodec codec) : codec_(codec), state_(std::make_unique<State>()) {
  InstallLogCallback();
  Reset();
}

H26xDecoder::~H26xDecoder() = default;

void H26xDecoder::Reset() {
  const AVCodec* decoder =
      avcodec_find_decoder(codec_ == H26xCodec::kH264 ? AV_CODEC_ID_H264 : AV_CODEC_ID_HEVC);
  if (decoder == nullptr || !state_->frame || !state_->packet) {
    throw std::runtime_error("libavcodec: no " + CodecName(codec_) + " decoder");
  }
  state_->context.reset(avcodec_alloc_context3(decoder));
  AVCodecContext& context = *state_->context;
  context.thread_count = 1;                  // no frame threading: one picture per unit, in order
  context.flags |= AV_CODEC_FLAG_LOW_DELAY;  // no B-frames: output each picture at once
  context.err_recognition = AV_EF_EXPLODE | AV_EF_BITSTREAM | AV_EF_BUFFER | AV_EF_CRCCHECK;
  const int opened = avcodec_open2(&context, decoder, nullptr);
  if (opened < 0) {
    throw std::runtime_error("libavcodec: cannot open the " + CodecName(codec_) +
                             " decoder: " + ErrorText(opened));
  }
  started_ = false;
}

Yuv420Picture H26xDecoder::Decode(std::span<const std::uint8_t> access_unit,
                                  const H26xUnitPlace& place) {
  const auto fail = [&](const std::string& what) {
    return IoError(place.source, place.offset,
                   "frame " + std::to_string(place.frame) + ": " + CodecName(codec_) +
                       " access unit of " + std::to_string(access_unit.size()) + " bytes " + what);
  };
  if (!started_ && !H26xIsKeyFrame(codec_, access_unit)) {
    throw fail(
        "is not a key frame, and the decoder has none to start from (a stream must start "
        "with an IDR picture)");
  }
  State& s = *state_;
  s.padded.assign(access_unit.size() + AV_INPUT_BUFFER_PADDING_SIZE, 0);
  std::copy(access_unit.begin(), access_unit.end(), s.padded.begin());
  s.packet->data = s.padded.data();
  s.packet->size = static_cast<int>(access_unit.size());
  last_library_error.clear();
  const int sent = avcodec_send_packet(s.context.get(), s.packet.get());
  s.packet->data = nullptr;
  s.packet->size = 0;
  const auto library = [] {
    return last_library_error.empty() ? std::string() : " (libavcodec: " + last_library_error + ")";
  };
  if (sent < 0) throw fail("does not decode: " + ErrorText(sent) + library());
  const int received = avcodec_receive_frame(s.context.get(), s.frame.get());
  if (received == AVERROR(EAGAIN)) {
    throw fail("gave no picture (a stream with reordered frames or a unit without a slice?)" +
               library());
  }
  if (received < 0) throw fail("does not decode: " + ErrorText(received) + library());
  const AVFrame& frame = *s.frame;
  if ((frame.flags & AV_FRAME_FLAG_CORRUPT) != 0 || frame.decode_error_flags != 0) {
    av_frame_unref(s.frame.get());
    throw fail("decodes to a damaged picture" + library());
  }
  const bool planar420 = frame.format == AV_PIX_FMT_YUV420P || frame.format == AV_PIX_FMT_YUVJ420P;
  if (frame.width != kAhatWidth || frame.height != kAhatHeight || !planar420) {
    const std::string found = std::to_string(frame.width) + " x " + std::to_string(frame.height) +
                              " " + std::to_string(frame.format);
    av_frame_unref(s.frame.get());
    throw fail("decodes to a " + found + " picture, expected 512 x 512 8-bit 4:2:0");
  }
  Yuv420Picture picture;
  CopyPlane(frame, 0, picture.y);
  CopyPlane(frame, 1, picture.u);
  CopyPlane(frame, 2, picture.v);
  av_frame_unref(s.frame.get());
  started_ = true;
  return picture;
}

// ---------------------------------------------------------------------------------------------
// Encoder

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
  InstallLogCallback();
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
  last_library_error.clear();
  const int opened = avcodec_open2(&context, encoder, &settings);
  av_dict_free(&settings);
  if (opened < 0) {
    throw std::runtime_error(std::string("libavcodec: cannot open ") + name + ": " +
                             ErrorText(opened) + " " + last_library_error);
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
