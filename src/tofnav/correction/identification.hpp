// SPDX-License-Identifier: BSD-3-Clause
// Patient-specific identification of the depth-error model (Eq. 7) and model comparison.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/correction/identification_screening.hpp"
#include "tofnav/correction/levenberg_marquardt.hpp"
#include "tofnav/correction/surface_costs.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

/// The CT skin and where each frame's camera roughly is in it: what Err_C (Eq. 5) needs.
struct CorrectnessTarget {
  const SurfaceIndex* skin_in_image = nullptr;
  /// image_from_ahat guess per identification frame (same order), nullopt where unknown.
  std::vector<std::optional<Rigid3d>> image_from_ahat;
};

struct IdentificationOptions {
  /// Sticker thickness: marker points lie this far outside the skin [mm] (both costs).
  double marker_thickness_mm = 0.0;
  /// Huber scale of the point distances [mm]; 0 = plain least squares.
  double huber_scale_mm = 1.0;
  /// Frames (evenly chosen among those with a guess) that run an ICP per evaluation for Err_C;
  /// their sum is re-weighted to count as much as all frames' Err_S would.
  int max_correctness_frames = 12;
  /// Beyond the paper: the start is re-expressed (exactly) at the head samples' median incidence
  /// and, with the intensity term, median AB before the fit, so that C1 is the bias at the data's
  /// centre: at theta = 0 and a fixed AB it is an extrapolation that moves with C3 and C4 along
  /// their collinear direction (docs/correction.md 2.7). false keeps the start's references.
  bool centre_references = true;
  /// Beyond the paper: after a first fit, drop the markers whose median Eq. (6) distance lies
  /// beyond max(marker_outlier_spreads x 1.4826 MAD, min_marker_outlier_mm) of the others' (not
  /// on the skin: a tool's marker on its plate, a sticker on hair) and fit again.
  bool reject_outlier_markers = true;
  double marker_outlier_spreads = 3.0;
  double min_marker_outlier_mm = 2.0;
  /// Beyond the paper: head points and frames of transient foreground (a hand) left out first.
  ForegroundScreeningOptions foreground;
  /// Marker observations whose centres lie this close in `world` are one marker (the report's
  /// per-marker counts) [mm]; stickers are placed farther apart than this.
  double marker_group_radius_mm = 10.0;
  CorrectnessOptions correctness;
  /// Beyond the paper: when at least min_tool_pose_frames correctness frames have a reference-
  /// tool pose, Err_C places the skin once through the tool (JointCorrectnessDistances) and adds
  /// each frame's head samples' distances to the skin, weighted by this relative to its markers'
  /// (docs/correction.md 2; 1 since the intensity form, 2.1). 0 keeps the markers only.
  int min_tool_pose_frames = 3;
  double head_surface_weight = 1.0;
  /// Beyond the paper: Err_S's weight in Eq. (7) when Err_C runs through the reference tool. A
  /// sticker's Eq. (6) distance carries the skin's shape under it against the cubic through its
  /// 30 mm ring (-1.0 to +2.2 mm on the simulator's heads, from their true ranges), which Eq. (5)
  /// does not: it measures the same stickers against the CT's own skin (docs/correction.md 2.11).
  /// 1 weighs them as the paper does.
  double joint_smoothness_weight = 0.3;
  /// Frames (evenly chosen among those with a tool pose) in the joint Err_C: one ICP for them
  /// all per evaluation, so more frames than max_correctness_frames cost little, and they
  /// average the tracking noise of each frame's pose.
  int max_joint_correctness_frames = 30;
  /// Frames whose head samples, once placed through the tool, lie farther from the skin than
  /// this (median) leave Err_C: a wrong tool pose, or no head [mm].
  double joint_frame_max_median_mm = 3.0;
  /// Beyond the paper: when > 0, the sensor's cyclic error w(d) = A sin(2 pi d / P + phi) at
  /// this period P [mm] is fitted with the coefficients (two more parameters: A cos phi and
  /// A sin phi); 0 holds the start model's cyclic error fixed (docs/correction.md 2.2).
  double fit_cyclic_period_mm = 0.0;
  LevenbergMarquardtOptions lm;
  /// Central-difference steps of C1 [mm], C2 [1], C3 [mm per unit g], C4 [mm]; the cyclic
  /// error's two components take C1's.
  std::vector<double> difference_steps = {0.05, 1e-4, 0.05, 0.05};
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct IdentificationCost {
  double total = 0.0;  // Eq. (7) (robust) [mm^2]
  std::vector<FrameResidual> frames;
};

/// Eq. (7) minimised over the model's coefficients, starting from `start` (which also fixes the
/// variant: angle term, intensity term). Without a target (or a skin) only Err_S is used.
/// The result carries its fit report (per-frame residuals, standard errors, costs, time).
/// Throws std::invalid_argument when no frame has a usable marker patch.
DepthErrorModel IdentifyDepthModel(std::span<const IdentificationFrame> frames,
                                   const CorrectnessTarget* target, const DepthErrorModel& start,
                                   const IdentificationOptions& options = {});

/// Eq. (7) and the per-frame terms for a given model (ICPs from the target's guesses).
IdentificationCost EvaluateIdentificationCost(std::span<const IdentificationFrame> frames,
                                              const CorrectnessTarget* target,
                                              const DepthErrorModel& model,
                                              const IdentificationOptions& options = {});

/// Beyond the paper: each candidate variant identified on all but one of `folds` contiguous
/// blocks of frames and scored by Err_S (Eq. 6, plain RMS over markers, no robust loss) on the
/// held-out block; returns (name, mean held-out Err_S^2 [mm^2]) per candidate, in order.
std::vector<std::pair<std::string, double>> CrossValidateModels(
    std::span<const IdentificationFrame> frames, const CorrectnessTarget* target,
    std::span<const DepthErrorModel> candidates, int folds,
    const IdentificationOptions& options = {});

/// The candidates compared by default: theta (paper), theta^2, 1 - cos theta, theta + AB term.
std::vector<DepthErrorModel> DefaultModelCandidates();

}  // namespace tofnav
