// SPDX-License-Identifier: BSD-3-Clause
// `tofnav info`: one JSON tree per input, rendered as JSON or as text.
#include "tofnav/describe/describe.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/describe/describe_json.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_format.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/recording/stream_recorder.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

// Quantile of a histogram of integer values (q in [0, 1]); -1 when empty.
double HistogramQuantile(const std::vector<std::uint64_t>& histogram, double q) {
  const bool empty = std::all_of(histogram.begin(), histogram.end(), [](auto c) { return c == 0; });
  return empty ? -1.0 : QuantileOfCounts(histogram, q);
}

OrderedJson RigidJson(const Rigid3d& b_from_a) {
  const Eigen::AngleAxisd angle_axis(b_from_a.rotation);
  return OrderedJson{
      {"translation_mm",
       {b_from_a.translation.x(), b_from_a.translation.y(), b_from_a.translation.z()}},
      {"rotation_deg", angle_axis.angle() * kRadToDeg}};
}

OrderedJson TimingJson(const AhatRecording& recording) {
  const std::size_t n = recording.frame_count();
  OrderedJson timing{{"frames", n}};
  if (n == 0) return timing;
  const double first_s = static_cast<double>(recording.host_ticks(0)) * kSecondsPerHostTick;
  const double last_s = static_cast<double>(recording.host_ticks(n - 1)) * kSecondsPerHostTick;
  timing["first_timestamp_s"] = first_s;
  timing["duration_s"] = last_s - first_s;
  if (n < 2) return timing;
  std::vector<double> intervals_s;
  intervals_s.reserve(n - 1);
  for (std::size_t i = 1; i < n; ++i) {
    intervals_s.push_back(
        static_cast<double>(recording.host_ticks(i) - recording.host_ticks(i - 1)) *
        kSecondsPerHostTick);
  }
  const double median_s = Median(intervals_s);
  timing["median_interval_ms"] = median_s * 1e3;
  timing["median_rate_hz"] = median_s > 0.0 ? 1.0 / median_s : 0.0;
  timing["gaps_over_2x_median"] = std::count_if(intervals_s.begin(), intervals_s.end(),
                                                [&](double s) { return s > 2.0 * median_s; });
  return timing;
}

OrderedJson FrameStatisticsJson(const AhatRecording& recording, std::size_t sample_frames) {
  const std::size_t n = recording.frame_count();
  const std::size_t count = (sample_frames == 0 || sample_frames >= n) ? n : sample_frames;
  std::vector<std::uint64_t> range_histogram(4096, 0);
  std::vector<std::uint64_t> ab_histogram(65536, 0);
  std::uint64_t pixels = 0;
  std::size_t posed = 0;
  double max_step_mm = 0.0;
  bool ab_lossy = false;
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t index = count == n ? k : k * (n - 1) / std::max<std::size_t>(count - 1, 1);
    const AhatFrame frame = recording.ReadFrame(index);
    for (const std::uint16_t r : frame.range_mm.pixels()) ++range_histogram[std::min<int>(r, 4095)];
    for (const std::uint16_t a : frame.ab.pixels()) ++ab_histogram[a];
    pixels += frame.range_mm.size();
    posed += frame.world_from_rig.has_value() ? 1 : 0;
    max_step_mm = std::max(max_step_mm, frame.depth_step_mm);
    ab_lossy = ab_lossy || frame.ab_lossy;
  }
  const std::uint64_t invalid = range_histogram[0];
  range_histogram[0] = 0;
  return OrderedJson{
      {"sampled_frames", count},
      {"frames_with_pose", posed},
      {"valid_depth_fraction",
       pixels > 0 ? static_cast<double>(pixels - invalid) / static_cast<double>(pixels) : 0.0},
      {"range_mm",
       {{"min", HistogramQuantile(range_histogram, 0.0)},
        {"median", HistogramQuantile(range_histogram, 0.5)},
        {"max", HistogramQuantile(range_histogram, 1.0)}}},
      {"ab",
       {{"median", HistogramQuantile(ab_histogram, 0.5)},
        {"p99", HistogramQuantile(ab_histogram, 0.99)},
        {"max", HistogramQuantile(ab_histogram, 1.0)}}},
      {"depth_step_mm", max_step_mm},
      {"ab_lossy", ab_lossy}};
}

