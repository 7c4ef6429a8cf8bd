// SPDX-License-Identifier: BSD-3-Clause
// H.264 / H.265 through FFmpeg's libavcodec (docs/ahat.md 3.6): a strict decoder for hl2ss's
// access units, on one thread (live) or on frame threads (a recording read ahead).
#include "tofnav/recording/h26x_codec.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/frame.h>
}

#include <cstring>
#include <deque>
#include <mutex>
#include <stdexcept>

#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/h26x_libav.hpp"

namespace tofnav {
namespace {

using h26x_libav::CodecName;
using h26x_libav::ContextPtr;
using h26x_libav::DecoderLog;
using h26x_libav::ErrorText;
using h26x_libav::FramePtr;
using h26x_libav::PacketPtr;

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
  // Declared first, so destroyed last: freeing the context joins its frame threads, which may still
  // log into it (LeakSanitizer caught a line written into a destroyed log, session 62's CI).
  DecoderLog log;
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

  // The library's last error line since the last call, as " (libavcodec: ...)", or "".
  std::string TakeLibraryError() {
    std::string text;
    {
      const std::lock_guard lock(log.mutex);
      text.swap(log.last_error);
    }
    if (text.empty()) text.swap(h26x_libav::LastThreadError());
    return text.empty() ? std::string() : " (libavcodec: " + text + ")";
  }
};

H26xDecoder::H26xDecoder(H26xCodec codec, int frame_threads)
    : codec_(codec), frame_threads_(frame_threads), state_(std::make_unique<State>()) {
  if (frame_threads < 1 || frame_threads > 16) {
    throw std::invalid_argument("H26xDecoder: frame_threads must lie in [1, 16]");
  }
  h26x_libav::InstallLogCallback();
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

}  // namespace tofnav
