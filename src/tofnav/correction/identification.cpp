// SPDX-License-Identifier: BSD-3-Clause
// Patient-specific identification of the depth-error model (Eq. 7) and model comparison.
#include "tofnav/correction/identification.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/correction/joint_correctness.hpp"

namespace tofnav {
namespace {

// sign(d) sqrt(2 rho(d)) with the Huber rho: squares to the robust cost.
double Robust(double d, double scale) {
  const double a = std::abs(d);
  if (scale <= 0.0 || a <= scale) return d;
  return std::copysign(std::sqrt(scale * (2.0 * a - scale)), d);
}

// The frames taking part in Err_C with their ICP start poses (refined once at `start`); with
// enough reference-tool poses, one placement of the skin for them all (docs/correction.md 2).
struct CorrectnessPlan {
  std::vector<int> frames;
  std::vector<Rigid3d> guesses;
  std::optional<Rigid3d> image_from_tool;
  double weight = 1.0;  // sqrt of (frames with Err_S) / (frames with Err_C)
};

CorrectnessPlan PlanCorrectness(std::span<const IdentificationFrame> frames,
                                const CorrectnessTarget* target, const DepthErrorModel& start,
                                const IdentificationOptions& options) {
  CorrectnessPlan plan;
  if (!target || !target->skin_in_image) return plan;
  if (target->image_from_ahat.size() != frames.size()) {
    throw std::invalid_argument("CorrectnessTarget: one image_from_ahat guess per frame");
  }
  std::vector<int> usable, with_tool;
  int smooth_frames = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!frames[i].markers.empty()) ++smooth_frames;
    if (!target->image_from_ahat[i] || frames[i].head.size() < 50) continue;
    if (!frames[i].marker_points.empty()) usable.push_back(static_cast<int>(i));
    if (frames[i].tool_from_ahat) with_tool.push_back(static_cast<int>(i));
  }
  bool joint =
      options.min_tool_pose_frames > 0 && std::ssize(with_tool) >= options.min_tool_pose_frames;
  if (joint) usable = std::move(with_tool);
  const int count = joint ? options.max_joint_correctness_frames : options.max_correctness_frames;
  for (int k : EvenSubsample(static_cast<int>(usable.size()), count)) {
    plan.frames.push_back(usable[static_cast<std::size_t>(k)]);
  }
  plan.guesses.resize(plan.frames.size());
  CorrectnessOptions coarse = options.correctness;
  coarse.icp.max_distance_schedule_mm = {15.0, 8.0, 4.0};
  ParallelFor(0, static_cast<std::int64_t>(plan.frames.size()), [&](std::int64_t i) {
    const auto f = static_cast<std::size_t>(plan.frames[static_cast<std::size_t>(i)]);
    plan.guesses[static_cast<std::size_t>(i)] =
        CorrectnessDistances(frames[f], start, *target->skin_in_image, *target->image_from_ahat[f],
                             coarse)
            .image_from_ahat;
  });
  if (joint && !plan.frames.empty()) {
    const std::optional<Rigid3d> mean = MeanImageFromTool(frames, plan.frames, plan.guesses);
    const JointCorrectness placed = JointCorrectnessDistances(
        frames, plan.frames, start, *target->skin_in_image, *mean, coarse);
    // A frame whose head lies far from the skin once placed has a wrong tool pose (a plate
    // matched to the other's markers) or no head: it leaves Err_C, and the rest are placed again.
    std::vector<int> kept;
    std::vector<Rigid3d> kept_guesses;
    for (std::size_t c = 0; c < plan.frames.size(); ++c) {
      std::vector<double> d = placed.head_distances[c];
      for (double& x : d) x = std::abs(x);
      if (MedianSpread(std::move(d)).first <= options.joint_frame_max_median_mm) {
        kept.push_back(plan.frames[c]);
        kept_guesses.push_back(plan.guesses[c]);
      }
    }
    if (std::ssize(kept) >= options.min_tool_pose_frames) {
      plan.frames = std::move(kept);
      plan.guesses = std::move(kept_guesses);
      plan.image_from_tool =
          JointCorrectnessDistances(frames, plan.frames, start, *target->skin_in_image,
                                    placed.image_from_tool, coarse)
              .image_from_tool;
    } else {
      joint = false;  // too few frames agree with their tool pose: each frame on its own
    }
  }
  if (!plan.frames.empty()) {
    plan.weight = std::sqrt(std::max(1.0, static_cast<double>(smooth_frames)) /
                            static_cast<double>(plan.frames.size()));
  }
  return plan;
}

// Appends plan weight x Huber(d - thickness) / sqrt(n) of each distance; returns their plain RMS.
double AppendCorrectness(std::vector<double> distances, double thickness_mm, double weight,
                         double huber_mm, std::vector<double>& out) {
  for (double& x : distances) x -= thickness_mm;
  const double n = static_cast<double>(distances.size());
  for (double d : distances) out.push_back(weight * Robust(d, huber_mm) / std::sqrt(n));
  return Rms(distances);
}

