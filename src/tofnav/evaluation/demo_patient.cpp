// SPDX-License-Identifier: BSD-3-Clause
// tofnav demo, stages session, depth and reconstruction: the evd-usecase session simulated
// (simulate), the patient-specific model identified with the CT (identify --ct) and evaluated
// against the truth range (evaluate depth), the head fused in the headframe's frame
// (reconstruct) and compared with the true skin (evaluate reconstruction).
#include <algorithm>
#include <cmath>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/evaluation/demo_stages.hpp"
#include "tofnav/evaluation/depth_evaluate.hpp"
#include "tofnav/evaluation/reconstruct_evaluate.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/pipeline/identify.hpp"
#include "tofnav/pipeline/identify_consensus.hpp"
#include "tofnav/pipeline/reconstruct_correction.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_format.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/scenario/simulate.hpp"
#include "tofnav/scenario/truth_json.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav {
namespace {

constexpr int kHistogramBins = 40;

// Equal bins over [lo, hi] of each series (values outside are clamped into the end bins).
DemoJson Histogram(const std::vector<std::vector<float>>& series, double lo, double hi,
                   const std::vector<std::string>& names) {
  DemoJson h{{"bin_edges_mm", DemoJson::array()}};
  const double width = (hi - lo) / kHistogramBins;
  for (int b = 0; b <= kHistogramBins; ++b) h["bin_edges_mm"].push_back(lo + b * width);
  for (std::size_t s = 0; s < series.size(); ++s) {
    std::vector<int> counts(kHistogramBins, 0);
    for (const float v : series[s]) {
      if (!std::isfinite(v)) continue;
      const int b = static_cast<int>(std::floor((v - lo) / width));
      ++counts[static_cast<std::size_t>(std::clamp(b, 0, kHistogramBins - 1))];
    }
    h[names[s]] = counts;
  }
  return h;
}

struct SessionFiles {
  AhatCamera camera;
  std::unique_ptr<AhatRecording> recording;
};

SessionFiles OpenSession(const DemoContext& ctx) {
  Require(ctx.session.has_value(), "no patient session (its simulation failed)");
  return {AhatCamera(ReadHl2ssCalibration(ctx.session_dir / "calibration")),
          OpenAhatRecording(ctx.session_dir / "rm_depth_ahat.bin")};
}

const std::string& PatientObjectName(const sim::Scenario& s) {
  return s.scene.objects[static_cast<std::size_t>(s.patient->object)].name;
}

std::int64_t ToolMarkersLeftOut(const IdentifyRecordingResult& r) {
  std::int64_t n = 0;
  for (const auto& [name, count] : r.tool_marker_observations_left_out) n += count;
  return n;
}

}  // namespace

void RunDemoSession(DemoContext& ctx, DemoJson& stage) {
  sim::Scenario scenario =
      sim::BuiltinScenario("evd-usecase", ctx.patient_head ? &*ctx.patient_head : nullptr);
  scenario.timing.slot_stride = ctx.session_slot_stride;
  if (ctx.vary_session) ctx.vary_session(scenario);
  const std::vector<int> parts = HeadframeTools(scenario);
  Require(!parts.empty() && scenario.patient.has_value(), "evd-usecase has no headframe");
  const sim::Tool& first = scenario.scene.tools[static_cast<std::size_t>(parts.front())];
  ctx.truth_tool = first.name;
  ctx.true_tool_from_image =
      first.scene_from_tool.Inverse() *
      scenario.scene.objects[static_cast<std::size_t>(scenario.patient->object)].scene_from_object;
  ctx.session_dir = ctx.out / "session";
  SimulateOptions options;
  options.frames = ctx.session_frames;
  options.seed = ctx.seed;
  options.truth_depth = true;
  options.profile = ctx.stream_profile;
  options.bitrate_bps = ctx.bitrate_bps;
  options.progress = [&](std::size_t d, std::size_t t) { ctx.progress("simulate session", d, t); };
  const SimulateResult r = RunSimulation(scenario, ctx.session_dir, options);
  scenario.frames = r.frames;
  ctx.session = std::move(scenario);
  stage["scenario"] = "evd-usecase";
  stage["frames"] = r.frames;
  stage["dropped_slots"] = r.dropped_slots;
  stage["recording_duration_s"] = r.duration_s;
  {
    const Hl2ssRecording recorded(ctx.session_dir / "rm_depth_ahat.bin");
    stage["stream_profile"] = Hl2ssProfileName(recorded.config());
    // At the headset's 45 Hz (the session renders every n-th slot): bytes per frame x 45.
    stage["stream_mbit_s"] = recorded.payload_bytes_per_frame() * 8.0 * 45.0 * 1e-6;
  }
  stage["recording"] = "session/rm_depth_ahat.bin";
  stage["truth"] = "session/truth.json";
  stage["ct"] = "session/ct.nrrd";
  stage["plan"] = "session/plan.mrk.json";
  stage["headframe_tool"] = "session/tools/headframe.json";
}

