// SPDX-License-Identifier: BSD-3-Clause
// tofnav fit-marker-error: f_rf (paper Eq. 1) from linear-stage recordings (Sec. III-A.1).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "config_json.hpp"
#include "marker_source.hpp"
#include "progress.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/pipeline/marker_tasks.hpp"
#include "tofnav/pipeline/stage_cyclic_error.hpp"
#include "tofnav/recording/open_recording.hpp"

namespace tofnav {

using OrderedJson = nlohmann::ordered_json;

namespace {

// The sensor's cyclic error from the plate of every recording's runs (runs numbered on across
// recordings, each its own offset), against the tape's plane through f_rf.
StageCyclicErrorInfo MeasureStageCyclicError(const std::vector<std::filesystem::path>& recordings,
                                             MarkerSourceArgs source_args,
                                             const ToolGeometry& structure,
                                             const MarkerRangeModel& frf,
                                             const PlateSampleOptions& plate, double period_mm,
                                             bool quiet) {
  std::vector<PlateRangeSample> samples;
  int runs = 0;
  for (const std::filesystem::path& recording : recordings) {
    source_args.recording = recording;
    const MarkerSource source = OpenMarkerSource(source_args);
    ProgressBar progress("plate " + recording.filename().string(), quiet);
    // Each frame's own pose (filter off): the plane of that frame's tape.
    const std::vector<ToolPoseRecord> poses = TrackTools(
        source, source_args.detection, {structure}, ToolTrackerOptions{.filter_enabled = false},
        frf, [&](std::size_t done, std::size_t total) { progress.Update(done, total); });
    std::vector<PlateRangeSample> more = CollectPlateSamples(source, poses, structure, plate);
    int last = -1;
    for (PlateRangeSample& s : more) {
      last = std::max(last, s.run);
      s.run += runs;
    }
    runs += last + 1;
    samples.insert(samples.end(), more.begin(), more.end());
  }
  try {
    return StageCyclicErrorOf(FitPlateCyclicError(samples, period_mm));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("--cyclic-period-mm: ") + e.what());
  }
}

}  // namespace

