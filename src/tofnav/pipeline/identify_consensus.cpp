// SPDX-License-Identifier: BSD-3-Clause
// The identification's consensus over leave-a-tenth-out runs (docs/correction.md 2.9).
#include "tofnav/pipeline/identify_consensus.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace tofnav {
namespace {

constexpr double kRangeTermAtMm = 500.0;  // C2's effect compared at the middle of AHAT's range
constexpr int kTenths = 10;               // issue 40 item 2: a tenth of the frames left out

// The medoid among models[i] for i in `members`: least sum of distances, ties to the first.
std::size_t MedoidOf(const std::vector<DepthErrorModel>& models,
                     const std::vector<std::size_t>& members) {
  std::size_t best = members.front();
  double best_sum = std::numeric_limits<double>::infinity();
  for (const std::size_t i : members) {
    double sum = 0.0;
    for (const std::size_t j : members) sum += ModelDistanceMm(models[i], models[j]);
    if (sum < best_sum) {
      best_sum = sum;
      best = i;
    }
  }
  return best;
}

// A model as the coordinates ModelDistanceMm measures: C1, C2 x 500 mm, C3, C4 and the cyclic
// error's in-phase and quadrature amplitudes (all mm).
using ModelPoint = std::array<double, 6>;

ModelPoint PointOf(const DepthErrorModel& m) {
  return {m.c1_mm,
          m.c2 * kRangeTermAtMm,
          m.c3_mm,
          m.c4_mm,
          m.cyclic.amplitude_mm * std::cos(m.cyclic.phase_rad),
          m.cyclic.amplitude_mm * std::sin(m.cyclic.phase_rad)};
}

double SquaredDistance(const ModelPoint& a, const ModelPoint& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return sum;
}

}  // namespace

double ModelDistanceMm(const DepthErrorModel& a, const DepthErrorModel& b) {
  const DepthErrorModel b_at_a = b.WithReferences(a.theta_reference_rad, a.ab_reference);
  const double dc1 = a.c1_mm - b_at_a.c1_mm;
  const double dc2 = (a.c2 - b.c2) * kRangeTermAtMm;
  const double dc3 = a.c3_mm - b.c3_mm;
  const double dc4 = a.c4_mm - b.c4_mm;
  // The cyclic error A sin(2 pi d / P + phi) as its two quadrature amplitudes (same period).
  const double di = a.cyclic.amplitude_mm * std::cos(a.cyclic.phase_rad) -
                    b.cyclic.amplitude_mm * std::cos(b.cyclic.phase_rad);
  const double dq = a.cyclic.amplitude_mm * std::sin(a.cyclic.phase_rad) -
                    b.cyclic.amplitude_mm * std::sin(b.cyclic.phase_rad);
  return std::sqrt(dc1 * dc1 + dc2 * dc2 + dc3 * dc3 + dc4 * dc4 + di * di + dq * dq);
}

