// SPDX-License-Identifier: BSD-3-Clause
// Foreground screening of the identification frames and marker grouping (docs/correction.md,
// "Screening").
#include "tofnav/correction/identification_screening.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/correction/surface_costs.hpp"

namespace tofnav {
namespace {

using CellKey = std::int64_t;

// 21 bits a coordinate, clamped (a cell index beyond +-2^20 is kilometres away at 8 mm).
constexpr int kCellLimit = (1 << 20) - 1;

CellKey Key(const Eigen::Vector3i& c) {
  auto field = [](int v) {
    return static_cast<std::int64_t>(std::clamp(v, -kCellLimit, kCellLimit) + (1 << 20));
  };
  return (field(c.x()) << 42) | (field(c.y()) << 21) | field(c.z());
}

// Distinct frames seen in each cell's 3 x 3 x 3 neighbourhood, from per-cell frame bitsets.
// Written by hand: a sparse hash of bitsets is all it needs (no library grid counts distinct ids).
class SupportGrid {
 public:
  SupportGrid(double cell_mm, std::size_t frame_count)
      : cell_mm_(cell_mm), words_((frame_count + 63) / 64) {}

  void Add(std::size_t frame, const Eigen::Vector3d& p_world) {
    std::vector<std::uint64_t>& bits = occupied_[Key(CellOf(p_world))];
    if (bits.empty()) bits.assign(words_, 0);
    bits[frame / 64] |= std::uint64_t{1} << (frame % 64);
  }

  void Finish() {
    std::unordered_map<CellKey, std::vector<std::uint64_t>> dilated;
    for (const auto& [key, bits] : occupied_) {
      const Eigen::Vector3i c = Unkey(key);
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            std::vector<std::uint64_t>& acc = dilated[Key(c + Eigen::Vector3i(dx, dy, dz))];
            if (acc.empty()) acc.assign(words_, 0);
            for (std::size_t w = 0; w < words_; ++w) acc[w] |= bits[w];
          }
        }
      }
    }
    for (const auto& [key, bits] : dilated) {
      int n = 0;
      for (std::uint64_t w : bits) n += std::popcount(w);
      support_[key] = n;
    }
  }

  int Support(const Eigen::Vector3d& p_world) const {
    const auto it = support_.find(Key(CellOf(p_world)));
    return it == support_.end() ? 0 : it->second;
  }

 private:
  Eigen::Vector3i CellOf(const Eigen::Vector3d& p) const {
    return (p / cell_mm_).array().floor().cast<int>();
  }
  static Eigen::Vector3i Unkey(CellKey key) {
    auto field = [&](int shift) { return static_cast<int>((key >> shift) & 0x1FFFFF) - (1 << 20); };
    return {field(42), field(21), field(0)};
  }

  double cell_mm_;
  std::size_t words_;
  std::unordered_map<CellKey, std::vector<std::uint64_t>> occupied_;
  std::unordered_map<CellKey, int> support_;
};

struct Judge {
  const SupportGrid& grid;
  const ForegroundScreeningOptions& options;
  int well_observed = 0;  // frames

  // A point few frames see, in front of a neighbourhood many frames see along its ray.
  bool Foreground(const Eigen::Vector3d& p, const Eigen::Vector3d& camera) const {
    if (grid.Support(p) >= well_observed) return false;
    const Eigen::Vector3d ray = (p - camera).normalized();
    const double step = 0.5 * options.cell_mm;
    for (double t = 2.0 * options.cell_mm; t <= options.behind_search_mm; t += step) {
      if (grid.Support(p + t * ray) >= well_observed) return true;
    }
    return false;
  }
};

}  // namespace

void ForegroundScreeningOptions::Check() const {
  if (!(cell_mm > 0.0) || !(min_support_fraction >= 0.0 && min_support_fraction <= 1.0) ||
      min_support_frames < 1 || !(behind_search_mm > 0.0) ||
      !(max_frame_foreground_fraction >= 0.0) || !(max_patch_foreground_fraction >= 0.0)) {
    throw std::invalid_argument(
        "ForegroundScreeningOptions: need cell_mm > 0, min_support_fraction in [0, 1], "
        "min_support_frames >= 1, behind_search_mm > 0 and fractions >= 0");
  }
}