struct Evaluation {
  std::vector<std::vector<double>> smooth;   // per frame: robust, weighted residuals
  std::vector<std::vector<double>> correct;  // per correctness frame
  std::vector<FrameResidual> report;
};

// What one minimisation's evaluations keep for the next (each figure is exactly that without it):
// the joint ICP's nearest-neighbour answers and, per frame and marker, the neighbours' ranges
// with the cyclic error removed.
struct EvaluationCaches {
  IcpNeighbourCache icp;
  std::vector<std::vector<DecycledRanges>> patches;  // [frame][marker]
  explicit EvaluationCaches(std::span<const IdentificationFrame> frames) {
    for (const IdentificationFrame& f : frames) patches.emplace_back(f.markers.size());
  }
};

Evaluation Evaluate(std::span<const IdentificationFrame> frames, const CorrectnessTarget* target,
                    const CorrectnessPlan& plan, const DepthErrorModel& model,
                    const IdentificationOptions& options, EvaluationCaches* caches = nullptr) {
  Evaluation e;
  e.smooth.resize(frames.size());
  e.correct.resize(plan.frames.size());
  e.report.resize(frames.size());
  const double h = options.huber_scale_mm;
  // Err_S beside the joint Err_C: weighed by what its geometry can tell (docs/correction.md 2.11).
  const double smooth_weight = plan.image_from_tool ? options.joint_smoothness_weight : 1.0;
  ParallelFor(0, static_cast<std::int64_t>(frames.size()), [&](std::int64_t fi) {
    const auto f = static_cast<std::size_t>(fi);
    const IdentificationFrame& frame = frames[f];
    FrameResidual& rep = e.report[f];
    rep.frame = frame.index;
    const double k = static_cast<double>(frame.markers.size());
    double sum_sq = 0.0;
    for (std::size_t p = 0; p < frame.markers.size(); ++p) {
      const MarkerPatch& patch = frame.markers[p];
      std::vector<double> d =
          SmoothnessDistances(patch, model, caches != nullptr ? &caches->patches[f][p] : nullptr);
      for (double& x : d) x -= options.marker_thickness_mm;
      const double n = static_cast<double>(patch.marker_points.size());
      for (std::size_t i = 0; i < patch.marker_points.size(); ++i) {
        // A singular fit keeps the residual count: count it as one scale away.
        const double di = i < d.size() ? d[i] : h;
        e.smooth[f].push_back(smooth_weight * Robust(di, h) / std::sqrt(n * k));
      }
      const double rms = Rms(d);
      sum_sq += rms * rms;
      ++rep.markers;
    }
    if (rep.markers > 0) rep.err_s_mm = std::sqrt(sum_sq / rep.markers);
  });
  const double thickness = options.marker_thickness_mm;
  if (plan.image_from_tool) {
    const JointCorrectness joint = JointCorrectnessDistances(
        frames, plan.frames, model, *target->skin_in_image, *plan.image_from_tool,
        options.correctness, caches != nullptr ? &caches->icp : nullptr);
    for (std::size_t c = 0; c < plan.frames.size(); ++c) {
      const auto f = static_cast<std::size_t>(plan.frames[c]);
      if (!joint.marker_distances[c].empty()) {
        e.report[f].err_c_mm =
            AppendCorrectness(joint.marker_distances[c], thickness, plan.weight, h, e.correct[c]);
      }
      AppendCorrectness(joint.head_distances[c], 0.0, plan.weight * options.head_surface_weight, h,
                        e.correct[c]);
    }
    return e;
  }
  ParallelFor(0, static_cast<std::int64_t>(plan.frames.size()), [&](std::int64_t ci) {
    const auto c = static_cast<std::size_t>(ci);
    const auto f = static_cast<std::size_t>(plan.frames[c]);
    CorrectnessFrame result = CorrectnessDistances(frames[f], model, *target->skin_in_image,
                                                   plan.guesses[c], options.correctness);
    e.report[f].err_c_mm =
        AppendCorrectness(std::move(result.distances), thickness, plan.weight, h, e.correct[c]);
  });
  return e;
}

Eigen::VectorXd Flatten(const Evaluation& e) {
  std::size_t n = 0;
  for (const auto& v : e.smooth) n += v.size();
  for (const auto& v : e.correct) n += v.size();
  Eigen::VectorXd r(static_cast<Eigen::Index>(n));
  Eigen::Index i = 0;
  for (const auto& v : e.smooth) {
    for (double x : v) r(i++) = x;
  }
  for (const auto& v : e.correct) {
    for (double x : v) r(i++) = x;
  }
  return r;
}