namespace {

// The head's median depth error after correcting with `model`, against the truth.
double HeadAfterMedianMm(const DemoContext& ctx, const AhatRecording& recording,
                         const AhatCamera& camera, const DepthModelFile& model) {
  const DepthEvaluation e = EvaluateDepthAgainstTruth(
      recording, camera, ctx.session_dir, *ctx.session, model, ctx.depth_eval_frames, nullptr);
  for (const ObjectDepthError& o : e.objects) {
    if (o.name == PatientObjectName(*ctx.session)) return o.after_mm->median;
  }
  throw std::runtime_error("no head pixel was evaluated");
}

// The runs without a tenth of the frames each (issue 40 item 2: C1 by at most 0.1 mm): how far
// each coefficient moves from the full run's, and how far the head's corrected depth moves with
// them (C1, C3 and C4 trade off: docs/correction.md 2.4). With the consensus, also how far the
// medoid and the mean move when one of its runs is left out (pipeline/identify_consensus.hpp).
// The stage kept run `used`'s model, or with `mean` the runs' ConsensusMean; `used_head_mm` is the
// head median of the one kept.
DemoJson IdentificationStability(const DemoContext& ctx, const AhatRecording& recording,
                                 const AhatCamera& camera, const IdentifyConsensusResult& runs,
                                 std::size_t used, bool mean, double used_head_mm) {
  constexpr double kC1LimitMm = 0.1;  // issue 40 item 2
  const std::vector<DepthErrorModel> models = runs.Models();
  std::vector<double> head_mm(models.size());
  for (std::size_t i = 0; i < models.size(); ++i) {
    head_mm[i] = i == used && !mean ? used_head_mm
                                    : HeadAfterMedianMm(ctx, recording, camera, runs.Run(i).file);
  }
  const DepthErrorModel& full = models.front();
  DemoJson list = DemoJson::array();
  double max_c1_mm = 0.0, max_head_mm = 0.0;
  for (std::size_t k = 0; k < runs.subsets.size(); ++k) {
    // Each run centres its references on its own samples: C1 compared at the full run's.
    const DepthErrorModel m =
        models[k + 1].WithReferences(full.theta_reference_rad, full.ab_reference);
    const double head_change_mm = head_mm[k + 1] - head_mm[0];
    max_c1_mm = std::max(max_c1_mm, std::abs(m.c1_mm - full.c1_mm));
    // C1 at theta = 0 and AB = 130 counts, the uncentred form's (docs/correction.md 2.4).
    const double c1_origin_change_mm =
        m.WithReferences(0.0, 130.0).c1_mm - full.WithReferences(0.0, 130.0).c1_mm;
    max_head_mm = std::max(max_head_mm, std::abs(head_change_mm));
    list.push_back({{"left_out", "frame k with k % 10 == " + std::to_string(k)},
                    {"C1_mm", m.c1_mm},
                    {"C2", m.c2},
                    {"C3_mm_per_rad", m.c3_mm},
                    {"C4_mm", m.c4_mm},
                    {"cyclic_error", CyclicErrorToJson(m.cyclic)},
                    {"C1_change_mm", m.c1_mm - full.c1_mm},
                    {"final_cost_mm2", models[k + 1].report.final_cost},
                    {"frames_used", models[k + 1].report.frames_used},
                    {"C1_at_theta0_ab130_change_mm", c1_origin_change_mm},
                    {"head_after_median_change_mm", head_change_mm}});
  }
  DemoJson out{{"runs", list},
               {"max_C1_change_mm", max_c1_mm},
               {"max_head_after_median_change_mm", max_head_mm},
               {"acceptance",
                DemoJson::array({Acceptance("max_C1_change_mm", max_c1_mm, "<=", kC1LimitMm)})}};
  if (ctx.consensus) {
    const ConsensusJackknife jack = JackknifeMedoid(models);
    double max_consensus_head_mm = 0.0;
    for (const std::size_t k : jack.kept_without_run) {
      max_consensus_head_mm =
          std::max(max_consensus_head_mm, std::abs(head_mm[k] - head_mm[runs.kept]));
    }
    out["consensus"] = {{"kept", runs.kept == 0 ? std::string("the full run")
                                                : "without frame k with k % 10 == " +
                                                      std::to_string(runs.kept - 1)},
                        {"kept_run", runs.kept},
                        {"identified_again", runs.identified_again},
                        {"restarted_from_least_cost", runs.restarted},
                        {"restart_kept", runs.restart_kept},
                        {"max_C1_change_mm", jack.max_c1_change_mm},
                        {"max_head_after_median_change_mm", max_consensus_head_mm}};
    // The mean's own jackknife: its head median with every run and without each subset run,
    // each model in the medoid's file (its f_rf and report), as the stage would keep it.
    const auto head_with = [&](const DepthErrorModel& model) {
      DepthModelFile f = runs.Run(runs.kept).file;
      f.model = model;
      return HeadAfterMedianMm(ctx, recording, camera, f);
    };
    const DepthErrorModel all = ConsensusMean(models);
    const double all_head_mm = mean ? used_head_mm : head_with(all);
    const ConsensusMeanJackknife mean_jack = JackknifeMean(models);
    double max_mean_head_mm = 0.0;
    for (const DepthErrorModel& without : mean_jack.without_run) {
      max_mean_head_mm = std::max(max_mean_head_mm, std::abs(head_with(without) - all_head_mm));
    }
    out["consensus"]["mean"] = {{"kept", mean},
                                {"C1_mm", all.c1_mm},
                                {"C2", all.c2},
                                {"C3_mm_per_rad", all.c3_mm},
                                {"C4_mm", all.c4_mm},
                                {"max_C1_change_mm", mean_jack.max_c1_change_mm},
                                {"max_head_after_median_change_mm", max_mean_head_mm}};
  }
  return out;
}

}  // namespace

