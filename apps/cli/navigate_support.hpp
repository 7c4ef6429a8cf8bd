// SPDX-License-Identifier: BSD-3-Clause
// Pieces of `tofnav navigate` and `tofnav verify` kept out of the command's flow: the
// registration file, the summary's dropped counts, the supervisor's clean-up, the check's report.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "supervisor.hpp"
#include "tofnav/pipeline/landmark_check.hpp"
#include "tofnav/stream/headset_display.hpp"
#include "tofnav/stream/navigation_session.hpp"

namespace tofnav {

/// Exit status of `verify` when a landmark's error is over the limit or not every landmark was
/// touched.
constexpr int kExitVerifyFailed = 4;

/// tool_from_image from a registration file; a file naming image_from_tool is inverted.
Rigid3d ReadToolFromImage(const std::filesystem::path& path);

/// What navigation left out, and why (docs/navigation.md section 1.1): JSON and text.
nlohmann::ordered_json DroppedJson(const NavigationSessionStats& stats);
void PrintDropped(const NavigationSessionStats& stats);

/// The supervisor's part once the worker has ended (docs/navigation.md 6.6): what the worker left
/// on the headset is replaced by a red NAVIGATION STOPPED panel; returns the worker's status.
int ClearAfterWorker(const WorkerEnd& end, const HeadsetShown& left,
                     const HeadsetDisplayOptions& headset);

/// For the supervisor's tests only: a crash, without a core file.
[[noreturn]] void InjectedAbort();

/// The landmarks of a markups file (labels as names; "landmark N" when unlabelled).
std::vector<Landmark> ReadLandmarks(const std::filesystem::path& path);

/// One touch as a line: "verify: nasion 0.42 mm ok (rested 1.02 s, 46 frames)"; a touch nearer
/// another landmark says so.
std::string TouchLine(const LandmarkCheck& check, const LandmarkTouch& touch);

/// The check's "verify" object of --json: per landmark its error vector and pass, the limit,
/// the largest error and whether it passed.
nlohmann::ordered_json LandmarkCheckJson(const LandmarkCheck& check);

}  // namespace tofnav