// `start` at the median incidence and AB of the frames' head samples (the marker patches' head
// neighbours where no frame has head samples): where its C1 is well determined.
DepthErrorModel AtSampleCentre(std::span<const IdentificationFrame> frames,
                               const DepthErrorModel& start) {
  std::vector<double> theta, ab;
  auto add = [&](const SurfaceSample& s) {
    if (std::isfinite(s.incidence_rad)) theta.push_back(s.incidence_rad);
    if (std::isfinite(s.ab) && s.ab > 0.0f) ab.push_back(s.ab);
  };
  for (const IdentificationFrame& f : frames) std::ranges::for_each(f.head, add);
  if (theta.empty()) {
    for (const IdentificationFrame& f : frames) {
      for (const MarkerPatch& p : f.markers) std::ranges::for_each(p.neighbours, add);
    }
  }
  if (theta.empty()) return start;
  const double theta_ref = std::clamp(Median(theta), 0.0, 0.5 * std::numbers::pi);
  const double ab_ref =
      start.use_intensity && !ab.empty() ? std::max(Median(ab), 1.0) : start.ab_reference;
  return start.WithReferences(theta_ref, ab_ref);
}

struct Fit {
  DepthErrorModel model;  // coefficients only (no report)
  LevenbergMarquardtResult lm;
  Evaluation final_eval;
  bool correctness = false;  // Err_C took part
  bool joint = false;        // through the reference tool, with the head surface
};

// One Levenberg-Marquardt minimisation of Eq. (7) from `start`: over the model's coefficients and,
// with options.fit_cyclic_period_mm, the cyclic error's two components (appended).
Fit FitOnce(std::span<const IdentificationFrame> frames, const CorrectnessTarget* target,
            const DepthErrorModel& start, const IdentificationOptions& options) {
  const CorrectnessPlan plan = PlanCorrectness(frames, target, start, options);
  std::vector<double> p0 = ModelParameters(start);
  const std::vector<double>& d = options.difference_steps;
  std::vector<double> step_values = FreeParameterValues(start, {d[0], d[1], d[2], d[3]});
  const std::size_t coefficient_count = p0.size();
  const double period = options.fit_cyclic_period_mm;
  if (period > 0.0) {
    const CyclicRangeError& c = start.cyclic;
    const bool same = c.enabled() && std::abs(c.period_mm - period) < 1e-9 * period;
    p0.push_back(same ? c.amplitude_mm * std::cos(c.phase_rad) : 0.0);
    p0.push_back(same ? c.amplitude_mm * std::sin(c.phase_rad) : 0.0);
    step_values.insert(step_values.end(), 2, d[0]);
  }
  const Eigen::VectorXd x0 = Eigen::Map<const Eigen::VectorXd>(p0.data(), std::ssize(p0));
  const Eigen::VectorXd steps =
      Eigen::Map<const Eigen::VectorXd>(step_values.data(), std::ssize(step_values));
  auto model_of = [&](const Eigen::VectorXd& x) {
    DepthErrorModel m = start;
    const auto n = static_cast<Eigen::Index>(coefficient_count);
    SetModelParameters(m, std::vector<double>(x.data(), x.data() + n));
    if (period > 0.0) {
      m.cyclic = {std::hypot(x(n), x(n + 1)), period, std::atan2(x(n + 1), x(n))};
    }
    return m;
  };
  EvaluationCaches caches(frames);  // the evaluations run one after another
  auto residuals = [&](const Eigen::VectorXd& x) {
    DepthErrorModel m = model_of(x);
    if (!(m.c2 > -0.5)) m.c2 = -0.5;  // keeps Eq. (4) finite while the optimiser explores
    return Flatten(Evaluate(frames, target, plan, m, options, &caches));
  };
  Fit fit;
  fit.lm = MinimiseLeastSquares(residuals, x0, steps, options.lm);
  fit.model = model_of(fit.lm.parameters);
  fit.model.report = {};
  fit.final_eval = Evaluate(frames, target, plan, fit.model, options, &caches);
  fit.correctness = !plan.frames.empty();
  fit.joint = plan.image_from_tool.has_value();
  return fit;
}

}  // namespace

