// SPDX-License-Identifier: BSD-3-Clause
// The accuracy check before guidance: the tracked pointer's tip rests on landmarks planned in the
// image; each landmark's error is the tip against the landmark placed by the registration
// (docs/navigation.md section 7). Frame by frame, for recordings and live streams alike.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/pipeline/navigator.hpp"

namespace tofnav {

/// A landmark planned in the image (CT LPS) [mm]: nasion, a tragus, a divot on the headframe.
struct Landmark {
  std::string name;
  Eigen::Vector3d in_image = Eigen::Vector3d::Zero();
};

struct LandmarkCheckOptions {
  /// A touch: over the last still_time_s [s] ...
  double still_time_s = 1.0;
  /// ... at least still_fraction of the tip positions lie within still_radius_mm of their median.
  /// The tip of a tracked pointer scatters by its markers' angular noise times their distance
  /// from the tip (0.4 mm standard deviation, spikes of 2-4 mm, for the simulator's 200 mm
  /// pointer), so a rest is judged on most positions, not all, and a slow drift of a couple of
  /// millimetres a second still counts as resting.
  double still_radius_mm = 2.0;
  double still_fraction = 0.8;
  /// After a touch, the median of the last 0.2 s of the tip must move this far [mm] from it
  /// before the next touch counts, so one long rest is one touch.
  double leave_mm = 10.0;
  /// A missing tip for longer than this [s] restarts the rest.
  double max_gap_s = 0.25;
  /// A landmark passes when its error is at most this [mm].
  double pass_mm = 2.0;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// One landmark touched: the mean of the rest's tip positions within still_radius_mm of their
/// median (the scatter's spikes left out) against the landmark, in the reference tool's
/// frame (both measured in the same frames, so neither the headset's motion nor its world map
/// enters), reported in image axes.
struct LandmarkTouch {
  int landmark = -1;                                         // index in the list
  Eigen::Vector3d tip_in_image = Eigen::Vector3d::Zero();    // image_from_tool * tip
  Eigen::Vector3d error_in_image = Eigen::Vector3d::Zero();  // tip - landmark, LPS [mm]
  double error_mm = 0.0;
  bool pass = false;
  double start_s = 0.0;  // the rest's first and last frame
  double end_s = 0.0;
  int frames = 0;  // tip positions averaged
  /// The landmark nearest the touch, when it is not the one asked for (a wrong landmark
  /// touched, or a registration off by about the landmarks' spacing).
  std::optional<int> nearer_landmark;
};

/// Asks for the landmarks in their order: each rest of the pointer's tip is a touch of the
/// landmark asked for, then the next is asked for. Feed every NavigationState in time order.
class LandmarkCheck {
 public:
  /// `tool_from_image`: the registration checked. `tip_in_instrument`: the pointer's
  /// pivot-calibrated tip. PreconditionError on no landmark or bad options.
  LandmarkCheck(std::vector<Landmark> landmarks, const Rigid3d& tool_from_image,
                const Eigen::Vector3d& tip_in_instrument, const LandmarkCheckOptions& options = {});

  /// One frame; the touch it completes, if any. Frames without both tools measured
  /// (tool_from_instrument), or with the reference still SETTLING, add nothing.
  std::optional<LandmarkTouch> Add(const NavigationState& state);

  bool done() const { return touches_.size() == landmarks_.size(); }
  /// The landmark asked for next (nullopt when done).
  std::optional<int> next() const;
  bool passed() const;  // done, and every touch passed
  double max_error_mm() const;
  const std::vector<Landmark>& landmarks() const { return landmarks_; }
  const std::vector<LandmarkTouch>& touches() const { return touches_; }
  const LandmarkCheckOptions& options() const { return options_; }
  /// One line for a terminal, the headset panel and Slicer: "verify: touch nasion (1 of 4)",
  /// "verify: nasion 0.42 mm ok, ..." and, when done, "verify PASSED: largest error 0.61 mm
  /// (limit 2.0 mm)" or "verify FAILED: ...".
  std::string StatusLine() const;

 private:
  struct Sample {
    double t_s;
    Eigen::Vector3d tip_in_image;
  };
  std::vector<Landmark> landmarks_;
  Rigid3d image_from_tool_;
  Eigen::Vector3d tip_in_instrument_;
  LandmarkCheckOptions options_;
  std::deque<Sample> rest_;  // the shortest run of recent samples spanning still_time_s
  std::optional<Eigen::Vector3d> left_from_;  // the last touch, until the tip has left it
  std::vector<LandmarkTouch> touches_;
};

}  // namespace tofnav