void RunDemoDepth(DemoContext& ctx, DemoJson& stage) {
  const SessionFiles s = OpenSession(ctx);
  const SurfaceIndex skin(DemoSkin(ctx));
  IdentifyRecordingOptions options;  // the automatic head region leaves the headframe out
  options.max_frames = static_cast<int>(ctx.session_frames);
  // Tracked tools' markers are left out before the sticker tests (docs/correction.md 2).
  if (ctx.session) options.exclude_tools = SessionTrackedTools(ctx);
  // Err_C places the skin once through the headframe, as reconstruct fuses (docs/correction.md 2).
  const std::filesystem::path headframe = ctx.session_dir / "tools" / "headframe.json";
  if (std::filesystem::exists(headframe)) options.reference_tool = ReadToolJson(headframe);
  // The device's illuminator constant K is what a user calibrates once per headset; the
  // simulator's multipath gain g scales the indirect light, which the removal sees as a device
  // of constant K / g (none at g = 0: a world without indirect light). docs/correction.md 7.
  if (ctx.session) {
    const double gain = ctx.session->render.multipath.gain;
    options.sampling.multipath.enabled = gain > 0.0;
    if (gain > 0.0)
      options.sampling.multipath.ab_scale = ctx.session->render.radiometry.ab_scale / gain;
    options.sampling.multipath.falloff_power = ctx.session->render.radiometry.falloff_power;
    // The sensor's cyclic error is fitted with the coefficients at the device's period, L / N
    // with N its phase steps: a property of the device, as K is (docs/correction.md 2.2).
    options.identification.fit_cyclic_period_mm = ctx.session->render.sensor.wiggle_period_mm;
  }
  if (ctx.stage_cyclic) {  // measured on the stage's plate (docs/correction.md 2.8): held
    options.identification.fit_cyclic_period_mm = 0.0;
    options.start.cyclic = *ctx.stage_cyclic;
  }
  if (ctx.method == Method::kPaper) UsePaperIdentification(options);
  Require(!ctx.consensus || ctx.stability_subsets >= 2,
          "the consensus needs at least 2 runs without a tenth of the frames (--stability)");
  const IdentifyConsensusResult runs = IdentifyWithConsensus(
      *s.recording, s.camera, ctx.frf, &skin, options, ctx.stability_subsets,
      [&](int run, int, std::size_t d, std::size_t t) {
        ctx.progress(run == 0 ? "identify" : "identify without a tenth", d, t);
      });
  const std::size_t used = ctx.consensus ? runs.kept : 0;
  const IdentifyRecordingResult& identified = runs.Run(used);
  // The medoid's file with the runs' mean coefficients when asked (docs/correction.md 2.16).
  const bool mean = ctx.consensus && ctx.consensus_mean;
  DepthModelFile file = identified.file;
  if (mean) file.model = ConsensusMean(runs.Models());
  WriteDepthModelJson(ctx.out / "depth_model.json", file);
  ctx.depth_model = file;
  const DepthErrorModel& m = file.model;
  stage["model"] = {
      {"name", m.Name()},
      {"C1_mm", m.c1_mm},
      {"C2", m.c2},
      {"C3_mm_per_rad", m.c3_mm},
      {"C4_mm", m.c4_mm},
      {"cyclic_error", CyclicErrorToJson(m.cyclic)},
      {"costs", m.report.costs},
      {"final_cost_mm2", m.report.final_cost},
      {"multipath_removed", m.multipath.enabled},
      {"frames", m.report.frames_used},
      {"frames_left_out", m.report.frames_left_out},
      {"marker_observations", m.report.marker_observations},
      {"marker_observations_rejected", m.report.marker_observations_rejected},
      {"marker_observations_curved", m.report.marker_observations_curved},
      {"tool_marker_observations_left_out", ToolMarkersLeftOut(identified)},
      {"frames_with_reference_tool", identified.frames_with_reference_tool},
      {"frames_reference_rotation_smoothed", identified.frames_reference_rotation_smoothed},
      {"seconds", m.report.seconds}};
  if (ctx.consensus) {
    stage["model"]["consensus_of_runs"] = runs.subsets.size() + 1;
    stage["model"]["consensus"] = mean ? "mean" : "medoid";
  }
  stage["depth_model_json"] = "depth_model.json";

  const DepthEvaluation e = EvaluateDepthAgainstTruth(
      *s.recording, s.camera, ctx.session_dir, *ctx.session, file, ctx.depth_eval_frames,
      [&](std::size_t d, std::size_t t) { ctx.progress("evaluate depth", d, t); });
  stage["frames"] = e.frames;
  stage["objects"] = DemoJson::array();
  const std::string& head = PatientObjectName(*ctx.session);
  const ObjectDepthError* head_error = nullptr;
  for (const ObjectDepthError& o : e.objects) {
    if (o.name == head) head_error = &o;
    stage["objects"].push_back({{"name", o.name},
                                {"pixels", o.before_mm.count},
                                {"before_median_mm", o.before_mm.median},
                                {"before_iqr_mm", o.before_mm.iqr()},
                                {"after_median_mm", o.after_mm->median},
                                {"after_iqr_mm", o.after_mm->iqr()},
                                {"reduction_percent", o.reduction_percent},
                                {"head_region_percent", o.head_region_percent},
                                {"target", o.name == head}});
    if (o.name == head) {
      stage["objects"].back()["by_incidence_deg"] = DepthErrorBinsJson(o.by_incidence_deg, "deg");
      stage["objects"].back()["by_range_mm"] = DepthErrorBinsJson(o.by_range_mm, "mm");
    }
  }
  Require(head_error != nullptr, "no head pixel was evaluated");
  if (ctx.stability_subsets > 0) {
    stage["stability"] = IdentificationStability(ctx, *s.recording, s.camera, runs, used, mean,
                                                 head_error->after_mm->median);
  }
  const double lo = std::floor(std::min(Quantile(head_error->before_errors_mm, 0.005),
                                        Quantile(head_error->after_errors_mm, 0.005)));
  const double hi = std::ceil(std::max(Quantile(head_error->before_errors_mm, 0.995),
                                       Quantile(head_error->after_errors_mm, 0.995)));
  stage["histogram"] = Histogram({head_error->before_errors_mm, head_error->after_errors_mm}, lo,
                                 std::max(hi, lo + 1.0), {"before", "after"});
  stage["acceptance"] = DemoJson::array(  // issue 5 (head, with the CT)
      {Acceptance("head after_median_mm (abs)", std::abs(head_error->after_mm->median), "<=", 0.5),
       Acceptance("head reduction_percent", head_error->reduction_percent, ">=", 90.0)});
}