void IdentificationOptions::Check() const {
  if (!(huber_scale_mm >= 0.0) || !(std::abs(marker_thickness_mm) < 10.0) ||
      max_correctness_frames < 0 || max_joint_correctness_frames < 0 ||
      difference_steps.size() != 4 || !(marker_outlier_spreads > 0.0) ||
      !(min_marker_outlier_mm >= 0.0) || !(head_surface_weight >= 0.0) ||
      !(joint_smoothness_weight >= 0.0) || !(joint_frame_max_median_mm > 0.0)) {
    throw std::invalid_argument(
        "IdentificationOptions: need huber_scale_mm >= 0, max_correctness_frames >= 0, four "
        "difference_steps, marker_outlier_spreads > 0, min_marker_outlier_mm >= 0, "
        "head_surface_weight >= 0, joint_smoothness_weight >= 0 and joint_frame_max_median_mm > 0");
  }
  for (double s : difference_steps) {
    if (!(s > 0.0)) throw std::invalid_argument("IdentificationOptions: difference_steps > 0");
  }
  if (!(marker_group_radius_mm > 0.0)) {
    throw std::invalid_argument("IdentificationOptions: marker_group_radius_mm > 0");
  }
  if (!(fit_cyclic_period_mm >= 0.0) || !std::isfinite(fit_cyclic_period_mm)) {
    throw std::invalid_argument("IdentificationOptions: fit_cyclic_period_mm finite and >= 0");
  }
  foreground.Check();
  correctness.Check();
  lm.Check();
}

IdentificationCost EvaluateIdentificationCost(std::span<const IdentificationFrame> frames,
                                              const CorrectnessTarget* target,
                                              const DepthErrorModel& model,
                                              const IdentificationOptions& options) {
  options.Check();
  model.Check();
  CorrectnessPlan plan = PlanCorrectness(frames, target, model, options);
  const Evaluation e = Evaluate(frames, target, plan, model, options);
  return {Flatten(e).squaredNorm(), e.report};
}

DepthErrorModel IdentifyDepthModel(std::span<const IdentificationFrame> frames,
                                   const CorrectnessTarget* target, const DepthErrorModel& start,
                                   const IdentificationOptions& options) {
  options.Check();
  start.Check();
  const auto t0 = std::chrono::steady_clock::now();
  ForegroundScreeningReport screening;
  const std::vector<IdentificationFrame> screened =
      ScreenForeground(frames, start, options.foreground, screening);
  int patches = 0, frames_used = 0;
  for (const IdentificationFrame& f : screened) {
    patches += static_cast<int>(f.markers.size());
    frames_used += f.markers.empty() && f.head.empty() ? 0 : 1;
  }
  if (patches == 0) {
    throw std::invalid_argument(
        screening.marker_patches_left_out > 0
            ? "IdentifyDepthModel: every marker patch was screened out as foreground"
            : "IdentifyDepthModel: no frame has a marker with head around it");
  }
  Fit fit = FitOnce(screened, target,
                    options.centre_references ? AtSampleCentre(screened, start) : start, options);
  const double initial_cost = fit.lm.initial_cost;
  int evaluations = fit.lm.evaluations, rejected = 0;
  std::vector<std::vector<char>> rejected_flags;
  if (options.reject_outlier_markers) {
    const std::vector<IdentificationFrame> kept =
        WithoutOutlierMarkers(screened, fit.model,
                              {options.marker_thickness_mm, options.marker_outlier_spreads,
                               options.min_marker_outlier_mm},
                              rejected_flags);
    for (const auto& v : rejected_flags)
      rejected += static_cast<int>(std::count(v.begin(), v.end(), 1));
    if (rejected > 0 && rejected < patches) {
      fit = FitOnce(kept, target, fit.model, options);
      evaluations += fit.lm.evaluations;
    } else {
      rejected = 0;  // every marker would go: keep the first fit, rejecting none
      rejected_flags.clear();
    }
  }
  DepthErrorModel model = fit.model;
  DepthModelFitReport& rep = model.report;
  rep = {};
  rep.method = "levenberg-marquardt";
  rep.costs = !fit.correctness ? "smoothness"
              : fit.joint      ? "correctness+head-surface+smoothness"
                               : "correctness+smoothness";
  rep.frames_used = frames_used;
  rep.frames_left_out = screening.frames_left_out;
  rep.head_points_left_out = screening.head_points_left_out;
  rep.marker_patches_screened_out = screening.marker_patches_left_out;
  for (const IdentificationFrame& f : frames) rep.marker_observations_curved += f.curved_markers;
  rep.marker_observations = patches;
  rep.marker_observations_rejected = rejected;
  const std::vector<std::vector<int>> ids =
      GroupMarkerObservations(screened, options.marker_group_radius_mm, rep.markers);
  for (std::size_t f = 0; f < rejected_flags.size(); ++f) {
    for (std::size_t k = 0; k < rejected_flags[f].size(); ++k) {
      if (rejected_flags[f][k]) ++rep.markers[static_cast<std::size_t>(ids[f][k])].rejected;
    }
  }
  rep.evaluations = evaluations;
  rep.initial_cost = 2.0 * initial_cost;
  rep.final_cost = 2.0 * fit.lm.final_cost;
  rep.standard_errors.assign(fit.lm.standard_errors.data(),
                             fit.lm.standard_errors.data() + fit.lm.standard_errors.size());
  rep.frames = std::move(fit.final_eval.report);
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return model;
}

}  // namespace tofnav
