// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate suite: one case of a robustness suite (docs/suite.md): its variation, how its
// head and headset are derived, and the row of figures its run gives.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tofnav/pipeline/paper_method.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/sim/multipath.hpp"
#include "tofnav/sim/scenario_variation.hpp"

namespace tofnav {

using SuiteJson = nlohmann::ordered_json;

/// One scenario variation of the suite file.
struct SuiteCase {
  std::string name;
  std::string head = "phantom";  // phantom | ct:<volume> | mesh:<skin.ply>
  bool head_mirror = false;      // ct: the volume mirrored left-right (another head)
  double head_scale = 1.0;       // ct: voxel spacing scaled (a smaller or larger head)
  std::uint64_t seed = 1;
  std::string device = "synthetic";  // synthetic | perturbed:<n> | folder:<hl2ss calibration>
  double multipath_gain = sim::MultipathOptions{}.gain;  // the simulator's calibrated default
  /// > 0 replaces the simulator's multipath quadrature, source and receiver blocks of this many
  /// pixels (MultipathOptions::source_stride_px, receiver_stride_px; docs/simulator.md 6.9.1); 0:
  /// the simulator's default, 16.
  int multipath_stride_px = 0;
  /// >= 0 replaces the simulator's range noise floor exponent (NoiseOptions::
  /// depth_sigma_floor_exponent; its default 1.5 meets STTAR's marker rows, docs/simulator.md 10.1;
  /// 0 is the flat floor of the suites before session 29).
  double noise_floor_exponent = -1.0;
  sim::ScenarioVariation variation;
};

/// A suite file: its cases and the frame scale they run at.
struct SuiteFile {
  std::string name;
  double frames_scale = 0.35;
  /// "stage": "per_device" (the default): one whole f_rf stage per device and seed, shared by the
  /// cases (SuiteRunOptions::stage_folder); "per_case": each case records its own, 400 frames.
  bool stage_per_device = true;
  std::vector<SuiteCase> cases;
};

/// Parses a suite file; IoError naming the file and the JSON path of a bad key or value.
SuiteFile ReadSuiteFile(const std::filesystem::path& path);

/// How the cases of a suite are run (`tofnav evaluate suite`'s options).
struct SuiteRunOptions {
  double frames_scale = 1.0;  // the demo's frame counts times this
  bool quiet = true;
  /// The recordings are written in this profile at `bitrate_bps` (unset: the hl2ss client's
  /// default).
  Hl2ssStreamProfile stream_profile{Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kRaw};
  std::optional<std::uint32_t> bitrate_bps;
  /// > 0: the depth stage's stability check (DemoContext), whose largest C1 and head-median
  /// changes go in the row as stability_c1_mm and stability_head_mm.
  int stability_subsets = 0;
  /// With stability_subsets >= 2: the medoid of the runs is the model (DemoContext::consensus);
  /// its own stability goes in the row as consensus_c1_mm and consensus_head_mm.
  bool consensus = false;
  bool consensus_mean = true;       // DemoContext::consensus_mean
  Method method = Method::kTofnav;  // the stages after the session: tofnav's or the paper's
  /// The stages to run, prerequisites included (DemoStagesWithPrerequisites); empty: all. The
  /// row then carries them as "stages_run" and its acceptance only the lines of those stages.
  std::set<std::string> stages;
  /// Non-empty: the f_rf stage is one calibration per device (and per render setting the stage
  /// sees), recorded whole (the built-in stage's 1800 frames) under this folder with
  /// `stage_seed` by the first case that needs it and read by the others, as a clinic calibrates
  /// a headset's tape once (docs/suite.md); empty: each case records its own, shorter stage.
  std::filesystem::path stage_folder;
  std::uint64_t stage_seed = 1;
};

/// Simulates and runs the case's sessions through the whole pipeline under `dir` (the demo's
/// stages, docs/demo.md) and returns its row: {"name", "ok", "error", "method", figures...}.
SuiteJson RunSuiteCase(const SuiteCase& c, const std::filesystem::path& dir,
                       const SuiteRunOptions& options);

/// The acceptance lines of the outlier-proof pipeline (docs/suite.md) for one row: each
/// {figure, value, op, limit, met}; where the row has "stages_run", the lines of those stages.
SuiteJson SuiteAcceptance(const SuiteJson& row);

}  // namespace tofnav