void RunDemoReconstruction(DemoContext& ctx, DemoJson& stage) {
  const SessionFiles s = OpenSession(ctx);
  const ToolGeometry tool = ReadToolJson(ctx.session_dir / "tools" / "headframe.json");
  ReconstructOptions options;
  // Before UseDepthModel, which hands the head region on to the range correction.
  if (ctx.method == Method::kPaper) UsePaperReconstruction(options);
  if (ctx.depth_model) {
    UseDepthModel(*ctx.depth_model, options);
  } else if (ctx.frf) {
    options.marker_error = *ctx.frf;
    stage["note"] = "no depth model (stage depth failed): uncorrected ranges";
  }
  const ReconstructResult r =
      ReconstructSurface(*s.recording, s.camera, tool, options,
                         [&](std::size_t d, std::size_t t) { ctx.progress("reconstruct", d, t); });
  WriteMesh(ctx.out / "surface.ply", r.mesh);
  ctx.surface = r.mesh;

  // The true surfaces rigid with the headframe, in its frame (that of ctx.truth_tool).
  const sim::Scenario& scenario = *ctx.session;
  const auto patient = static_cast<std::size_t>(scenario.patient->object);
  const int mount = scenario.object_mounts[patient];
  const sim::Tool* first = nullptr;
  for (const sim::Tool& t : scenario.scene.tools) {
    if (t.name == ctx.truth_tool) first = &t;
  }
  Require(first != nullptr, "the headframe's first tool is not in the scenario");
  std::vector<TruthSurface> truth;
  for (std::size_t o = 0; o < scenario.scene.objects.size(); ++o) {
    if (scenario.object_mounts[o] != mount) continue;
    const sim::SceneObject& object = scenario.scene.objects[o];
    truth.push_back(
        {object.name, scenario.scene.materials[static_cast<std::size_t>(object.material)].name,
         o == patient,
         Transform(first->scene_from_tool.Inverse() * object.scene_from_object, object.mesh)});
  }
  const ReconstructionEvaluation e = EvaluateReconstruction(r.mesh, truth);
  WriteMesh(ctx.out / "surface_error.ply", e.colored);
  const ObjectError* head = nullptr;
  for (const ObjectError& o : e.objects) {
    if (o.name == PatientObjectName(scenario)) head = &o;
  }
  Require(head != nullptr, "no reconstructed vertex lies on the head");
  stage["frames_fused"] = r.frames_fused;
  stage["frames_skipped"] = r.frames_skipped;
  stage["voxel_mm"] = options.tsdf.voxel_size_mm;
  stage["roi_automatic"] = r.roi_automatic;
  stage["vertices"] = r.mesh.vertices.size();
  stage["head_vertices"] = head->stats.abs_mm.count;
  stage["outliers"] = e.outliers;
  stage["median_mm"] = head->stats.abs_mm.median;
  stage["iqr_mm"] = head->stats.abs_mm.iqr();
  stage["p95_mm"] = head->stats.abs_mm.p95;
  stage["beyond_3mm_percent"] = 100.0 * head->stats.beyond_3mm_fraction;
  stage["all_median_mm"] = e.all.abs_mm.median;
  stage["objects"] = DemoJson::array();
  for (const ObjectError& o : e.objects) {
    stage["objects"].push_back({{"name", o.name},
                                {"vertices", o.stats.abs_mm.count},
                                {"median_mm", o.stats.abs_mm.median},
                                {"iqr_mm", o.stats.abs_mm.iqr()}});
  }
  std::vector<float> abs_error;
  for (const float v : e.colored.vertex_scalars) {
    if (std::isfinite(v)) abs_error.push_back(std::abs(v));
  }
  DemoJson histogram = Histogram({abs_error}, 0.0, 3.0, {"counts"});
  stage["histogram"] = histogram;
  stage["surface_ply"] = "surface.ply";
  stage["mesh_error_ply"] = "surface_error.ply";
  stage["acceptance"] = DemoJson::array(
      {Acceptance("head median_mm", head->stats.abs_mm.median, "<=", 0.3)});  // issue 6
}

}  // namespace tofnav
