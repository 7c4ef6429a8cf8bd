// SPDX-License-Identifier: BSD-3-Clause
// LandmarkCheck: rests of the pointer's tip as touches of the asked-for landmarks
// (docs/navigation.md section 7).
#include "tofnav/pipeline/landmark_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

std::string Mm(double value_mm) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f mm", value_mm);
  return text;
}

// Component-wise median: robust to the tip's scatter spikes.
Eigen::Vector3d MedianPoint(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d m;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v;
    v.reserve(points.size());
    for (const Eigen::Vector3d& p : points) v.push_back(p[k]);
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    m[k] = *mid;
  }
  return m;
}

}  // namespace

void LandmarkCheckOptions::Check() const {
  Require(std::isfinite(still_time_s) && still_time_s > 0.0,
          "LandmarkCheckOptions.still_time_s must be > 0");
  Require(std::isfinite(still_radius_mm) && still_radius_mm > 0.0,
          "LandmarkCheckOptions.still_radius_mm must be > 0");
  Require(std::isfinite(still_fraction) && still_fraction > 0.0 && still_fraction <= 1.0,
          "LandmarkCheckOptions.still_fraction must be in (0, 1]");
  Require(std::isfinite(leave_mm) && leave_mm >= still_radius_mm,
          "LandmarkCheckOptions.leave_mm must be >= still_radius_mm");
  Require(std::isfinite(max_gap_s) && max_gap_s > 0.0,
          "LandmarkCheckOptions.max_gap_s must be > 0");
  Require(std::isfinite(pass_mm) && pass_mm > 0.0, "LandmarkCheckOptions.pass_mm must be > 0");
}

LandmarkCheck::LandmarkCheck(std::vector<Landmark> landmarks, const Rigid3d& tool_from_image,
                             const Eigen::Vector3d& tip_in_instrument,
                             const LandmarkCheckOptions& options)
    : landmarks_(std::move(landmarks)),
      image_from_tool_(tool_from_image.Inverse()),
      tip_in_instrument_(tip_in_instrument),
      options_(options) {
  options_.Check();
  Require(!landmarks_.empty(), "LandmarkCheck: no landmark to check");
  for (const Landmark& l : landmarks_) {
    Require(l.in_image.allFinite(), "LandmarkCheck: landmark '" + l.name + "' is not finite");
  }
}

std::optional<LandmarkTouch> LandmarkCheck::Add(const NavigationState& state) {
  // Not on a reference still SETTLING (docs/navigation.md 1.2): like a frame without the tool.
  if (done() || !state.tool_from_instrument || state.reference_settling) return std::nullopt;
  const Eigen::Vector3d tip = image_from_tool_ * (*state.tool_from_instrument * tip_in_instrument_);
  if (!rest_.empty() && state.timestamp_s - rest_.back().t_s > options_.max_gap_s) rest_.clear();
  rest_.push_back({state.timestamp_s, tip});
  // The shortest run of samples that spans still_time_s.
  while (rest_.size() > 2 && rest_.back().t_s - rest_[1].t_s >= options_.still_time_s) {
    rest_.pop_front();
  }
  if (left_from_) {  // one rest, one touch: wait until the tip has left the last one
    constexpr double kLeaveWindowS = 0.2;
    std::vector<Eigen::Vector3d> recent;
    for (auto it = rest_.rbegin(); it != rest_.rend(); ++it) {
      if (rest_.back().t_s - it->t_s > kLeaveWindowS) break;
      recent.push_back(it->tip_in_image);
    }
    if ((MedianPoint(recent) - *left_from_).norm() < options_.leave_mm) return std::nullopt;
    left_from_.reset();
    rest_.erase(rest_.begin(), rest_.end() - 1);  // the rest starts now
  }
  if (rest_.size() < 3 || rest_.back().t_s - rest_.front().t_s < options_.still_time_s) {
    return std::nullopt;
  }
  std::vector<Eigen::Vector3d> tips;
  for (const Sample& s : rest_) tips.push_back(s.tip_in_image);
  const Eigen::Vector3d median = MedianPoint(tips);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int near = 0;
  for (const Eigen::Vector3d& p : tips) {
    if ((p - median).norm() > options_.still_radius_mm) continue;
    sum += p;
    ++near;
  }
  if (near < options_.still_fraction * static_cast<double>(tips.size())) return std::nullopt;
  const Eigen::Vector3d mean = sum / near;

  LandmarkTouch touch;
  touch.landmark = static_cast<int>(touches_.size());
  const Landmark& asked = landmarks_[static_cast<std::size_t>(touch.landmark)];
  touch.tip_in_image = mean;
  touch.error_in_image = mean - asked.in_image;
  touch.error_mm = touch.error_in_image.norm();
  touch.pass = touch.error_mm <= options_.pass_mm;
  touch.start_s = rest_.front().t_s;
  touch.end_s = rest_.back().t_s;
  touch.frames = near;
  std::size_t nearest = 0;
  for (std::size_t i = 1; i < landmarks_.size(); ++i) {
    if ((landmarks_[i].in_image - mean).norm() < (landmarks_[nearest].in_image - mean).norm()) {
      nearest = i;
    }
  }
  if (nearest != static_cast<std::size_t>(touch.landmark)) {
    touch.nearer_landmark = static_cast<int>(nearest);
  }
  touches_.push_back(touch);
  left_from_ = mean;
  return touch;
}

std::optional<int> LandmarkCheck::next() const {
  if (done()) return std::nullopt;
  return static_cast<int>(touches_.size());
}

bool LandmarkCheck::passed() const {
  return done() && std::all_of(touches_.begin(), touches_.end(),
                               [](const LandmarkTouch& t) { return t.pass; });
}

double LandmarkCheck::max_error_mm() const {
  double worst = 0.0;
  for (const LandmarkTouch& t : touches_) worst = std::max(worst, t.error_mm);
  return worst;
}

std::string LandmarkCheck::StatusLine() const {
  std::string line;
  if (!done()) {
    const auto n = static_cast<std::size_t>(*next());
    line = "verify: touch " + landmarks_[n].name + " (" + std::to_string(n + 1) + " of " +
           std::to_string(landmarks_.size()) + ")";
    if (!touches_.empty()) {
      const LandmarkTouch& last = touches_.back();
      line += "; " + landmarks_[static_cast<std::size_t>(last.landmark)].name + " " +
              Mm(last.error_mm) + (last.pass ? " ok" : " TOO FAR");
    }
    return line;
  }
  line = std::string(passed() ? "verify PASSED" : "verify FAILED") + ": largest error " +
         Mm(max_error_mm()) + " (limit " + Mm(options_.pass_mm) + ")";
  for (const LandmarkTouch& t : touches_) {
    if (!t.pass)
      line += "; " + landmarks_[static_cast<std::size_t>(t.landmark)].name + " " + Mm(t.error_mm);
  }
  return line;
}

}  // namespace tofnav
