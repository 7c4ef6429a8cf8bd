// SPDX-License-Identifier: BSD-3-Clause
// Fidelity, STTAR's sphere markers (Martin-Gomez, Li et al., IEEE TVCG 2023; docs/simulator.md
// 10.1): a four-sphere tool static in front of a fixed headset at 350-700 mm, each pose then moved
// 20 mm along the camera's z (MarkerNoiseScenario). Each marker's measured depth over a hold (its
// noise, measured as STTAR does), the measured 20 mm move (raw and filtered poses), and the raw
// poses' lateral, longitudinal and rotation errors against the truth.
#include <algorithm>
#include <cmath>

#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/casefile/tool_poses_io.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/evaluation/demo_stages.hpp"
#include "tofnav/evaluation/fidelity.hpp"
#include "tofnav/evaluation/tracking_truth.hpp"
#include "tofnav/markers/marker_centre.hpp"
#include "tofnav/pipeline/marker_tasks.hpp"
#include "tofnav/sensor/ahat_frame.hpp"
#include "tofnav/sim/scenario_fidelity.hpp"

namespace tofnav {
namespace {

const char* const kSttarExperiment = "STTAR sphere markers";
const char* const kSttarSource = "STTAR (TVCG 2023), real HoloLens 2, 350-700 mm";
// A detected centre this close to a true sphere centre is that sphere's (spheres >= 40 mm apart).
constexpr double kSttarMatchMm = 8.0;
// The nearest and the farthest quarter of the depth range give the two noise rows (STTAR: 0.49
// mm near, 1.08 mm far).
constexpr double kSttarEndFraction = 0.25;
// Frames at the start of a hold left out of the move's pairs: tofnav's filter gates the 20 mm
// jump into a hold, restarts from a raw pose within three frames and settles over about five
// more (tracking/pose_filter.hpp); the raw poses use the same pairs.
constexpr std::int64_t kSttarSettleFrames = 8;
constexpr double kSttarMinHoldFrames = 12.0;  // frames per hold at any frames_scale

// Per hold: the depth (camera z) of its markers' centroid, and per marker its depths over the
// hold's frames, measured two ways: as STTAR does (unit ray at the blob centroid times the range
// of the one pixel at the truncated centroid plus the radius, docs/tracking.md 7.1), and as
// tofnav does (MarkerCentres: the core pixels' trimmed mean, f_rf applied).
struct SttarHoldDepths {
  double depth_mm = 0.0;
  std::vector<std::vector<double>> pixel_z_mm, centre_z_mm;
};

Eigen::Vector3d SttarCentroid(const ToolGeometry& tool) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& m : tool.markers_in_tool) sum += m;
  return sum / static_cast<double>(tool.markers_in_tool.size());
}