std::size_t MedoidIndex(const std::vector<DepthErrorModel>& models) {
  if (models.empty()) throw std::invalid_argument("MedoidIndex: no models");
  std::vector<std::size_t> all(models.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return MedoidOf(models, all);
}

ConsensusJackknife JackknifeMedoid(const std::vector<DepthErrorModel>& models) {
  const std::size_t kept = MedoidIndex(models);
  const DepthErrorModel& m = models[kept];
  ConsensusJackknife out;
  for (std::size_t left = 1; left < models.size(); ++left) {
    std::vector<std::size_t> rest;
    for (std::size_t i = 0; i < models.size(); ++i) {
      if (i != left) rest.push_back(i);
    }
    const std::size_t k = MedoidOf(models, rest);
    out.kept_without_run.push_back(k);
    const double c1 = models[k].WithReferences(m.theta_reference_rad, m.ab_reference).c1_mm;
    out.max_c1_change_mm = std::max(out.max_c1_change_mm, std::abs(c1 - m.c1_mm));
  }
  return out;
}

DepthErrorModel ConsensusMean(const std::vector<DepthErrorModel>& models) {
  const DepthErrorModel& medoid = models.at(MedoidIndex(models));
  std::vector<ModelPoint> points;
  bool same_period = true;
  for (const DepthErrorModel& m : models) {
    points.push_back(PointOf(m.WithReferences(medoid.theta_reference_rad, medoid.ab_reference)));
    same_period = same_period && m.cyclic.period_mm == medoid.cyclic.period_mm;
  }
  // Mean shift from the medoid: each step the weighted mean with the weights at the last centre.
  // It converges to the nearest mode of the runs' Gaussian density; 1e-9 mm is far below any
  // figure it feeds, and 200 steps far more than the few it takes (the runs lie within a scale).
  constexpr double kConvergedMm = 1e-9;
  constexpr int kMaxSteps = 200;
  const double inv_two_s2 = 1.0 / (2.0 * kConsensusScaleMm * kConsensusScaleMm);
  ModelPoint centre = PointOf(medoid);
  for (int step = 0; step < kMaxSteps; ++step) {
    ModelPoint next{};
    double total = 0.0;
    for (const ModelPoint& p : points) {
      const double w = std::exp(-SquaredDistance(p, centre) * inv_two_s2);
      total += w;
      for (std::size_t i = 0; i < p.size(); ++i) next[i] += w * p[i];
    }
    // total > 0: the centre never leaves the runs (it starts on one and moves to weighted means).
    for (double& v : next) v /= total;
    const double moved = std::sqrt(SquaredDistance(next, centre));
    centre = next;
    if (moved < kConvergedMm) break;
  }
  DepthErrorModel out = medoid;
  out.c1_mm = centre[0];
  out.c2 = centre[1] / kRangeTermAtMm;
  out.c3_mm = centre[2];
  out.c4_mm = centre[3];
  if (same_period && medoid.cyclic.amplitude_mm > 0.0) {
    out.cyclic.amplitude_mm = std::hypot(centre[4], centre[5]);
    out.cyclic.phase_rad = std::atan2(centre[5], centre[4]);
  }
  out.Check();
  return out;
}

ConsensusMeanJackknife JackknifeMean(const std::vector<DepthErrorModel>& models) {
  const DepthErrorModel all = ConsensusMean(models);
  ConsensusMeanJackknife out;
  for (std::size_t left = 1; left < models.size(); ++left) {
    std::vector<DepthErrorModel> rest;
    for (std::size_t i = 0; i < models.size(); ++i) {
      if (i != left) rest.push_back(models[i]);
    }
    out.without_run.push_back(ConsensusMean(rest));
    const double c1 =
        out.without_run.back().WithReferences(all.theta_reference_rad, all.ab_reference).c1_mm;
    out.max_c1_change_mm = std::max(out.max_c1_change_mm, std::abs(c1 - all.c1_mm));
  }
  return out;
}

const IdentifyRecordingResult& IdentifyConsensusResult::Run(std::size_t i) const {
  return i == 0 ? full : subsets.at(i - 1);
}

std::vector<DepthErrorModel> IdentifyConsensusResult::Models() const {
  std::vector<DepthErrorModel> models{full.file.model};
  for (const IdentifyRecordingResult& s : subsets) models.push_back(s.file.model);
  return models;
}

BasinCheck CheckBasins(const std::vector<std::optional<MergedPlacement>>& placements,
                       const std::vector<double>& inlier_fractions) {
  if (placements.size() != inlier_fractions.size()) {
    throw std::invalid_argument("CheckBasins: one inlier fraction per placement");
  }
  BasinCheck out;
  for (std::size_t i = 0; i < placements.size(); ++i) {
    if (placements[i] && (!out.best || inlier_fractions[i] > inlier_fractions[*out.best]))
      out.best = i;
  }
  if (!out.best) return out;
  for (std::size_t i = 0; i < placements.size(); ++i) {
    if (placements[i] && PlacementsDiffer(*placements[i], *placements[*out.best]))
      out.elsewhere.push_back(i);
  }
  return out;
}

MinimumCheck CheckMinima(const std::vector<DepthErrorModel>& models) {
  if (models.empty()) throw std::invalid_argument("CheckMinima: no models");
  const auto cost_per_frame = [](const DepthErrorModel& m) {
    return m.report.final_cost / std::max(1, m.report.frames_used);
  };
  MinimumCheck out;
  for (std::size_t i = 1; i < models.size(); ++i) {
    if (cost_per_frame(models[i]) < cost_per_frame(models[out.best])) out.best = i;
  }
  for (std::size_t i = 0; i < models.size(); ++i) {
    if (ModelDistanceMm(models[i], models[out.best]) > kOtherMinimumMm) out.elsewhere.push_back(i);
  }
  return out;
}

IdentifyConsensusResult IdentifyWithConsensus(
    const AhatRecording& recording, const AhatCamera& camera,
    const std::optional<MarkerRangeModel>& marker_range, const SurfaceIndex* skin,
    const IdentifyRecordingOptions& options, int subsets,
    const std::function<void(int, int, std::size_t, std::size_t)>& progress) {
  if (subsets < 0 || subsets > kTenths) {
    throw std::invalid_argument("consensus: " + std::to_string(subsets) +
                                " subsets; 0 to 10 (each leaves a tenth out)");
  }
  const int runs = subsets + 1;
  const auto report = [&](int run) {
    return [&progress, run, runs](std::size_t done, std::size_t total) {
      if (progress) progress(run, runs, done, total);
    };
  };
  IdentifyRecordingOptions run_options = options;
  // Run 0 on every picked frame, run k + 1 without the frames j with j % 10 == k.
  const auto identify = [&](std::size_t run) {
    run_options.leave_out.reset();
    if (run > 0) run_options.leave_out = FrameLeaveOut{static_cast<int>(run) - 1, kTenths};
    return IdentifyFromRecording(recording, camera, marker_range, skin, run_options,
                                 report(static_cast<int>(run)));
  };
  IdentifyConsensusResult out;
  out.full = identify(0);
  for (int k = 0; k < subsets; ++k)
    out.subsets.push_back(identify(static_cast<std::size_t>(k) + 1));
  // One basin for every run: a run whose first placement of the skin lies elsewhere than the
  // best-kept one's (by the figure each run chose its own with) is identified again with that
  // placement among its candidates (docs/correction.md 2.13).
  std::vector<std::optional<MergedPlacement>> placements;
  std::vector<double> inliers;
  for (std::size_t i = 0; i <= out.subsets.size(); ++i) {
    placements.push_back(out.Run(i).placement);
    inliers.push_back(out.Run(i).icp_inlier_fraction);
  }
  const BasinCheck basins = CheckBasins(placements, inliers);
  if (basins.best) {
    run_options.placement_guesses = {*placements[*basins.best]};
    for (const std::size_t i : basins.elsewhere) {
      (i == 0 ? out.full : out.subsets[i - 1]) = identify(i);
      out.identified_again.push_back(i);
    }
  }
  // One minimum: a run that ended far from the least-cost run's model is identified again from
  // it, and keeps the answer that costs less on its own frames (docs/correction.md 2.14).
  const MinimumCheck minima = CheckMinima(out.Models());
  if (!minima.elsewhere.empty()) {
    const IdentifyRecordingResult& best = out.Run(minima.best);
    run_options.joint_start = best.file.model;
    run_options.placement_guesses.clear();
    if (best.placement) run_options.placement_guesses = {*best.placement};
    for (const std::size_t i : minima.elsewhere) {
      IdentifyRecordingResult again = identify(i);
      IdentifyRecordingResult& run = i == 0 ? out.full : out.subsets[i - 1];
      out.restarted.push_back(i);
      if (again.file.model.report.final_cost < run.file.model.report.final_cost) {
        run = std::move(again);
        out.restart_kept.push_back(i);
      }
    }
  }
  out.kept = MedoidIndex(out.Models());
  return out;
}

}  // namespace tofnav
