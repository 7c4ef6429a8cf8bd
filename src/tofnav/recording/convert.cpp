// SPDX-License-Identifier: BSD-3-Clause
// Re-writes an AHAT recording in another container.
#include "tofnav/recording/convert.hpp"

#include <limits>

#include "tofnav/core/require.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/stream_recorder.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {
namespace {

// Frame loop shared by both writers (each has Append(frame) and Close()).
template <typename Writer>
ConvertResult CopyFrames(const AhatRecording& input, Writer& writer,
                         const ConvertOptions& options) {
  ConvertResult result;
  const std::size_t n = input.frame_count();
  for (std::size_t i = 0; i < n; ++i) {
    const AhatFrame frame = input.ReadFrame(i);
    writer.Append(frame);
    ++result.frames_written;
    result.frames_with_pose += frame.world_from_rig ? 1 : 0;
    if (options.progress) options.progress(i + 1, n);
  }
  writer.Close();
  return result;
}

// The StreamRecorder LUT is the ray at API point (u + 0.5, v + 0.5), which is exactly our pixel
// centre ray (c = 0.5); a table sampled at s = 0 is re-sampled there through the camera model.
AhatCalibration WithHalfPixelSamples(const AhatCalibration& calibration) {
  if (calibration.sample_offset_px == 0.5) return calibration;
  const AhatCamera camera(calibration);
  AhatCalibration out = calibration;
  out.sample_offset_px = 0.5;
  constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const Eigen::Vector3f& ray = camera.PixelRay(u, v);
      out.uv2xy(u, v) = camera.IsValid(u, v) ? Eigen::Vector2f(ray.x() / ray.z(), ray.y() / ray.z())
                                             : Eigen::Vector2f(kNan, kNan);
    }
  }
  return out;
}

}  // namespace

ConvertResult ConvertRecording(const AhatRecording& input, const std::filesystem::path& output,
                               const ConvertOptions& options) {
  if (options.format == RecordingFormat::kStreamRecorder) {
    const std::optional<AhatCalibration> calibration =
        options.calibration ? options.calibration : input.calibration();
    Require(calibration.has_value(),
            "StreamRecorder output needs a calibration (the input has none: pass one)");
    StreamRecorderWriter writer(output, WithHalfPixelSamples(*calibration));
    return CopyFrames(input, writer, options);
  }
  Hl2ssWriterOptions writer_options;
  writer_options.mode = 1;
  writer_options.profile_z = options.format == RecordingFormat::kHl2ssZdepth
                                 ? Hl2ssDepthProfile::kZdepth
                                 : Hl2ssDepthProfile::kSame;
  Hl2ssRecordingWriter writer(output, writer_options);
  return CopyFrames(input, writer, options);
}

}  // namespace tofnav
