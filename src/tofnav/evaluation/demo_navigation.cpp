// SPDX-License-Identifier: BSD-3-Clause
// tofnav demo, stages registration, tracking and guidance: the CT skin (skin) registered to the
// reconstruction (register) against the true registration, the tools tracked with f_rf (track +
// evaluate tracking), and the plan navigated (navigate + evaluate guidance) over the session.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/casefile/transform_io.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/evaluation/demo_stages.hpp"
#include "tofnav/evaluation/guidance_evaluate.hpp"
#include "tofnav/evaluation/tracking_truth.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/pipeline/marker_tasks.hpp"
#include "tofnav/pipeline/navigator.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/registration/register_surface.hpp"
#include "tofnav/scenario/truth_json.hpp"

namespace tofnav {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

double AngleDeg(const Rigid3d& a, const Rigid3d& b) {
  return Eigen::AngleAxisd(a.rotation.inverse() * b.rotation).angle() * kDegPerRad;
}

// The instrument as the navigator showed it in one frame: its measured pose, for the truth check.
ToolPoseRecord InstrumentRecord(std::size_t index, const AhatFrame& frame,
                                const NavigationState& s) {
  ToolPoseRecord r;
  r.frame = static_cast<std::int64_t>(index);
  r.host_ticks = frame.host_ticks;
  r.time_s = frame.timestamp_s();
  r.tool = "instrument";
  r.status = s.instrument_status.value_or(ToolStatus::kOutOfView);
  r.ahat_from_tool = s.ahat_from_instrument;
  return r;
}

// What the surgeon saw of the instrument against the truth: the frames it was shown in, those
// whose pose belongs to something else (a wrong identity: another tool's markers), and the tip's
// distance from its true place over the right ones.
DemoJson InstrumentFigures(std::span<const ToolPoseRecord> records, const ToolGeometry& instrument,
                           const std::filesystem::path& truth) {
  const std::vector<ToolTruthEvaluation> e = EvaluateTrackingAgainstTruth(records, truth);
  Require(e.size() == 1, "instrument: no frames to evaluate");
  const TrackingEvaluationOptions wrong;  // the limits of a wrong identity
  std::vector<double> tip_mm;
  for (const ToolEvaluationFrame& f : e[0].frames) {
    if (!f.raw || wrong.IsWrongIdentity(*f.raw, f.true_ahat_from_tool)) continue;
    const Eigen::Vector3d& tip = *instrument.tip_in_tool;
    tip_mm.push_back((*f.raw * tip - f.true_ahat_from_tool * tip).norm());
  }
  const Summary t = Summarise(tip_mm);
  return {{"shown_frames", e[0].evaluation.posed_frames},
          {"fully_visible_frames", e[0].evaluation.fully_visible_frames},
          {"wrong_identities", e[0].evaluation.wrong_identities},
          {"tip_error_median_mm", tip_mm.empty() ? DemoJson() : DemoJson(t.median)},
          {"tip_error_max_mm", tip_mm.empty() ? DemoJson() : DemoJson(t.max)}};
}

}  // namespace