// Every detected sphere matched to the nearest true centre, its depth measured both ways.
std::vector<SttarHoldDepths> SttarMarkerDepths(const FidelityOptions& options,
                                               const MarkerSource& source,
                                               const std::vector<sim::MarkerNoiseHold>& holds,
                                               const ToolGeometry& tool,
                                               const MarkerRangeModel& frf) {
  std::vector<SttarHoldDepths> depths(holds.size());
  const Eigen::Vector3d centroid = SttarCentroid(tool);
  for (std::size_t h = 0; h < holds.size(); ++h) {
    depths[h].depth_mm = (holds[h].ahat_from_tool * centroid).z();
    depths[h].pixel_z_mm.resize(tool.markers_in_tool.size());
    depths[h].centre_z_mm.resize(tool.markers_in_tool.size());
  }
  const std::int64_t per_hold = holds.front().frames;
  const double radius_mm = tool.SurfaceToCentreMm();
  ForEachFrameMarkers(
      source, MarkerDetectionOptions{},
      [&](std::size_t index, const AhatFrame& frame, std::vector<DetectedMarker>& markers) {
        const auto h = static_cast<std::size_t>(static_cast<std::int64_t>(index) / per_hold);
        if (h >= holds.size()) return;
        if (!frf.empty()) markers = CorrectMarkerRanges(std::move(markers), frf);
        const Points3d centres = MarkerCentres(markers, radius_mm);
        for (std::size_t m = 0; m < tool.markers_in_tool.size(); ++m) {
          const Eigen::Vector3d truth = holds[h].ahat_from_tool * tool.markers_in_tool[m];
          double best_mm = kSttarMatchMm;
          std::size_t nearest = centres.size();
          for (std::size_t c = 0; c < centres.size(); ++c) {
            if ((centres[c] - truth).norm() < best_mm) {
              best_mm = (centres[c] - truth).norm();
              nearest = c;
            }
          }
          if (nearest == centres.size()) continue;
          depths[h].centre_z_mm[m].push_back(centres[nearest].z());
          const DetectedMarker& d = markers[nearest];
          const int u = static_cast<int>(d.pixel.x()), v = static_cast<int>(d.pixel.y());
          if (u < 0 || v < 0 || u >= frame.range_mm.width() || v >= frame.range_mm.height()) {
            continue;
          }
          const std::uint16_t range = frame.range_mm(u, v);
          if (range == 0 || range >= kAhatInvalidRange) continue;
          depths[h].pixel_z_mm[m].push_back(d.ray_in_ahat.z() * (range + radius_mm));
        }
      },
      [&](std::size_t d, std::size_t t) {
        if (options.progress) options.progress("STTAR markers: marker depths", d, t);
      });
  return depths;
}

// Mean per-marker depth sd (of `which` depths) over the holds whose depth is in [from_mm, to_mm].
double SttarMeanMarkerSd(const std::vector<SttarHoldDepths>& depths, double from_mm, double to_mm,
                         std::vector<std::vector<double>> SttarHoldDepths::*which,
                         std::size_t& markers) {
  std::vector<double> sds;
  for (const SttarHoldDepths& hold : depths) {
    if (hold.depth_mm < from_mm || hold.depth_mm > to_mm) continue;
    for (const std::vector<double>& z : hold.*which) {
      if (z.size() >= 3) sds.push_back(Summarise(z).sd);
    }
  }
  markers = sds.size();
  return sds.empty() ? std::nan("") : Mean(sds);
}

nlohmann::ordered_json SttarSds(const std::vector<std::vector<double>>& per_marker) {
  nlohmann::ordered_json sds = nlohmann::ordered_json::array();
  for (const std::vector<double>& z : per_marker) {
    sds.push_back(z.size() >= 3 ? nlohmann::ordered_json(Summarise(z).sd) : nullptr);
  }
  return sds;
}

// The tool's poses over the recording, one per frame (nullopt where none), from TrackTools;
// written to DIR/poses_<name>.csv.
struct SttarPoses {
  std::vector<ToolEvaluationFrame> frames;  // by frame index
};

SttarPoses SttarTrack(const FidelityOptions& options, const MarkerSource& source,
                      const ToolGeometry& tool, const MarkerRangeModel& frf,
                      const ToolTrackerOptions& tracker, const std::filesystem::path& dir,
                      const std::string& name) {
  const std::string label = "STTAR markers: track " + name;
  const std::vector<ToolPoseRecord> records = TrackTools(
      source, MarkerDetectionOptions{}, {tool}, tracker, frf, [&](std::size_t d, std::size_t t) {
        if (options.progress) options.progress(label, d, t);
      });
  WriteToolPoses(dir / ("poses_" + name + ".csv"), records);
  const std::vector<ToolTruthEvaluation> e =
      EvaluateTrackingAgainstTruth(records, dir / "truth.json");
  if (e.size() != 1) throw std::runtime_error("STTAR markers: the tool has no poses");
  SttarPoses poses;
  poses.frames.resize(source.frames);
  for (std::size_t i = 0; i < records.size(); ++i) {
    poses.frames.at(static_cast<std::size_t>(records[i].frame)) = e[0].frames.at(i);
  }
  return poses;
}

