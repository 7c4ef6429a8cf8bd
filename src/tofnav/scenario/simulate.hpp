// SPDX-License-Identifier: BSD-3-Clause
// `tofnav simulate`: renders a scenario into a recording, its calibration and the ground truth
// (file layout and schemas: docs/simulator.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/sim/scenario.hpp"
#include "tofnav/sim/simulator.hpp"

namespace tofnav {

struct SimulateOptions {
  std::optional<std::int64_t> frames;  // overrides scenario.frames: the first N frames
  std::optional<std::uint64_t> seed;   // overrides scenario.seed
  /// The recording's hl2ss profile: SAME+RAW by default; H.264/H.265 profiles are encoded with
  /// libx264/libx265 as the headset would (docs/ahat.md 3.6).
  Hl2ssStreamProfile profile{Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kRaw};
  std::optional<std::uint32_t> bitrate_bps;  // H26x; unset: the hl2ss client's default
  bool truth_depth = false;                  // also write truth_range_f32.bin
  /// A camera built for the scenario's calibration options, to share between runs (optional).
  std::shared_ptr<const sim::SimulatorCamera> camera;
  /// Called after each frame with (frames done, total).
  std::function<void(std::size_t, std::size_t)> progress;
  void Check() const;  // throws PreconditionError naming the bad field
};

struct SimulateResult {
  std::int64_t frames = 0;
  std::int64_t dropped_slots = 0;
  double duration_s = 0.0;                   // recording time, first to last frame
  std::vector<std::filesystem::path> files;  // relative to the output folder
  /// Per scene tool: frames in which every marker was hit by at least one pixel-centre ray.
  std::vector<std::int64_t> fully_visible_frames;
  /// One line each, e.g. a tool that is never fully visible in the rendered frames.
  std::vector<std::string> warnings;
};

/// Writes into `out_dir` (created if missing): rm_depth_ahat.bin (hl2ss, pose mode 1),
/// calibration/rm_depth_ahat/*, truth.json, and with options.truth_depth truth_range_f32.bin;
/// with a patient also ct.nrrd, skin_truth.ply and plan.mrk.json; meshes/<object>.ply for every
/// scene object (its mesh in its own frame; truth.json files "mesh:<object>"). Frames are rendered
/// and written one at a time (memory does not grow with the frame count); every file is atomic. The
/// same scenario and seed give byte-identical files. Refuses (PreconditionError, before writing
/// anything) a scenario whose markers reach into other surfaces (sim::RequireMarkersClear).
SimulateResult RunSimulation(sim::Scenario scenario, const std::filesystem::path& out_dir,
                             const SimulateOptions& options = {});

}  // namespace tofnav