void RunDemoRegistration(DemoContext& ctx, DemoJson& stage) {
  Require(ctx.surface.has_value(), "no reconstructed surface (stage reconstruction failed)");
  const TriangleMesh& skin = DemoSkin(ctx);
  WriteMesh(ctx.out / "skin.ply", skin);
  const std::vector<Trajectory> plan = ReadTrajectories(ctx.session_dir / "plan.mrk.json");
  std::vector<Eigen::Vector3d> targets;
  for (const Trajectory& t : plan) targets.push_back(t.target_lps_mm);
  const PointCloud surface{ctx.surface->vertices, ctx.surface->vertex_normals, {}, {}};
  RegisterSurfaceOptions options;
  std::optional<Rigid3d> guess;  // tofnav: none (its coarse search); the paper: a hand placement
  if (ctx.method == Method::kPaper) {
    UsePaperRegistration(options);
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the skin's centroid, in `image`
    for (const Eigen::Vector3d& v : skin.vertices) centre += v;
    centre /= static_cast<double>(std::max<std::size_t>(1, skin.vertices.size()));
    guess = HandPlacedStart(ctx.true_tool_from_image, centre, ctx.seed);
  }
  const RegisterSurfaceResult r =
      RegisterSurface(surface, SurfaceIndex(skin), targets, options, guess);
  const RegistrationQuality& q = r.quality;
  WriteTransform(ctx.out / "tool_from_image.json", {"tool",
                                                    "image",
                                                    r.tool_from_image,
                                                    {{"rmse_mm", q.rmse_mm},
                                                     {"inlier_fraction", q.inlier_fraction},
                                                     {"accepted", q.accepted() ? 1.0 : 0.0}}});
  WriteMesh(ctx.out / "surface_in_image.ply", Transform(r.tool_from_image.Inverse(), *ctx.surface));
  ctx.tool_from_image = r.tool_from_image;  // handed on even when refused (flagged below)

  const Rigid3d& truth = ctx.true_tool_from_image;
  double tre_sum = 0.0, tre_max = 0.0;
  DemoJson per_target = DemoJson::array();
  for (const Trajectory& t : plan) {
    const double tre = (r.tool_from_image * t.target_lps_mm - truth * t.target_lps_mm).norm();
    tre_sum += tre;
    tre_max = std::max(tre_max, tre);
    per_target.push_back({{"name", t.name}, {"tre_mm", tre}});
  }
  const Rigid3d error_in_image = truth.Inverse() * r.tool_from_image;
  if (guess) {  // how far the hand placement was from the truth at the targets (mean)
    double start_sum = 0.0;
    for (const Trajectory& t : plan)
      start_sum += (*guess * t.target_lps_mm - truth * t.target_lps_mm).norm();
    stage["start_tre_mm"] = plan.empty() ? 0.0 : start_sum / static_cast<double>(plan.size());
  }
  const double tre_mm = plan.empty() ? 0.0 : tre_sum / static_cast<double>(plan.size());
  stage["accepted"] = q.accepted();
  stage["status"] = ToString(q.status);
  stage["message"] = q.message;
  stage["rmse_mm"] = q.rmse_mm;
  stage["inlier_fraction"] = q.inlier_fraction;
  stage["ambiguity"] = q.ambiguity;
  stage["ambiguity_shift_mm"] = q.ambiguity_shift_mm;
  stage["effective_samples"] = q.effective_samples;
  stage["max_predicted_tre_mm"] = q.max_predicted_tre_mm;
  stage["icp_iterations"] = r.icp.iterations;
  stage["icp_unsettled_mm"] = q.unsettled_mm;
  stage["tre_mm"] = tre_mm;
  stage["tre_max_mm"] = tre_max;
  stage["targets"] = per_target;
  stage["rotation_error_deg"] = AngleDeg(r.tool_from_image, truth);
  stage["translation_error_mm"] = error_in_image.translation.norm();
  stage["skin_ply"] = "skin.ply";
  stage["surface_in_image_ply"] = "surface_in_image.ply";
  stage["transform_json"] = "tool_from_image.json";
  stage["acceptance"] = DemoJson::array({Acceptance("tre_mm", tre_mm, "<=", 1.0)});  // issue 7
  if (!q.accepted()) {
    throw std::runtime_error("registration refused (" + std::string(ToString(q.status)) +
                             "): " + q.message);
  }
}

std::vector<ToolGeometry> SessionTrackedTools(const DemoContext& ctx) {
  Require(ctx.session.has_value(), "no simulated session");
  const std::vector<int> headframe = HeadframeTools(*ctx.session);
  const std::vector<int> on_patient = ctx.session->ToolsRigidWithPatient();
  std::vector<ToolGeometry> tools;
  for (std::size_t i = 0; i < ctx.session->scene.tools.size(); ++i) {
    const int t = static_cast<int>(i);
    const bool sticker = std::find(on_patient.begin(), on_patient.end(), t) != on_patient.end() &&
                         std::find(headframe.begin(), headframe.end(), t) == headframe.end();
    const std::filesystem::path file =
        ctx.session_dir / "tools" / (ctx.session->scene.tools[i].name + ".json");
    if (!sticker && std::filesystem::exists(file)) tools.push_back(ReadToolJson(file));
  }
  return tools;
}

