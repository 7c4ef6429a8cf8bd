// SPDX-License-Identifier: BSD-3-Clause
// libavcodec's log kept for error messages, its error texts (h26x_libav.hpp).
#include "tofnav/recording/h26x_libav.hpp"

extern "C" {
#include <libavutil/error.h>
#include <libavutil/log.h>
}

#include <cstdarg>
#include <cstdio>
#include <cstring>

namespace tofnav::h26x_libav {
namespace {

// libavcodec reports why a unit failed through its log, not its return codes: the last error
// line is kept for the message, and nothing is printed. A decoder's own lines (its frame threads
// log through copies of its context, which carry its `opaque`) go to that decoder's Log; any other
// line to the calling thread's.
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

}  // namespace

void InstallLogCallback() {
  static std::once_flag once;
  std::call_once(once, [] { av_log_set_callback(LogCallback); });
}

std::string& LastThreadError() { return last_library_error; }

std::string ErrorText(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof(text));
  return text;
}

std::string CodecName(H26xCodec codec) { return codec == H26xCodec::kH264 ? "H.264" : "H.265"; }

}  // namespace tofnav::h26x_libav
