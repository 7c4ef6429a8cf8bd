// SPDX-License-Identifier: BSD-3-Clause
// truth.json of a simulation (schema: docs/simulator.md), written frame by frame.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/sim/scenario.hpp"
#include "tofnav/sim/simulator.hpp"

namespace tofnav {

/// Run facts written into the header next to the scenario's.
struct TruthRunInfo {
  std::string profile = "raw";  // recording depth profile: "raw" or "zdepth"
  /// Output files by role ("recording", "calibration", "truth_range", "ct", "skin", "plan"),
  /// relative to the output folder.
  std::vector<std::pair<std::string, std::string>> files;
};

/// The joined headframe tool of a scenario: the tools rigid with the patient whose names start
/// with "reference" (evd-usecase: reference_left and reference_right), in scenario order. The
/// simulator writes them as one tool, tools/headframe.json, in the frame of the first, and
/// truth.json carries headframe_from_image (docs/simulator.md). A single reference tool is a
/// headframe of one part (the suite's single-tool case); empty when there is none.
std::vector<int> HeadframeTools(const sim::Scenario& scenario);
inline constexpr const char* kHeadframeToolName = "headframe";

/// Streams truth.json: the header (conventions, camera, materials, tools with marker geometry,
/// patient, <tool>_from_image), then one line per frame, then the counts. Atomic: the file
/// appears on Close(). All matrices are 4 x 4 row-major nested lists, column-vector convention
/// (p_target = M p_source), mm.
class SimulationTruthWriter {
 public:
  SimulationTruthWriter(const std::filesystem::path& path, const sim::Scenario& scenario,
                        const TruthRunInfo& info);
  void Append(const sim::SimulatedFrame& frame);
  void Close(std::int64_t dropped_slots);

 private:
  const sim::Scenario& scenario_;
  AtomicFileWriter file_;
  std::int64_t frames_ = 0;
  std::int64_t last_slot_ = -1;
};

}  // namespace tofnav