void RunDemoTracking(DemoContext& ctx, DemoJson& stage) {
  Require(ctx.session.has_value(), "no patient session (its simulation failed)");
  const MarkerSource source = OpenSimulatedMarkerSource(ctx.session_dir);
  const MarkerDetectionOptions detection;
  const std::vector<ToolGeometry> tools = SessionTrackedTools(ctx);
  Require(!tools.empty(), "the session wrote no tool file");
  ToolTrackerOptions tracker;
  if (ctx.method == Method::kPaper) UsePaperTracking(tracker);  // no pose filter
  const std::vector<ToolPoseRecord> records =
      TrackTools(source, detection, tools, tracker, ctx.frf.value_or(MarkerRangeModel{}),
                 [&](std::size_t d, std::size_t t) { ctx.progress("track", d, t); });
  WriteToolPoses(ctx.out / "poses.csv", records);
  const std::vector<ToolTruthEvaluation> evaluations =
      EvaluateTrackingAgainstTruth(records, ctx.session_dir / "truth.json");
  std::ostringstream csv;
  csv << "t_s,tool,position_error_mm,rotation_error_deg,filtered_position_error_mm,"
         "filtered_rotation_error_deg\n";
  stage["tools"] = DemoJson::array();
  stage["acceptance"] = DemoJson::array();
  for (const ToolTruthEvaluation& t : evaluations) {
    const ToolEvaluation& e = t.evaluation;
    // The tracker's output pose: the filtered one, or the raw one where there is no filter.
    const PoseErrorStats& output =
        ctx.method == Method::kPaper ? e.raw_fully_visible : e.filtered_fully_visible;
    for (std::size_t i = 0; i < t.frames.size(); ++i) {
      const ToolEvaluationFrame& f = t.frames[i];
      if (!f.raw) continue;
      csv << t.times_s[i] << ',' << t.name << ','
          << (f.raw->translation - f.true_ahat_from_tool.translation).norm() << ','
          << AngleDeg(*f.raw, f.true_ahat_from_tool) << ',';
      if (f.filtered) {  // empty where the filter gated the frame (or there is no filter)
        csv << (f.filtered->translation - f.true_ahat_from_tool.translation).norm() << ','
            << AngleDeg(*f.filtered, f.true_ahat_from_tool);
      } else {
        csv << ',';
      }
      csv << '\n';
    }
    stage["tools"].push_back({{"name", t.name},
                              {"frames", e.frames},
                              {"posed_frames", e.posed_frames},
                              {"tracked_percent", 100.0 * e.tracked_fraction},
                              {"position_rms_mm", e.raw.position_mm.rms},
                              {"rotation_rms_deg", e.raw.rotation_deg.rms},
                              {"filtered_position_rms_mm", output.position_mm.rms},
                              {"filtered_rotation_rms_deg", output.rotation_deg.rms},
                              // How far another run would put them (docs/statistics.md).
                              {"filtered_position_rms_se_mm", output.position_rms_se_mm},
                              {"filtered_rotation_rms_se_deg", output.rotation_rms_se_deg},
                              {"wrong_identities", e.wrong_identities}});
    if (ctx.method != Method::kPaper) {  // beside the lines: the poses navigation shows settled
      stage["tools"].back()["settled_rotation_rms_deg"] =
          e.filtered_settled_fully_visible.rotation_deg.rms;
      stage["tools"].back()["settling_frames"] = e.settling_frames;
    }
    if (!t.name.starts_with("reference")) continue;  // issue 4's lines are the reference tools'
    // Issue 4's lines on the tracker's output pose: the filtered one (orientation filtered in the
    // world frame, position with a camera-motion-adaptive filter, when the rig pose is known).
    // The raw figures stay in the table beside them.
    stage["acceptance"].push_back(
        Acceptance(t.name + " filtered position_rms_mm", output.position_mm.rms, "<=", 0.25));
    stage["acceptance"].push_back(
        Acceptance(t.name + " filtered rotation_rms_deg", output.rotation_deg.rms, "<=", 0.25));
    stage["acceptance"].push_back(
        Acceptance(t.name + " tracked_percent", 100.0 * e.tracked_fraction, ">=", 99.0));
    stage["acceptance"].push_back(
        Acceptance(t.name + " wrong_identities", e.wrong_identities, "<=", 0.0));
  }
  WriteFileAtomically(ctx.out / "tracking_error.csv", csv.str());
  stage["poses_csv"] = "poses.csv";
  stage["error_csv"] = "tracking_error.csv";
}