// |measured move - move_mm| of the markers' centroid, per frame pair: frame k of a position's
// static hold against frame k of its moved hold, for k >= kSttarSettleFrames.
std::vector<double> SttarMoveErrors(const SttarPoses& poses,
                                    const std::vector<sim::MarkerNoiseHold>& holds,
                                    const Eigen::Vector3d& centroid, double move_mm,
                                    bool filtered) {
  std::vector<double> errors;
  for (std::size_t h = 0; h + 1 < holds.size(); h += 2) {
    for (std::int64_t k = kSttarSettleFrames; k < holds[h].frames; ++k) {
      const ToolEvaluationFrame& a =
          poses.frames.at(static_cast<std::size_t>(holds[h].first_slot + k));
      const ToolEvaluationFrame& b =
          poses.frames.at(static_cast<std::size_t>(holds[h + 1].first_slot + k));
      const std::optional<Rigid3d>& pa = filtered ? a.filtered : a.raw;
      const std::optional<Rigid3d>& pb = filtered ? b.filtered : b.raw;
      if (!pa || !pb) continue;
      errors.push_back(std::abs(((*pb * centroid) - (*pa * centroid)).norm() - move_mm));
    }
  }
  return errors;
}

nlohmann::ordered_json SttarSummaryJson(const Summary& s) {
  return {{"count", s.count}, {"mean", s.mean}, {"sd", s.sd}, {"median", s.median}};
}

}  // namespace

