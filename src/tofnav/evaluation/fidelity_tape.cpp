// SPDX-License-Identifier: BSD-3-Clause
// Fidelity, the tape on the linear stage (paper Sec. III-A.1): the marker-stage scene's four runs
// (0, 10, 20 and 30 deg), each marker's measured surface range against the stage's reference
// (CollectStageSamples, the f_rf data), binned by range; and f_rf fitted for the other protocols.
#include <algorithm>
#include <cmath>
#include <map>

#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/evaluation/demo_stages.hpp"
#include "tofnav/evaluation/fidelity.hpp"
#include "tofnav/pipeline/marker_tasks.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav {
namespace {

constexpr double kTapeRunRestartMm = 100.0;  // a run restarts 400 mm back (demo_marker.cpp)
constexpr double kTapeBinMm = 50.0;
constexpr double kTapeFromMm = 300.0, kTapeToMm = 700.0;  // the paper's stage range
constexpr std::size_t kTapeMinBinSamples = 5;

// Mean range error per 50 mm bin of measured range within 300-700 mm (bins with too few samples
// left out): bin start [mm] -> mean [mm].
std::map<double, double> BinMeans(std::span<const MarkerRangeSample> samples) {
  std::map<double, std::pair<double, std::size_t>> sums;
  for (const MarkerRangeSample& s : samples) {
    if (s.range_mm < kTapeFromMm || s.range_mm >= kTapeToMm) continue;
    auto& [sum, n] = sums[kTapeBinMm * std::floor(s.range_mm / kTapeBinMm)];
    sum += s.error_mm;
    ++n;
  }
  std::map<double, double> means;
  for (const auto& [bin, sn] : sums) {
    if (sn.second >= kTapeMinBinSamples) means[bin] = sn.first / static_cast<double>(sn.second);
  }
  return means;
}

}  // namespace

void FidelityTapeStage(const FidelityOptions& options, FidelityResult& result,
                       MarkerRangeModel& frf) {
  sim::Scenario scenario = sim::BuiltinScenario("marker-stage");
  const auto frames = static_cast<std::int64_t>(
      std::max(80.0, std::round(static_cast<double>(options.stage_frames) * options.frames_scale)));
  const double speed_mm_per_s = FitMarkerStageInto(scenario, frames);
  const std::filesystem::path dir = options.out / "tape_stage";
  SimulateForFidelity(options, scenario, dir, "tape stage: simulate", options.seed);
  const MarkerSource source = OpenSimulatedMarkerSource(dir);
  StageSampleOptions sample_options;
  sample_options.split_jump_mm = kTapeRunRestartMm;
  sample_options.speed_mm_s = speed_mm_per_s;
  const StageSamples samples = CollectStageSamples(
      source, MarkerDetectionOptions{}, ReadToolFile(dir / "tools" / "tape_structure.json"),
      sample_options, [&](std::size_t d, std::size_t t) {
        if (options.progress) options.progress("tape stage: measure", d, t);
      });
  if (samples.samples.empty()) throw std::runtime_error("tape stage: no run gave samples");
  frf = FitMarkerRangeModel(samples.samples).model;

  // The runs' samples follow each other in run order; a run's tilt is its order among the used
  // runs (the scene's runs are at 0, 10, 20 and 30 deg).
  std::vector<std::map<double, double>> per_run;
  std::size_t first = 0;
  for (const StageRun& run : samples.runs) {
    if (!run.dropped.empty() || run.samples == 0) continue;  // not in samples.samples
    per_run.push_back(BinMeans(std::span(samples.samples).subspan(first, run.samples)));
    first += run.samples;
  }
  const std::map<double, double> all = BinMeans(samples.samples);
  if (all.size() < 2) throw std::runtime_error("tape stage: fewer than two range bins");
  double lo = all.begin()->second, hi = lo;
  for (const auto& [bin, mean] : all) {
    lo = std::min(lo, mean);
    hi = std::max(hi, mean);
  }
  // Between angles: each bin's spread across the runs, averaged over the bins all runs reach.
  double spread_sum = 0.0;
  int spread_bins = 0;
  for (const auto& [bin, mean] : all) {
    double run_lo = mean, run_hi = mean;
    bool every_run = per_run.size() >= 2;
    for (const auto& run : per_run) {
      const auto it = run.find(bin);
      if (it == run.end()) {
        every_run = false;
        break;
      }
      run_lo = std::min(run_lo, it->second);
      run_hi = std::max(run_hi, it->second);
    }
    if (!every_run) continue;
    spread_sum += run_hi - run_lo;
    ++spread_bins;
  }
  const double between_angles_mm = spread_bins > 0 ? spread_sum / spread_bins : std::nan("");
  const char* source_text = "paper Sec. III-A.1 (linear stage, 300-700 mm, 0-30 deg)";
  result.rows.push_back(MakeFidelityRow("tape on a linear stage",
                                        "largest change of the range error over depth [mm]",
                                        source_text, 4.25, std::nullopt, hi - lo));
  result.rows.push_back(MakeFidelityRow("tape on a linear stage",
                                        "difference between angles 0-30 deg, mean [mm]",
                                        source_text, 1.08, std::nullopt, between_angles_mm));
  nlohmann::ordered_json bins = nlohmann::ordered_json::array();
  for (const auto& [bin, mean] : all) bins.push_back({{"from_mm", bin}, {"mean_error_mm", mean}});
  result.details["tape_stage"] = {{"frames", source.frames},
                                  {"runs_used", per_run.size()},
                                  {"samples", samples.samples.size()},
                                  {"bins", bins},
                                  {"between_angles_bins", spread_bins}};
}

}  // namespace tofnav