void RunDemoGuidance(DemoContext& ctx, DemoJson& stage) {
  Require(ctx.tool_from_image.has_value(), "no registration (stage registration failed)");
  NavigationCase c;
  c.reference = ReadToolJson(ctx.session_dir / "tools" / "headframe.json");
  c.tool_from_image = *ctx.tool_from_image;
  c.plan = ReadTrajectories(ctx.session_dir / "plan.mrk.json");
  if (ctx.frf) c.marker_range = *ctx.frf;
  // The instrument tracked beside the headframe, as the surgeon navigates it (their markers are
  // matched together: the instrument can take the headframe's blobs, docs/tracking.md 9.4).
  const std::filesystem::path instrument_file = ctx.session_dir / "tools" / "instrument.json";
  if (std::filesystem::exists(instrument_file)) {
    ToolGeometry instrument = ReadToolJson(instrument_file);
    if (instrument.tip_in_tool) c.instrument = std::move(instrument);
  }
  const std::unique_ptr<AhatRecording> recording =
      OpenAhatRecording(ctx.session_dir / "rm_depth_ahat.bin");
  NavigatorOptions options;
  if (ctx.method == Method::kPaper) UsePaperTracking(options);
  Navigator navigator(AhatCamera(ReadHl2ssCalibration(ctx.session_dir / "calibration")), c,
                      options);
  std::string csv = NavigationCsvHeader();
  std::vector<PlacedFrame> placed;
  std::vector<ToolPoseRecord> instrument;
  const std::size_t frames = recording->frame_count();
  for (std::size_t i = 0; i < frames; ++i) {
    const AhatFrame frame = recording->ReadFrame(i);
    const NavigationState s = navigator.Process(frame);
    csv += NavigationCsvRow(s, c.plan);
    if (s.world_from_image) placed.push_back({s.timestamp_s, *s.world_from_image});
    if (c.instrument) instrument.push_back(InstrumentRecord(i, frame, s));
    ctx.progress("navigate", i + 1, frames);
  }
  WriteFileAtomically(ctx.out / "navigation.csv", csv);
  Require(!placed.empty(), "no frame placed the plan (headframe never tracked)");
  const GuidanceEvaluation g =
      EvaluateGuidanceAgainstTruth(placed, ctx.session_dir / "truth.json", c.plan);
  stage["frames"] = frames;
  stage["placed_frames"] = g.frames;
  stage["trajectories"] = DemoJson::array();
  for (const TrajectoryGuidanceError& t : g.trajectories) {
    stage["trajectories"].push_back({{"name", t.name},
                                     {"entry_error_mm", t.entry_mm.median},
                                     {"angle_error_deg", t.direction_deg.median}});
  }
  stage["entry_median_mm"] = g.entry_mm.median;
  stage["entry_p95_mm"] = g.entry_mm.p95;
  stage["angle_median_deg"] = g.direction_deg.median;
  stage["angle_p95_deg"] = g.direction_deg.p95;
  stage["entry_world_median_mm"] = g.entry_world_mm.median;
  if (c.instrument) {  // a truth that cannot judge the instrument loses its figures, not the plan's
    try {
      stage["instrument"] =
          InstrumentFigures(instrument, *c.instrument, ctx.session_dir / "truth.json");
    } catch (const std::exception& e) {
      stage["instrument"] = {{"error", e.what()}};
    }
  }
  stage["navigation_csv"] = "navigation.csv";
  stage["acceptance"] = DemoJson::array(  // issue 8
      {Acceptance("entry_median_mm", g.entry_mm.median, "<=", 1.0),
       Acceptance("angle_median_deg", g.direction_deg.median, "<=", 1.0)});
}

}  // namespace tofnav