void FidelitySttarMarkers(const FidelityOptions& options, const MarkerRangeModel& frf,
                          FidelityResult& result) {
  sim::MarkerNoiseProtocol protocol;
  protocol.positions = options.marker_positions;
  protocol.frames_per_hold = static_cast<std::int64_t>(
      std::max(kSttarMinHoldFrames,
               std::round(static_cast<double>(options.marker_hold_frames) * options.frames_scale)));
  protocol.seed = options.seed;
  const std::vector<sim::MarkerNoiseHold> holds = sim::MarkerNoiseHolds(protocol);
  const std::filesystem::path dir = options.out / "sttar_markers";
  SimulateForFidelity(options, sim::MarkerNoiseScenario(protocol), dir, "STTAR markers: simulate",
                      options.seed);
  const MarkerSource source = OpenSimulatedMarkerSource(dir);
  const ToolGeometry tool =
      ReadToolFile(dir / "tools" / (std::string(sim::kMarkerNoiseToolName) + ".json"));
  const Eigen::Vector3d centroid = SttarCentroid(tool);

  // (1) Per-marker depth noise, the nearest and the farthest quarter of 350-700 mm: the rows as
  // STTAR measured it (one pixel's range), tofnav's centres in the details.
  const std::vector<SttarHoldDepths> depths = SttarMarkerDepths(options, source, holds, tool, frf);
  const double end_mm = kSttarEndFraction * (protocol.max_depth_mm - protocol.min_depth_mm);
  const double near_to_mm = protocol.min_depth_mm + end_mm;
  const double far_from_mm = protocol.max_depth_mm - end_mm;
  std::size_t near_markers = 0, far_markers = 0, unused = 0;
  const double near_sd = SttarMeanMarkerSd(depths, protocol.min_depth_mm, near_to_mm,
                                           &SttarHoldDepths::pixel_z_mm, near_markers);
  const double far_sd = SttarMeanMarkerSd(depths, far_from_mm, protocol.max_depth_mm,
                                          &SttarHoldDepths::pixel_z_mm, far_markers);
  const double near_centre_sd = SttarMeanMarkerSd(depths, protocol.min_depth_mm, near_to_mm,
                                                  &SttarHoldDepths::centre_z_mm, unused);
  const double far_centre_sd = SttarMeanMarkerSd(depths, far_from_mm, protocol.max_depth_mm,
                                                 &SttarHoldDepths::centre_z_mm, unused);

  // (2) and (3): tofnav's tracker with f_rf, filter off (raw) and on (its default).
  const SttarPoses raw =
      SttarTrack(options, source, tool, frf, {.filter_enabled = false}, dir, "raw");
  const SttarPoses filtered = SttarTrack(options, source, tool, frf, {}, dir, "filtered");
  const Summary move_raw =
      Summarise(SttarMoveErrors(raw, holds, centroid, protocol.move_mm, false));
  const Summary move_filtered =
      Summarise(SttarMoveErrors(filtered, holds, centroid, protocol.move_mm, true));
  std::vector<double> lateral, longitudinal, rotation;
  for (const ToolEvaluationFrame& f : raw.frames) {
    if (!f.raw) continue;
    const Eigen::Vector3d at = f.true_ahat_from_tool * centroid;
    const Eigen::Vector3d error = *f.raw * centroid - at;
    const Eigen::Vector3d ray = at.normalized();
    longitudinal.push_back(std::abs(error.dot(ray)));
    lateral.push_back((error - error.dot(ray) * ray).norm());
    rotation.push_back(RotationDistanceRad(*f.raw, f.true_ahat_from_tool) / kDegToRad);
  }
  if (move_raw.count == 0 || lateral.empty()) {
    throw std::runtime_error("STTAR markers: the tool was not tracked");
  }
  const Summary lat = Summarise(lateral), lon = Summarise(longitudinal), rot = Summarise(rotation);

  const auto row = [&](const std::string& figure, double published, std::optional<double> sd,
                       double ours) {
    result.rows.push_back(
        MakeFidelityRow(kSttarExperiment, figure, kSttarSource, published, sd, ours));
  };
  row("marker depth sd (one pixel), nearest quarter [mm]", 0.49, std::nullopt, near_sd);
  row("marker depth sd (one pixel), farthest quarter [mm]", 1.08, std::nullopt, far_sd);
  row("20 mm move along z: error, raw [mm]", 0.38, 0.52, move_raw.mean);
  row("20 mm move along z: error, filtered [mm]", 0.36, 0.22, move_filtered.mean);
  row("tool position error, lateral (raw) [mm]", 0.09, 0.06, lat.mean);
  row("tool position error, longitudinal (raw) [mm]", 0.42, 0.32, lon.mean);
  row("tool rotation error (raw) [deg]", 0.80, 0.39, rot.mean);

  nlohmann::ordered_json per_hold = nlohmann::ordered_json::array();
  for (std::size_t h = 0; h < holds.size(); ++h) {
    per_hold.push_back({{"position", holds[h].position},
                        {"moved", holds[h].moved},
                        {"depth_mm", depths[h].depth_mm},
                        {"marker_depth_sd_mm", SttarSds(depths[h].pixel_z_mm)},
                        {"marker_centre_depth_sd_mm", SttarSds(depths[h].centre_z_mm)}});
  }
  result.details["markers"] = {
      {"positions", protocol.positions},
      {"frames_per_hold", protocol.frames_per_hold},
      {"frames", source.frames},
      {"depth_sd_near",
       {{"to_mm", near_to_mm}, {"markers", near_markers}, {"tofnav_centre_mm", near_centre_sd}}},
      {"depth_sd_far",
       {{"from_mm", far_from_mm}, {"markers", far_markers}, {"tofnav_centre_mm", far_centre_sd}}},
      {"move_settle_frames", kSttarSettleFrames},
      {"move_error_raw_mm", SttarSummaryJson(move_raw)},
      {"move_error_filtered_mm", SttarSummaryJson(move_filtered)},
      {"lateral_error_raw_mm", SttarSummaryJson(lat)},
      {"longitudinal_error_raw_mm", SttarSummaryJson(lon)},
      {"rotation_error_raw_deg", SttarSummaryJson(rot)},
      {"holds", per_hold}};
}

}  // namespace tofnav
