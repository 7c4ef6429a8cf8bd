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
#include <deque>
#include <mutex>
#include <stdexcept>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

// libavcodec reports why a unit failed through its log, not its return codes: the last error
// line is kept for the message, and nothing is printed. A decoder's own lines (its frame threads
// log through copies of its context, which carry its `opaque`) go to that decoder's Log; any other
// line to the calling thread's.
struct DecoderLog {
  std::mutex mutex;
  std::string last_error;
};
thread_local std::string last_library_error;

DecoderLog* LogOf(void* object) {
  if (object == nullptr) return nullptr;
  const AVClass* type = *static_cast<const AVClass* const*>(object);
  if (type == nullptr || std::strcmp(type->class_name, "AVCodecContext") != 0) return nullptr;
  return static_cast<DecoderLog*>(static_cast<AVCodecContext*>(object)->opaque);
}

void LogCallback(void* object, int level, const char* format, va_list arguments) {
  if (level > AV_LOG_ERROR) return;
  char line[512];
  std::vsnprintf(line, sizeof(line), format, arguments);
  std::string text(line);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  if (text.empty()) return;
  if (DecoderLog* log = LogOf(object)) {
    const std::lock_guard lock(log->mutex);
    log->last_error = text;
  } else {
    last_library_error = text;
  }
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
  const int shift = plane == 0 ? 0 : 1;  // 4:2:0 chroma is half size both ways
  if (out.width() != kAhatWidth >> shift || out.height() != kAhatHeight >> shift) {
    out = Image<std::uint8_t>(kAhatWidth >> shift, kAhatHeight >> shift);
  }
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
  struct Unit {
    H26xUnitPlace place;
    std::int64_t pts;  // numbered by Send: a picture's pts names the unit it came from
  };
  std::deque<Unit> in_flight;  // sent units whose pictures have not come out, oldest first
  std::int64_t next_pts = 0;
  DecoderLog log;

  // The library's last error line since the last call, as " (libavcodec: ...)", or "".
  std::string TakeLibraryError() {
    std::string text;
    {
      const std::lock_guard lock(log.mutex);
      text.swap(log.last_error);
    }
    if (text.empty()) text.swap(last_library_error);
    return text.empty() ? std::string() : " (libavcodec: " + text + ")";
  }
};

H26xDecoder::H26xDecoder(H26xCodec codec, int frame_threads)
    : codec_(codec), frame_threads_(frame_threads), state_(std::make_unique<State>()) {
  if (frame_threads < 1 || frame_threads > 16) {
    throw std::invalid_argument("H26xDecoder: frame_threads must lie in [1, 16]");
  }
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
  context.opaque = &state_->log;
  context.thread_count = frame_threads_;
  // One thread: each picture comes out of its own unit at once (no B-frames). More: frame threads,
  // each picture frame_threads - 1 units later (the same pictures, bit for bit).
  context.thread_type = frame_threads_ > 1 ? FF_THREAD_FRAME : 0;
  if (frame_threads_ == 1) context.flags |= AV_CODEC_FLAG_LOW_DELAY;
  context.err_recognition = AV_EF_EXPLODE | AV_EF_BITSTREAM | AV_EF_BUFFER | AV_EF_CRCCHECK;
  const int opened = avcodec_open2(&context, decoder, nullptr);
  if (opened < 0) {
    throw std::runtime_error("libavcodec: cannot open the " + CodecName(codec_) +
                             " decoder: " + ErrorText(opened));
  }
  started_ = false;
  ended_ = false;
  state_->in_flight.clear();
  state_->TakeLibraryError();
}

Yuv420Picture H26xDecoder::Decode(std::span<const std::uint8_t> access_unit,
                                  const H26xUnitPlace& place) {
  Yuv420Picture picture;
  Decode(access_unit, place, picture);
  return picture;
}

void H26xDecoder::Decode(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place,
                         Yuv420Picture& picture) {
  if (frame_threads_ != 1) throw std::logic_error("H26xDecoder::Decode needs one frame thread");
  Send(access_unit, place);
  if (!Receive(picture)) {
    throw Failure(place, access_unit.size(),
                  "gave no picture (a stream with reordered frames or a unit without a slice?)" +
                      state_->TakeLibraryError());
  }
}