int RunFitMarkerError(int argc, char** argv) {
  CLI::App app{
      "Fit f_rf, the retro-reflector range error (Eq. 1), from recordings of a marker "
      "structure on a linear stage: reference from the structure's pose, a line over "
      "time, a csaps smoothing spline (docs/tracking.md)",
      "tofnav fit-marker-error"};
  AddConfigOptions(app);
  std::vector<std::filesystem::path> recordings;
  MarkerSourceArgs source_args;
  std::filesystem::path tool_path, out_path;
  std::optional<double> speed_mm_s;
  std::string smoothing = "gcv";
  double jump_mm = 20.0, speed_tolerance = 0.1;
  bool quiet = false, json = false;
  StageRangeErrorOptions stage_options;
  app.add_option("recordings", recordings, "stage recording(s) (hl2ss .bin or StreamRecorder)")
      ->required();
  source_args.AddTo(app, false);
  app.add_option("--tool", tool_path, "the multi-marker structure (tool JSON or .rom)")->required();
  app.add_option("--out", out_path, "f_rf curve JSON to write")->required();
  app.add_option("--speed-mm-s", speed_mm_s,
                 "the stage's commanded speed [mm/s]: the reference line moves at it (only its "
                 "origin is fitted); runs whose fitted speed differs by > 10 % drop");
  app.add_option("--smoothing", smoothing,
                 "csaps p in [0, 1], or 'gcv' (generalised cross-validation)");
  app.add_option("--split-jump-mm", jump_mm,
                 "a structure jump larger than this between frames starts a new run [mm]");
  app.add_option("--min-frames", stage_options.min_frames, "posed frames a run needs");
  bool allow_lossy_depth = false;
  app.add_flag("--allow-lossy-depth", allow_lossy_depth,
               "use SAME+H26x depth (4 mm steps, lossy) anyway (docs/ahat.md 3.6.5)");
  bool range_only = false;
  app.add_flag("--range-only", range_only,
               "f_rf of the range alone, Eq. (1) as published (default: with the tape's "
               "entrance-angle term when the runs' tilts span 10 deg; docs/tracking.md 4)");
  double cyclic_period_mm = 0.0;
  PlateSampleOptions plate;
  app.add_option("--cyclic-period-mm", cyclic_period_mm,
                 "also measure the sensor's cyclic range error at this period (L / 3 = "
                 "351.66666666666667 for AHAT's 142 MHz) on the plate the tape sits on, against "
                 "the f_rf-corrected tape's plane; identify holds it (docs/correction.md 2.8); 0: "
                 "not measured")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--plate-radius-mm", plate.plate_radius_mm,
                 "with --cyclic-period-mm: the largest disc around the markers' centroid, in their "
                 "plane, that the plate covers [mm]")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the summary as one JSON object");
  TOFNAV_PARSE(app, argc, argv);
  if ((cyclic_period_mm > 0.0) != (plate.plate_radius_mm > 0.0)) {
    throw std::runtime_error("--cyclic-period-mm and --plate-radius-mm go together");
  }

  SmoothingSplineOptions spline_options;
  if (smoothing != "gcv") {
    try {
      spline_options.smoothing_p = std::stod(smoothing);
    } catch (const std::exception&) {
      throw std::runtime_error("--smoothing must be a number in [0, 1] or 'gcv', not '" +
                               smoothing + "'");
    }
    spline_options.Check();
  }
  const ToolGeometry structure = ReadToolFile(tool_path);
  std::vector<MarkerRangeSample> samples;
  OrderedJson runs_json = OrderedJson::array();
  int frames_used = 0;
  StageSampleOptions sample_options{jump_mm, speed_mm_s, speed_tolerance, stage_options};
  for (const std::filesystem::path& recording : recordings) {
    source_args.recording = recording;
    const MarkerSource source = OpenMarkerSource(source_args);
    RefuseLossyDepth(*source.recording, recording, allow_lossy_depth);
    ProgressBar progress("fit-marker-error " + recording.filename().string(), quiet || json);
    const StageSamples stage = CollectStageSamples(
        source, source_args.detection, structure, sample_options,
        [&](std::size_t done, std::size_t total) { progress.Update(done, total); });
    samples.insert(samples.end(), stage.samples.begin(), stage.samples.end());
    frames_used += stage.frames_used;
    for (const StageRun& r : stage.runs) {
      OrderedJson run{{"recording", recording.string()}, {"run", r.run}, {"frames", r.frames}};
      if (r.speed_mm_s) {
        run["frames_used"] = r.frames_used;
        run["speed_mm_s"] = *r.speed_mm_s;
        run["line_rms_mm"] = *r.line_rms_mm;
        run["samples"] = r.samples;
      }
      if (!r.dropped.empty()) run["dropped"] = r.dropped;
      runs_json.push_back(run);
    }
  }
  if (samples.empty()) throw std::runtime_error("no run gave range-error samples");
  const MarkerRangeFitResult fit = FitMarkerRangeModel(samples, spline_options, !range_only);
  MarkerRangeFile file{fit.model,
                       {static_cast<int>(samples.size()), frames_used, fit.rms_residual_mm,
                        fit.fit.effective_dof, spline_options.smoothing_p ? "given" : "gcv"}};
  if (cyclic_period_mm > 0.0) {
    plate.split_jump_mm = jump_mm;
    file.cyclic_error = MeasureStageCyclicError(recordings, source_args, structure, fit.model,
                                                plate, cyclic_period_mm, quiet || json);
  }
  WriteMarkerRangeJson(out_path, file);

  OrderedJson curve = OrderedJson::array();
  for (double d = 300.0; d <= 700.0; d += 50.0) curve.push_back({d, fit.model.BiasMm(d)});
  OrderedJson summary{{"out", out_path.string()},
                      {"samples", samples.size()},
                      {"frames_used", frames_used},
                      {"smoothing_p", fit.fit.smoothing_p},
                      {"effective_dof", fit.fit.effective_dof},
                      {"rms_residual_mm", fit.rms_residual_mm},
                      {"entrance_gain_mm_per_rad", fit.model.entrance_gain_mm_per_rad},
                      {"f_rf_mm", curve},
                      {"runs", runs_json}};
  if (file.cyclic_error) summary["cyclic_error"] = StageCyclicErrorToJson(*file.cyclic_error);
  if (json) {
    std::cout << WithOptions(summary, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "f_rf from " << samples.size() << " samples of " << frames_used << " frames: p "
            << fit.fit.smoothing_p << ", " << fit.fit.effective_dof
            << " degrees of freedom, residual RMS " << fit.rms_residual_mm << " mm, entrance gain "
            << fit.model.entrance_gain_mm_per_rad << " mm/rad -> " << out_path.string()
            << "\n  f_rf [mm]:";
  for (const auto& c : curve) std::cout << " " << c[0].get<double>() << ": " << c[1].get<double>();
  std::cout << "\n";
  if (const auto& c = file.cyclic_error) {
    std::cout << "  cyclic error (the plate, " << c->plate_samples << " pixels over " << c->span_mm
              << " mm): " << c->cyclic.amplitude_mm << " +- " << c->amplitude_sd_mm
              << " mm at period " << c->cyclic.period_mm << " mm, phase " << c->cyclic.phase_rad
              << " +- " << c->phase_sd_rad << " rad\n";
  }
  for (const auto& run : runs_json) {
    std::cout << "  " << run["recording"].get<std::string>() << " run " << run["run"] << ": "
              << run["frames"] << " frames";
    if (run.contains("speed_mm_s")) {
      std::cout << ", " << run["frames_used"] << " used, speed " << run["speed_mm_s"]
                << " mm/s, line RMS " << run["line_rms_mm"] << " mm";
    }
    if (run.contains("dropped")) std::cout << ", dropped: " << run["dropped"].get<std::string>();
    std::cout << "\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace tofnav