std::vector<IdentificationFrame> ScreenForeground(std::span<const IdentificationFrame> frames,
                                                  const DepthErrorModel& model,
                                                  const ForegroundScreeningOptions& options,
                                                  ForegroundScreeningReport& report) {
  options.Check();
  report = {};
  report.frames_in = static_cast<int>(frames.size());
  std::vector<IdentificationFrame> out(frames.begin(), frames.end());
  std::size_t posed = 0;
  for (const IdentificationFrame& f : frames) posed += f.world_from_ahat ? 1 : 0;
  report.frames_without_world_pose = static_cast<int>(frames.size() - posed);
  const int well_observed = std::max(
      options.min_support_frames,
      static_cast<int>(std::ceil(options.min_support_fraction * static_cast<double>(posed))));
  // Fewer posed frames than a well-observed surface needs: nothing can be judged.
  if (!options.enabled || static_cast<int>(posed) <= well_observed) return out;

  SupportGrid grid(options.cell_mm, frames.size());
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!frames[f].world_from_ahat) continue;
    const Rigid3d& world_from_ahat = *frames[f].world_from_ahat;
    for (const SurfaceSample& s : frames[f].head)
      grid.Add(f, world_from_ahat * CorrectedPoint(s, model));
  }
  grid.Finish();
  const Judge judge{grid, options, well_observed};

  std::vector<int> dropped_points(frames.size(), 0), dropped_patches(frames.size(), 0);
  std::vector<char> dropped_frame(frames.size(), 0);
  ParallelFor(0, static_cast<std::int64_t>(frames.size()), [&](std::int64_t fi) {
    const auto f = static_cast<std::size_t>(fi);
    IdentificationFrame& frame = out[f];
    if (!frame.world_from_ahat) return;
    const Rigid3d& world_from_ahat = *frame.world_from_ahat;
    const Eigen::Vector3d camera = world_from_ahat.translation;
    auto foreground = [&](const SurfaceSample& s) {
      return judge.Foreground(world_from_ahat * CorrectedPoint(s, model), camera);
    };
    const std::size_t before = frame.head.size();
    std::erase_if(frame.head, foreground);
    const std::size_t removed = before - frame.head.size();
    if (before > 0 && static_cast<double>(removed) >
                          options.max_frame_foreground_fraction * static_cast<double>(before)) {
      dropped_frame[f] = 1;
      dropped_patches[f] = static_cast<int>(frame.markers.size());
      frame.head.clear();
      frame.markers.clear();
      frame.marker_points.clear();
      return;
    }
    dropped_points[f] = static_cast<int>(removed);
    std::vector<MarkerPatch> kept;
    for (MarkerPatch& patch : frame.markers) {
      const auto bad = std::count_if(patch.neighbours.begin(), patch.neighbours.end(), foreground);
      if (static_cast<double>(bad) <=
          options.max_patch_foreground_fraction * static_cast<double>(patch.neighbours.size())) {
        kept.push_back(std::move(patch));
      } else {
        ++dropped_patches[f];
      }
    }
    frame.markers = std::move(kept);
  });
  for (std::size_t f = 0; f < frames.size(); ++f) {
    report.frames_left_out += dropped_frame[f];
    report.head_points_left_out += dropped_points[f];
    report.marker_patches_left_out += dropped_patches[f];
  }
  return out;
}

std::vector<std::vector<int>> GroupMarkerObservations(std::span<const IdentificationFrame> frames,
                                                      double radius_mm,
                                                      std::vector<StickerUse>& markers) {
  markers.clear();
  std::vector<Eigen::Vector3d> sums;
  std::vector<std::vector<int>> ids(frames.size());
  for (std::size_t f = 0; f < frames.size(); ++f) {
    for (const MarkerPatch& patch : frames[f].markers) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& p : patch.marker_points) centre += p;
      if (!patch.marker_points.empty()) centre /= static_cast<double>(patch.marker_points.size());
      if (frames[f].world_from_ahat) centre = *frames[f].world_from_ahat * centre;
      int best = -1;
      double best_mm = radius_mm;
      for (std::size_t m = 0; m < markers.size(); ++m) {
        const Eigen::Vector3d mean = sums[m] / static_cast<double>(markers[m].observations);
        const double d = (mean - centre).norm();
        if (d <= best_mm) {
          best_mm = d;
          best = static_cast<int>(m);
        }
      }
      if (best < 0) {
        best = static_cast<int>(markers.size());
        markers.emplace_back();
        sums.emplace_back(Eigen::Vector3d::Zero());
      }
      const auto b = static_cast<std::size_t>(best);
      sums[b] += centre;
      ++markers[b].observations;
      ids[f].push_back(best);
    }
  }
  for (std::size_t m = 0; m < markers.size(); ++m) {
    const Eigen::Vector3d mean = sums[m] / static_cast<double>(markers[m].observations);
    markers[m].centre_mm = {mean.x(), mean.y(), mean.z()};
  }
  return ids;
}

std::vector<IdentificationFrame> WithoutOutlierMarkers(std::span<const IdentificationFrame> frames,
                                                       const DepthErrorModel& model,
                                                       const MarkerOutlierLimits& limits,
                                                       std::vector<std::vector<char>>& rejected) {
  std::vector<std::vector<double>> per_frame(frames.size());
  ParallelFor(0, static_cast<std::int64_t>(frames.size()), [&](std::int64_t fi) {
    const auto f = static_cast<std::size_t>(fi);
    for (const MarkerPatch& patch : frames[f].markers) {
      std::vector<double> d = SmoothnessDistances(patch, model);
      double m = INFINITY;  // a singular fit: always an outlier
      if (!d.empty()) m = MedianSpread(std::move(d)).first - limits.thickness_mm;
      per_frame[f].push_back(m);
    }
  });
  std::vector<double> all;
  for (const auto& v : per_frame) {
    for (double m : v) {
      if (std::isfinite(m)) all.push_back(m);
    }
  }
  rejected.assign(frames.size(), {});
  for (std::size_t f = 0; f < frames.size(); ++f) rejected[f].assign(frames[f].markers.size(), 0);
  std::vector<IdentificationFrame> out(frames.begin(), frames.end());
  if (all.empty()) return out;
  const auto [centre, spread] = MedianSpread(all);
  const double limit = std::max(limits.spreads * spread, limits.min_mm);
  for (std::size_t f = 0; f < out.size(); ++f) {
    std::vector<MarkerPatch> kept;
    Points3d& points = out[f].marker_points;  // Err_C's: drop the rejected markers' too
    for (std::size_t k = 0; k < out[f].markers.size(); ++k) {
      MarkerPatch& patch = out[f].markers[k];
      if (std::abs(per_frame[f][k] - centre) <= limit) {
        kept.push_back(std::move(patch));
        continue;
      }
      rejected[f][k] = 1;
      std::erase_if(points, [&](const Eigen::Vector3d& p) {
        return std::find(patch.marker_points.begin(), patch.marker_points.end(), p) !=
               patch.marker_points.end();
      });
    }
    out[f].markers = std::move(kept);
  }
  return out;
}

}  // namespace tofnav