IoError H26xDecoder::Failure(const H26xUnitPlace& place, std::size_t bytes,
                             const std::string& what) const {
  return IoError(place.source, place.offset,
                 "frame " + std::to_string(place.frame) + ": " + CodecName(codec_) +
                     " access unit of " + std::to_string(bytes) + " bytes " + what);
}

void H26xDecoder::Send(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place) {
  if (ended_) throw std::logic_error("H26xDecoder::Send after SendEnd (Reset first)");
  if (!started_ && !H26xIsKeyFrame(codec_, access_unit)) {
    throw Failure(place, access_unit.size(),
                  "is not a key frame, and the decoder has none to start from (a stream must "
                  "start with an IDR picture)");
  }
  started_ = true;
  State& s = *state_;
  H26xUnitPlace sent = place;
  sent.bytes = access_unit.size();
  s.in_flight.push_back({std::move(sent), s.next_pts});
  s.packet->pts = s.next_pts++;
  s.padded.assign(access_unit.size() + AV_INPUT_BUFFER_PADDING_SIZE, 0);
  std::copy(access_unit.begin(), access_unit.end(), s.padded.begin());
  s.packet->data = s.padded.data();
  s.packet->size = static_cast<int>(access_unit.size());
  // A line logged for a unit still in flight (by its frame thread) is kept for its failure.
  if (s.in_flight.size() == 1) s.TakeLibraryError();
  const int sent_code = avcodec_send_packet(s.context.get(), s.packet.get());
  s.packet->data = nullptr;
  s.packet->size = 0;
  // With frame threads a failure may be an older unit's: the oldest in flight is the one named.
  if (sent_code < 0) Fail("does not decode: " + ErrorText(sent_code));
}

void H26xDecoder::SendEnd() {
  if (ended_) return;
  ended_ = true;
  const int code = avcodec_send_packet(state_->context.get(), nullptr);
  if (code < 0 && code != AVERROR_EOF && !state_->in_flight.empty()) {
    Fail("does not decode: " + ErrorText(code));
  }
}

void H26xDecoder::Fail(const std::string& what) {
  State& s = *state_;
  const H26xUnitPlace place = s.in_flight.empty() ? H26xUnitPlace{} : s.in_flight.front().place;
  throw Failure(place, place.bytes, what + s.TakeLibraryError());
}

bool H26xDecoder::Receive(Yuv420Picture& picture) {
  State& s = *state_;
  if (s.in_flight.empty()) return false;
  const int received = avcodec_receive_frame(s.context.get(), s.frame.get());
  if (received == AVERROR(EAGAIN)) return false;
  if (received == AVERROR_EOF) {
    Fail("gave no picture (a stream with reordered frames or a unit without a slice?)");
  }
  if (received < 0) Fail("does not decode: " + ErrorText(received));
  const AVFrame& frame = *s.frame;
  if (frame.pts != AV_NOPTS_VALUE && frame.pts > s.in_flight.front().pts) {
    // An older unit gave no picture (a unit without a slice): it fails, not this picture.
    av_frame_unref(s.frame.get());
    Fail("gave no picture (a stream with reordered frames or a unit without a slice?)");
  }
  if ((frame.flags & AV_FRAME_FLAG_CORRUPT) != 0 || frame.decode_error_flags != 0) {
    av_frame_unref(s.frame.get());
    Fail("decodes to a damaged picture");
  }
  const bool planar420 = frame.format == AV_PIX_FMT_YUV420P || frame.format == AV_PIX_FMT_YUVJ420P;
  if (frame.width != kAhatWidth || frame.height != kAhatHeight || !planar420) {
    const std::string found = std::to_string(frame.width) + " x " + std::to_string(frame.height) +
                              " " + std::to_string(frame.format);
    av_frame_unref(s.frame.get());
    Fail("decodes to a " + found + " picture, expected 512 x 512 8-bit 4:2:0");
  }
  CopyPlane(frame, 0, picture.y);
  CopyPlane(frame, 1, picture.u);
  CopyPlane(frame, 2, picture.v);
  av_frame_unref(s.frame.get());
  s.in_flight.pop_front();
  return true;
}

std::size_t H26xDecoder::in_flight() const { return state_->in_flight.size(); }

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
