// SPDX-License-Identifier: BSD-3-Clause
// navigate_support.hpp: the registration file, the summary's dropped counts, the supervisor's
// clean-up and the landmark check's report.
#include "navigate_support.hpp"

#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>

#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/casefile/transform_io.hpp"
#include "tofnav/stream/headset_stop.hpp"

namespace tofnav {

Rigid3d ReadToolFromImage(const std::filesystem::path& path) {
  const NamedTransform t = ReadTransform(path);
  if (t.source_frame == "tool" && t.target_frame == "image") return t.target_from_source.Inverse();
  if (!t.source_frame.empty() && t.source_frame != "image") {
    throw std::runtime_error(path.string() + ": expected tool_from_image, found " + t.target_frame +
                             "_from_" + t.source_frame);
  }
  return t.target_from_source;
}

nlohmann::ordered_json DroppedJson(const NavigationSessionStats& stats) {
  nlohmann::ordered_json j{{"reference_pose_jumps", stats.reference_pose_jumps},
                           {"poses_refused_void", stats.poses_refused_void}};
  const auto uses = [](const std::map<MarkerUse, std::int64_t>& counts) {
    nlohmann::ordered_json u = nlohmann::ordered_json::object();
    for (const auto& [use, n] : counts) u[ToString(use)] = n;
    return u;
  };
  j["reference_markers"] = uses(stats.reference_markers);
  j["instrument_markers"] = uses(stats.instrument_markers);
  return j;
}

void PrintDropped(const NavigationSessionStats& stats) {
  std::cout << "  reference poses left out as jumps in the world: " << stats.reference_pose_jumps
            << "\n";
  if (stats.poses_refused_void > 0) {
    std::cout << "  candidate poses refused for a marker where the image shows empty space: "
              << stats.poses_refused_void << "\n";
  }
  const auto print = [](const char* tool, const std::map<MarkerUse, std::int64_t>& counts) {
    std::int64_t not_used = 0;
    for (const auto& [use, n] : counts) not_used += InPose(use) ? 0 : n;
    if (counts.empty()) return;
    std::cout << "  " << tool << " markers not in the pose: " << not_used;
    for (const auto& [use, n] : counts) {
      if (!InPose(use) || use == MarkerUse::kUsedDamaged)
        std::cout << ", " << ToString(use) << " " << n;
    }
    std::cout << "\n";
  };
  print("reference", stats.reference_markers);
  print("instrument", stats.instrument_markers);
}

int ClearAfterWorker(const WorkerEnd& end, const HeadsetShown& left,
                     const HeadsetDisplayOptions& headset) {
  if (!left.anything) return end.ShellStatus();
  const std::string how = end.Describe();
  try {
    ShowNavigationStopped(headset, left.panel, "NAVIGATION STOPPED\ntofnav " + how);
    std::fprintf(stderr,
                 "tofnav navigate: the navigation process %s without clearing the headset: "
                 "cleared it (the plan is gone; the headset shows NAVIGATION STOPPED)\n",
                 how.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr,
                 "tofnav navigate: the navigation process %s without clearing the headset, and "
                 "it could not be cleared (%s): its holograms are stale; restart the headset "
                 "app to remove them\n",
                 how.c_str(), e.what());
  }
  return end.ShellStatus();
}

void InjectedAbort() {
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  std::abort();
}

std::vector<Landmark> ReadLandmarks(const std::filesystem::path& path) {
  std::vector<Landmark> landmarks;
  for (const MarkupPoint& p : ReadLabelledMarkupPoints(path)) {
    landmarks.push_back(
        {p.label.empty() ? "landmark " + std::to_string(landmarks.size() + 1) : p.label, p.lps_mm});
  }
  return landmarks;
}

std::string TouchLine(const LandmarkCheck& check, const LandmarkTouch& touch) {
  char line[256];
  std::snprintf(line, sizeof line, "verify: %s %.2f mm %s (rested %.2f s, %d frames)",
                check.landmarks()[static_cast<std::size_t>(touch.landmark)].name.c_str(),
                touch.error_mm, touch.pass ? "ok" : "TOO FAR", touch.end_s - touch.start_s,
                touch.frames);
  std::string text = line;
  if (touch.nearer_landmark) {
    text += "; the tip was nearer " +
            check.landmarks()[static_cast<std::size_t>(*touch.nearer_landmark)].name +
            ": the wrong landmark touched, or the registration is off by about the landmarks' "
            "spacing";
  }
  return text;
}

nlohmann::ordered_json LandmarkCheckJson(const LandmarkCheck& check) {
  nlohmann::ordered_json touches = nlohmann::ordered_json::array();
  for (const LandmarkTouch& t : check.touches()) {
    nlohmann::ordered_json j{
        {"name", check.landmarks()[static_cast<std::size_t>(t.landmark)].name},
        {"error_mm", t.error_mm},
        {"error_in_image_mm", {t.error_in_image.x(), t.error_in_image.y(), t.error_in_image.z()}},
        {"tip_in_image_mm", {t.tip_in_image.x(), t.tip_in_image.y(), t.tip_in_image.z()}},
        {"pass", t.pass},
        {"rest_start_s", t.start_s},
        {"rest_end_s", t.end_s},
        {"frames", t.frames}};
    if (t.nearer_landmark) {
      j["nearer_landmark"] = check.landmarks()[static_cast<std::size_t>(*t.nearer_landmark)].name;
    }
    touches.push_back(j);
  }
  return {{"landmarks", check.landmarks().size()},
          {"touched", check.touches().size()},
          {"pass_mm", check.options().pass_mm},
          {"max_error_mm", check.max_error_mm()},
          {"passed", check.passed()},
          {"status", check.StatusLine()},
          {"touches", touches}};
}

}  // namespace tofnav
