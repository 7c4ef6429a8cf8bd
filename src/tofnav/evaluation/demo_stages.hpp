// SPDX-License-Identifier: BSD-3-Clause
// tofnav demo: the state shared by its stages and one function per stage (docs/demo.md).
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/pipeline/marker_frames.hpp"
#include "tofnav/pipeline/paper_method.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"
#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

using DemoJson = nlohmann::ordered_json;

/// What the stages hand on to each other; every path is under `out`.
struct DemoContext {
  std::filesystem::path out;
  std::string head;  // "phantom" or "ct:<volume>"
  std::uint64_t seed = 1;
  bool quiet = false;
  std::int64_t stage_frames = 400;  // marker-stage recording (four runs)
  /// Non-empty: the stage is one calibration shared by several cases (the suite's, per device:
  /// docs/suite.md), recorded once under this folder with `shared_stage_seed` and read from it
  /// by every later case; empty: each case records its own under `out` with `seed`.
  std::filesystem::path shared_stage;
  std::uint64_t shared_stage_seed = 1;
  std::int64_t session_frames = 300;     // patient session (identification, reconstruction, nav)
  std::int64_t session_slot_stride = 1;  // every n-th slot of the session's motion is rendered
  int depth_eval_frames = 24;            // frames of the depth evaluation (ray cast truth labels)
  /// > 0: the depth stage identifies again this many times, each time without another tenth of
  /// its frames (FrameLeaveOut subset k of 10), and reports how far C1 moves (issue 40 item 2).
  int stability_subsets = 0;
  /// With stability_subsets >= 2: the model kept is the medoid of the full run and those runs
  /// (pipeline/identify_consensus.hpp), not the full run's; its own stability is reported too.
  bool consensus = false;
  /// With consensus: the model kept is the runs' ConsensusMean (docs/correction.md 2.16); false
  /// keeps their medoid (`--consensus-medoid`). Either way both are reported, each with its own
  /// stability.
  bool consensus_mean = true;
  /// The method of the stages after the session: tofnav's, or the paper's as published
  /// (pipeline/paper_method.hpp; its registration starts from a seeded hand placement).
  Method method = Method::kTofnav;
  /// The stages to run (DemoStagesWithPrerequisites); empty: every stage.
  std::set<std::string> stages;
  std::function<void(const std::string&, std::size_t, std::size_t)> progress;
  /// The hl2ss profile every simulated recording is written in (the stream the pipeline reads):
  /// SAME+RAW by default; H.264/H.265 at `bitrate_bps` (unset: the hl2ss client's default).
  Hl2ssStreamProfile stream_profile{Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kRaw};
  std::optional<std::uint32_t> bitrate_bps;
  /// Applied to the built-in scenarios before they are simulated (the robustness suite's
  /// variations: docs/suite.md); unset, the demo's own scenarios.
  std::function<void(sim::Scenario&)> vary_stage, vary_session;

  std::optional<sim::PatientHead> patient_head;
  std::optional<MarkerRangeModel> frf;             // stage marker_error
  std::optional<MarkerRangeModel> range_only_frf;  // ... of the range alone: the paper's Eq. (1)
  /// The sensor's cyclic error measured on the stage's plate (docs/correction.md 2.8), held by
  /// the depth stage; unset: the depth stage fits it on the patient.
  std::optional<CyclicRangeError> stage_cyclic;
  std::optional<sim::Scenario> session;       // the simulated patient session
  std::filesystem::path session_dir;          // its folder
  std::optional<DepthModelFile> depth_model;  // stage depth
  std::optional<TriangleMesh> surface;        // stage reconstruction, in the headframe frame
  /// The session CT's skin (`tofnav skin`'s defaults), extracted once for the depth and
  /// registration stages (DemoSkin); `skin_of` is the CT it was extracted from.
  std::optional<TriangleMesh> skin;
  std::filesystem::path skin_of;
  std::optional<Rigid3d> tool_from_image;  // stage registration
  Rigid3d true_tool_from_image;            // the headframe's truth (session)
  std::string truth_tool;  // the simulator's tool whose frame the headframe tool shares
};

/// The skin of the session's CT (ctx.session_dir / "ct.nrrd"), extracted on first use.
const TriangleMesh& DemoSkin(DemoContext& ctx);

/// One acceptance line: `value` against `limit` (`op` "<=" or ">=").
DemoJson Acceptance(const std::string& figure, double value, const std::string& op, double limit);

// Each stage fills `stage` with its figures and artefact paths (relative to ctx.out) and throws
// on failure; the driver records ok / error / elapsed_s.
/// The session's tracked tools (the headframe's and any instrument), read from the tool files
/// the session wrote; skin stickers are for identification, not a tool.
std::vector<ToolGeometry> SessionTrackedTools(const DemoContext& ctx);

/// Every frame of a simulated folder's recording (DIR/rm_depth_ahat.bin, DIR/calibration) as a
/// source of marker detections.
MarkerSource OpenSimulatedMarkerSource(const std::filesystem::path& dir);

/// The built-in marker-stage's four runs made to fit `frames` (the same travel, faster: the
/// simulator has no motion blur); returns the stage's commanded speed [mm/s].
double FitMarkerStageInto(sim::Scenario& s, std::int64_t frames);

void RunDemoMarkerError(DemoContext& ctx, DemoJson& stage);
void RunDemoSession(DemoContext& ctx, DemoJson& stage);
void RunDemoDepth(DemoContext& ctx, DemoJson& stage);
void RunDemoReconstruction(DemoContext& ctx, DemoJson& stage);
void RunDemoRegistration(DemoContext& ctx, DemoJson& stage);
void RunDemoTracking(DemoContext& ctx, DemoJson& stage);
void RunDemoGuidance(DemoContext& ctx, DemoJson& stage);

/// The stages' names in the order they run: marker_error, session, depth, reconstruction,
/// registration, tracking, guidance.
std::vector<std::string> DemoStageNames();
/// `wanted` and every stage they need (tracking: marker_error and session; depth: those too;
/// reconstruction: depth; registration: reconstruction; guidance: registration and tracking).
/// Throws std::invalid_argument naming an unknown stage and the known ones.
std::set<std::string> DemoStagesWithPrerequisites(std::span<const std::string> wanted);

/// The frame counts of a run at `scale` (1: the default, <= 90 s on the 2-core machine).
void ScaleDemoFrames(DemoContext& ctx, double scale);

/// Runs every stage in order, or those in ctx.stages (a failed stage is recorded and the next
/// ones run with what they have; a stage not asked for is left out of the result):
/// {"name": {"ok", "error", "elapsed_s", figures...}, ...}. The head is loaded first when
/// ctx.patient_head is unset.
DemoJson RunDemoStages(DemoContext& ctx, const std::function<void()>& after_stage = {});

/// The stages after the session again, on the same session, with the paper's method as
/// published: a copy of `ctx` (after RunDemoStages) with method kPaper writing under
/// ctx.out / "paper_method". The same object as RunDemoStages, for those stages.
DemoJson RunDemoPaperMethod(const DemoContext& ctx, const std::function<void()>& after_stage = {});

/// The paper's reference figures (demo.json "paper"), keys as the stages' where comparable.
DemoJson PaperFigures();
/// The tables: ours beside the paper's, one block per stage.
void PrintDemoTables(const DemoJson& demo);

}  // namespace tofnav
