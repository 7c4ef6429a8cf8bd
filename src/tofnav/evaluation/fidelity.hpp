// SPDX-License-Identifier: BSD-3-Clause
// `tofnav evaluate fidelity`: the published measurements of real devices re-done on the simulator,
// each with its own protocol, as rows of (published, ours, within?) (issue 38 item 2;
// docs/simulator.md 10).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav {

/// One published figure and ours. A figure published as mean +- sd is within when ours lies in
/// [mean - sd, mean + sd]; one published without a spread is given a band of +-25 % of itself
/// (`published_low` / `published_high` say which band was used).
struct FidelityRow {
  std::string experiment;  // "skin study", "materials", ...
  std::string figure;      // what is measured, with its unit
  std::string source;      // where the published figure is (paper section, STTAR)
  double published = 0.0;
  double published_low = 0.0, published_high = 0.0;
  bool spread_published = false;  // false: the +-25 % band
  double ours = 0.0;
  bool within() const { return ours >= published_low && ours <= published_high; }
};

/// A row for a figure published as mean +- sd, or (sd unset) as one value with the +-25 % band.
FidelityRow MakeFidelityRow(std::string experiment, std::string figure, std::string source,
                            double published, std::optional<double> sd, double ours);

struct FidelityOptions {
  std::filesystem::path out;  // one folder per experiment's simulations
  std::uint64_t seed = 1;
  /// Frames of every protocol times this (1: the defaults below, about 4 minutes on 2 cores;
  /// the paper's own counts are larger: 500 frames per participant, 300 per phantom).
  double frames_scale = 1.0;
  int participants = 10;  // the skin study's
  std::int64_t participant_frames = 60;
  std::int64_t phantom_frames = 30;  // Table I: frames averaged per pixel (paper: 300)
  std::int64_t stage_frames = 160;   // the tape on the linear stage, four runs
  std::int64_t station_frames = 2;   // materials: frames per station (90 stations)
  /// STTAR's sphere tool (sim::MarkerNoiseProtocol): static positions over 350-700 mm, and the
  /// frames of each of a position's two holds (static, then moved 20 mm along z; >= 12 frames).
  int marker_positions = 12;
  std::int64_t marker_hold_frames = 18;
  /// The experiments to run (names as FidelityExperiments()); empty: all. The tape stage runs
  /// whenever materials, the skin study or the markers do (its f_rf corrects their markers).
  std::vector<std::string> only;
  /// Table I "after": a depth model per phantom ("photopolymer", "nylon"), e.g. one identified
  /// on a session of that phantom, corrects its frames before they are averaged; adds the rows.
  std::map<std::string, DepthModelFile> phantom_depth_models;
  /// Applied to every scene before it is simulated (e.g. a render setting under study); optional.
  std::function<void(sim::Scenario&)> vary;
  std::function<void(const std::string&, std::size_t, std::size_t)> progress;
};

struct FidelityResult {
  std::vector<FidelityRow> rows;
  nlohmann::ordered_json details;  // per experiment: the figures behind the rows
};

/// The experiments' names: "tape", "markers", "materials", "phantoms", "skin".
const std::vector<std::string>& FidelityExperiments();

/// Runs every experiment in order: the tape on the linear stage (whose f_rf the others use),
/// STTAR's sphere markers, the materials plate, Table I's phantoms, the skin study.
FidelityResult RunFidelity(const FidelityOptions& options);

/// Simulates `scenario` into `dir` (SAME+RAW) at `seed`, progress under `label`.
void SimulateForFidelity(const FidelityOptions& options, const sim::Scenario& scenario,
                         const std::filesystem::path& dir, const std::string& label,
                         std::uint64_t seed);

// The experiments, each appending its rows and details (fidelity_*.cpp).
void FidelityTapeStage(const FidelityOptions& options, FidelityResult& result,
                       MarkerRangeModel& frf);
void FidelitySttarMarkers(const FidelityOptions& options, const MarkerRangeModel& frf,
                          FidelityResult& result);
void FidelityMaterials(const FidelityOptions& options, const MarkerRangeModel& frf,
                       FidelityResult& result);
void FidelityPhantoms(const FidelityOptions& options, FidelityResult& result);
void FidelitySkinStudy(const FidelityOptions& options, const MarkerRangeModel& frf,
                       FidelityResult& result);

}  // namespace tofnav