OrderedJson CalibrationJson(const AhatCalibration& calibration) {
  const AhatCamera camera(calibration);
  std::size_t valid = 0;
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) valid += camera.IsValid(u, v) ? 1 : 0;
  }
  // Field of view across the centre row: angle between its outermost valid rays.
  const int row = camera.height() / 2;
  int left = 0;
  int right = camera.width() - 1;
  while (left < right && !camera.IsValid(left, row)) ++left;
  while (right > left && !camera.IsValid(right, row)) --right;
  const double fov_rad = std::acos(std::clamp(
      static_cast<double>(camera.PixelRay(left, row).dot(camera.PixelRay(right, row))), -1.0, 1.0));
  const Eigen::Vector3d axis_in_rig = camera.rig_from_ahat().rotation * Eigen::Vector3d::UnitZ();
  return OrderedJson{{"size", {calibration.uv2xy.width(), calibration.uv2xy.height()}},
                     {"sample_offset_px", calibration.sample_offset_px},
                     {"valid_pixels", valid},
                     {"centre_row_fov_deg", fov_rad * kRadToDeg},
                     {"rig_from_ahat", RigidJson(calibration.rig_from_ahat)},
                     {"optical_axis_in_rig", {axis_in_rig.x(), axis_in_rig.y(), axis_in_rig.z()}},
                     {"pinhole_fx_fy_cx_cy",
                      {calibration.pinhole_fx_fy_cx_cy[0], calibration.pinhole_fx_fy_cx_cy[1],
                       calibration.pinhole_fx_fy_cx_cy[2], calibration.pinhole_fx_fy_cx_cy[3]}},
                     {"undistort_map", !calibration.undistort_map.empty()},
                     {"scale", calibration.scale},
                     {"alias_mm", calibration.alias_mm}};
}

OrderedJson RecordingJson(const AhatRecording& recording, const DescribeOptions& options) {
  OrderedJson out{{"kind", "recording"}, {"format", recording.format()}};
  out["timing"] = TimingJson(recording);
  if (const auto* hl2ss = dynamic_cast<const Hl2ssRecording*>(&recording)) {
    const Hl2ssAhatConfig& config = hl2ss->config();
    out["hl2ss"] = OrderedJson{
        {"mode", config.mode},
        {"divisor", config.divisor},
        {"profile_z", static_cast<int>(config.profile_z)},
        {"profile_ab", static_cast<int>(config.profile_ab)},
        {"profile", Hl2ssProfileName(config)},
        {"bitrate_bps", config.bitrate_bps},
        {"gop_frames", Hl2ssGopFrames(config)},
        {"measured_stream_mbit_s", (hl2ss->ab_bitrate_bps() + hl2ss->zdepth_bitrate_bps()) * 1e-6},
        {"user", std::string(hl2ss->user_data().begin(), hl2ss->user_data().end())},
        {"skipped_empty_packets", hl2ss->skipped_empty_packets()},
        {"truncated_tail", hl2ss->truncated_tail()}};
    if (config.profile_ab != Hl2ssVideoProfile::kRaw) {
      out["hl2ss"]["measured_gop_frames"] = hl2ss->measured_gop_frames();
      out["hl2ss"]["measured_video_mbit_s"] = hl2ss->ab_bitrate_bps() * 1e-6;
    }
  }
  if (const auto* capture = dynamic_cast<const StreamRecorderCapture*>(&recording)) {
    out["stream_recorder"] = OrderedJson{{"unpaired_frames", capture->report().unpaired_frames},
                                         {"other_entries", capture->report().other_entries},
                                         {"unposed_frames", capture->report().unposed_frames}};
  }
  if (recording.frame_count() > 0)
    out["frames"] = FrameStatisticsJson(recording, options.sample_frames);
  if (const auto calibration = recording.calibration())
    out["calibration"] = CalibrationJson(*calibration);
  return out;
}

OrderedJson MeshJson(const std::filesystem::path& path) {
  const TriangleMesh mesh = ReadMesh(path);
  OrderedJson out{
      {"kind", "mesh"}, {"vertices", mesh.vertices.size()}, {"triangles", mesh.triangles.size()}};
  if (!mesh.vertices.empty()) {
    Eigen::Vector3d lo = mesh.vertices.front();
    Eigen::Vector3d hi = lo;
    for (const Eigen::Vector3d& p : mesh.vertices) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    out["bounds_min_mm"] = {lo.x(), lo.y(), lo.z()};
    out["bounds_max_mm"] = {hi.x(), hi.y(), hi.z()};
  }
  out["surface_area_mm2"] = mesh.SurfaceAreaMm2();
  out["normals"] = !mesh.vertex_normals.empty();
  out["colors"] = !mesh.vertex_colors.empty();
  out["scalars"] = !mesh.vertex_scalars.empty();
  return out;
}

