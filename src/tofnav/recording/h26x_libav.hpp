// SPDX-License-Identifier: BSD-3-Clause
// What the H.264 / H.265 decoder and encoder share about libavcodec (internal to recording/): its
// log, kept for error messages instead of printed; error texts; owning pointers.
#pragma once

extern "C" {
#include <libavcodec/avcodec.h>
}

#include <memory>
#include <mutex>
#include <string>

#include "tofnav/recording/h26x_codec.hpp"

namespace tofnav::h26x_libav {

/// Where a decoder's libavcodec error lines go: its context's `opaque` points here, and so do the
/// copies of the context its frame threads log through.
struct DecoderLog {
  std::mutex mutex;
  std::string last_error;
};

/// Routes libavcodec's log (once per process): lines at error level or worse are kept, in the
/// DecoderLog of the context that logged them or else in the calling thread's LastThreadError();
/// nothing is printed.
void InstallLogCallback();
/// The last error line libavcodec logged on this thread outside a decoder's context.
std::string& LastThreadError();
std::string ErrorText(int code);
std::string CodecName(H26xCodec codec);

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

}  // namespace tofnav::h26x_libav