OrderedJson VolumeJson(const std::filesystem::path& path) {
  const CtVolume volume = ReadVolume(path);
  const Eigen::Vector3d spacing = volume.spacing_mm();
  const auto [lo, hi] = std::minmax_element(volume.values.begin(), volume.values.end());
  OrderedJson image_from_ijk = OrderedJson::array();
  for (int r = 0; r < 4; ++r) {
    image_from_ijk.push_back({volume.image_from_ijk(r, 0), volume.image_from_ijk(r, 1),
                              volume.image_from_ijk(r, 2), volume.image_from_ijk(r, 3)});
  }
  return OrderedJson{{"kind", "volume"},
                     {"name", volume.name},
                     {"modality", volume.modality},
                     {"dims", {volume.dims[0], volume.dims[1], volume.dims[2]}},
                     {"spacing_mm", {spacing.x(), spacing.y(), spacing.z()}},
                     {"image_from_ijk_lps", image_from_ijk},
                     {"geometry_source", volume.geometry_source},
                     {"value_min", volume.values.empty() ? 0.0 : *lo},
                     {"value_max", volume.values.empty() ? 0.0 : *hi}};
}

bool HasMagic(const std::filesystem::path& path, std::string_view magic) {
  const RandomAccessFile file(path);
  if (file.size() < magic.size()) return false;
  const std::vector<std::uint8_t> head = file.ReadAt(0, magic.size(), "magic");
  return std::equal(head.begin(), head.end(), magic.begin());
}

OrderedJson Describe(const std::filesystem::path& path, const DescribeOptions& options) {
  if (std::filesystem::is_directory(path)) {
    if (std::filesystem::exists(path / kStreamRecorderTar)) {
      return RecordingJson(*OpenAhatRecording(path), options);
    }
    if (std::filesystem::exists(path / "rm_depth_ahat") ||
        std::filesystem::exists(path / "uv2xy.bin")) {
      OrderedJson out{{"kind", "calibration"}, {"format", "hl2ss calibration folder"}};
      out.update(CalibrationJson(ReadHl2ssCalibration(path)));
      return out;
    }
    try {
      return VolumeJson(path);  // a DICOM series folder
    } catch (const IoError& e) {
      throw IoError(path, std::nullopt,
                    "expected a StreamRecorder capture (Depth AHaT.tar), an hl2ss calibration "
                    "folder (rm_depth_ahat/) or a DICOM series (" +
                        std::string(e.what()) + ")");
    }
  }
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".ply" || extension == ".stl" || extension == ".obj") return MeshJson(path);
  if (extension == ".json") return internal::DescribeJsonDocument(path);
  if (extension == ".nrrd" || extension == ".nii" || extension == ".gz" || extension == ".inv3") {
    return VolumeJson(path);
  }
  if (std::filesystem::exists(path) && std::filesystem::file_size(path) == kHl2ssMode2Bytes &&
      !HasMagic(path, "HL2SS")) {
    OrderedJson out{{"kind", "calibration"}, {"format", "hl2ss Mode-2 blob"}};
    out.update(CalibrationJson(DecodeHl2ssMode2(ReadFileBytes(path), path)));
    return out;
  }
  return RecordingJson(*OpenAhatRecording(path), options);
}

void RenderText(const OrderedJson& node, int indent, std::string& out) {
  for (const auto& [key, value] : node.items()) {
    out.append(static_cast<std::size_t>(indent), ' ');
    out += key + ":";
    if (value.is_object()) {
      out += "\n";
      RenderText(value, indent + 2, out);
      continue;
    }
    out += " " + (value.is_string() ? value.get<std::string>() : value.dump()) + "\n";
  }
}

}  // namespace

std::string DescribeAsJson(const std::filesystem::path& path, const DescribeOptions& options) {
  return Describe(path, options).dump(2);
}

std::string DescribeAsText(const std::filesystem::path& path, const DescribeOptions& options) {
  std::string out = path.string() + "\n";
  RenderText(Describe(path, options), 2, out);
  return out;
}

}  // namespace tofnav
