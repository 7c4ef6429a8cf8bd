// SPDX-License-Identifier: BSD-3-Clause
// `tofnav reconstruct`: tracking, range cleaning and correction per frame, fusion, meshing.
#include "tofnav/pipeline/reconstruct.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "tofnav/core/frame_batches.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/correction/frame_segmentation.hpp"
#include "tofnav/fusion/mesh_boundary.hpp"
#include "tofnav/fusion/mesh_components.hpp"
#include "tofnav/pipeline/reconstruct_frames.hpp"

namespace tofnav {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Range codes as float mm, 0 = invalid.
Image<float> RangeFromCodes(const Image<std::uint16_t>& codes) {
  Image<float> range(codes.width(), codes.height());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const std::uint16_t code = codes.data()[i];
    range.data()[i] = code == 0 || code >= kAhatInvalidRange ? 0.0f : static_cast<float>(code);
  }
  return range;
}

// Removes retro-reflective pixels and a ring around them: AB >= threshold, dilated by a square
// of `dilation_px`.
void MaskMarkers(const Image<std::uint16_t>& ab, double ab_threshold, int dilation_px,
                 Image<float>& range) {
  const int w = range.width(), h = range.height();
  if (ab.width() != w || ab.height() != h) return;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (static_cast<double>(ab(u, v)) < ab_threshold) continue;
      for (int y = std::max(0, v - dilation_px); y <= std::min(h - 1, v + dilation_px); ++y) {
        for (int x = std::max(0, u - dilation_px); x <= std::min(w - 1, u + dilation_px); ++x) {
          range(x, y) = 0.0f;
        }
      }
    }
  }
}

Image<float> AbWeights(const AhatFrame& frame, double reference, double floor) {
  Image<float> weight(frame.ab.width(), frame.ab.height());
  for (int v = 0; v < weight.height(); ++v) {
    for (int u = 0; u < weight.width(); ++u) {
      const double r = static_cast<double>(frame.ab(u, v)) / reference;
      weight(u, v) = static_cast<float>(std::clamp(r * r, floor, 1.0));
    }
  }
  return weight;
}

double Median(std::vector<double> values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace

void AutoRoiOptions::Check() const {
  Require(centre_window_px >= 1, "AutoRoiOptions::centre_window_px must be >= 1");
  Require(std::isfinite(radius_mm) && radius_mm > 0.0, "AutoRoiOptions::radius_mm must be > 0");
  Require(std::isfinite(margin_mm) && margin_mm >= 0.0, "AutoRoiOptions::margin_mm must be >= 0");
  Require(frames >= 1, "AutoRoiOptions::frames must be >= 1");
  Require(component_radius_mm > 0.0, "AutoRoiOptions::component_radius_mm must be > 0");
}

void ReconstructOptions::Check() const {
  tsdf.Check();
  mesh.Check();
  auto_roi.Check();
  head_region.Check();
  pose.Check();
  if (!marker_error.empty()) marker_error.Check();
  Require(marker_mask_dilation_px >= 0 && marker_mask_dilation_px <= 32,
          "ReconstructOptions::marker_mask_dilation_px must be in [0, 32]");
  Require(std::isfinite(ab_weight_reference) && ab_weight_reference >= 0.0,
          "ReconstructOptions::ab_weight_reference must be >= 0");
  Require(std::isfinite(multipath_weight_ratio) && multipath_weight_ratio >= 0.0,
          "ReconstructOptions::multipath_weight_ratio must be >= 0");
  Require(min_ab_weight > 0.0 && min_ab_weight <= 1.0,
          "ReconstructOptions::min_ab_weight must be in (0, 1]");
  Require(frame_step >= 1, "ReconstructOptions::frame_step must be >= 1");
  Require(boundary_rings_removed >= 0, "ReconstructOptions::boundary_rings_removed must be >= 0");
  Require(!max_frames || *max_frames >= 1, "ReconstructOptions::max_frames must be >= 1");
  Require(std::isfinite(min_observed_frames) && min_observed_frames >= 0.0,
          "ReconstructOptions::min_observed_frames must be >= 0");
  Require(std::isfinite(min_observed_fraction) && min_observed_fraction >= 0.0 &&
              min_observed_fraction <= 1.0,
          "ReconstructOptions::min_observed_fraction must be in [0, 1]");
  model_check.Check();
  pose_consistency.Check();
  rotation_smoothing.Check();
}

namespace {

// Calls f(u, v, point_in_tool) for every valid pixel of a view.
template <typename F>
void ForEachRoiPoint(const RoiView& view, const AhatCamera& camera, F&& f) {
  const Image<float>& range_mm = *view.range_mm;
  Require(range_mm.width() == camera.width() && range_mm.height() == camera.height(),
          "AutomaticRoi: the range image must have the camera's size");
  for (int v = 0; v < range_mm.height(); ++v) {
    for (int u = 0; u < range_mm.width(); ++u) {
      if (range_mm(u, v) <= 0.0f || !camera.IsValid(u, v)) continue;
      f(u, v, view.tool_from_ahat * camera.PointFromRange(u, v, range_mm(u, v)));
    }
  }
}

// A view's centre: the component-wise median of its central window's points, or of all its
// points when that window is empty (e.g. only the head region is left); nullopt without any.
std::optional<Eigen::Vector3d> RoiViewCentre(const RoiView& view, const AhatCamera& camera,
                                             const AutoRoiOptions& options) {
  const int u0 = (camera.width() - options.centre_window_px) / 2;
  const int v0 = (camera.height() - options.centre_window_px) / 2;
  std::vector<double> x, y, z;
  const auto add = [&](const Eigen::Vector3d& p) {
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
  };
  ForEachRoiPoint(view, camera, [&](int u, int v, const Eigen::Vector3d& p) {
    if (u >= u0 && v >= v0 && u < u0 + options.centre_window_px &&
        v < v0 + options.centre_window_px) {
      add(p);
    }
  });
  if (x.empty()) ForEachRoiPoint(view, camera, [&](int, int, const Eigen::Vector3d& p) { add(p); });
  if (x.empty()) return std::nullopt;
  return Eigen::Vector3d(Median(std::move(x)), Median(std::move(y)), Median(std::move(z)));
}

}  // namespace

std::optional<Eigen::AlignedBox3d> AutomaticRoi(std::span<const RoiView> views,
                                                const AhatCamera& camera,
                                                const AutoRoiOptions& options,
                                                Eigen::Vector3d* centre_in_tool) {
  options.Check();
  std::vector<double> cx, cy, cz;          // the views' centres
  std::vector<std::size_t> centred_views;  // the views that have one
  for (std::size_t k = 0; k < views.size(); ++k) {
    const std::optional<Eigen::Vector3d> c = RoiViewCentre(views[k], camera, options);
    if (!c) continue;
    cx.push_back(c->x());
    cy.push_back(c->y());
    cz.push_back(c->z());
    centred_views.push_back(k);
  }
  if (cx.empty()) return std::nullopt;
  const Eigen::Vector3d centre(Median(cx), Median(cy), Median(cz));
  if (centre_in_tool) *centre_in_tool = centre;
  // The box of the most typical view: the one whose own centre is nearest the consensus.
  std::size_t typical = 0;
  for (std::size_t i = 1; i < centred_views.size(); ++i) {
    const auto distance = [&](std::size_t j) {
      return (Eigen::Vector3d(cx[j], cy[j], cz[j]) - centre).squaredNorm();
    };
    if (distance(i) < distance(typical)) typical = i;
  }
  Eigen::AlignedBox3d box(centre);
  ForEachRoiPoint(views[centred_views[typical]], camera, [&](int, int, const Eigen::Vector3d& p) {
    if ((p - centre).norm() <= options.radius_mm) box.extend(p);
  });
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(options.margin_mm);
  return Eigen::AlignedBox3d(box.min() - margin, box.max() + margin);
}

double SeldomObservedMinWeight(const ReconstructOptions& options, std::size_t frames_fused) {
  const double wanted =
      std::max({options.mesh.min_weight, options.min_observed_frames,
                options.min_observed_fraction * static_cast<double>(frames_fused)});
  // Half the frames fused at most: a short recording keeps what most of its frames saw.
  const double cap = std::min(options.tsdf.max_weight, static_cast<double>(frames_fused));
  return std::min(wanted, std::max(options.mesh.min_weight, 0.5 * cap));
}

namespace {

// One posed frame's range work, independent of other frames (run in parallel over a batch).
struct PreparedFrame {
  const TrackedFrame* tracked = nullptr;
  AhatFrame frame;
  Image<float> range_mm;
  Image<float> weight;
};

void Prepare(PreparedFrame& p, const AhatCamera& camera, const ReconstructOptions& options) {
  const double ab_threshold = p.tracked->ab_threshold;
  Image<float> indirect_ratio;
  if (options.correct_range) {
    CorrectedRange corrected = options.correct_range(p.frame, camera);
    p.range_mm = std::move(corrected.range_mm);
    indirect_ratio = std::move(corrected.indirect_ratio);
  } else {
    p.range_mm = RangeFromCodes(p.frame.range_mm);
  }
  Require(p.range_mm.width() == camera.width() && p.range_mm.height() == camera.height(),
          "ReconstructSurface: the corrected range image must have the camera's size");
  MaskMarkers(p.frame.ab, ab_threshold, options.marker_mask_dilation_px, p.range_mm);
  if (options.head_region.enabled) {
    SegmentationOptions seg;
    seg.marker_ab_threshold = ab_threshold;
    seg.transition_dilation_px = options.marker_mask_dilation_px;
    seg.min_range_mm = options.tsdf.min_range_mm;
    seg.max_range_mm = options.tsdf.max_range_mm;
    seg.head_region = options.head_region;
    const FrameSegmentation head = SegmentFrame(p.frame, camera, seg);
    for (std::size_t i = 0; i < p.range_mm.size(); ++i) {
      if (head.labels.data()[i] != static_cast<std::uint8_t>(PixelClass::kHead)) {
        p.range_mm.data()[i] = 0.0f;
      }
    }
  }
  if (options.ab_weight_reference > 0.0) {
    p.weight = AbWeights(p.frame, options.ab_weight_reference, options.min_ab_weight);
  }
  if (options.multipath_weight_ratio > 0.0 && !indirect_ratio.empty()) {
    if (p.weight.empty()) p.weight = Image<float>(camera.width(), camera.height(), 1.0f);
    for (std::size_t i = 0; i < p.weight.size(); ++i) {
      const double r = indirect_ratio.pixels()[i] / options.multipath_weight_ratio;
      p.weight.pixels()[i] = static_cast<float>(p.weight.pixels()[i] / (1.0 + r * r));
    }
  }
}

constexpr std::size_t kPrepareBatchFrames = 8;  // frames prepared in parallel

// IntegrateChecked, counted in `result`.
void FuseChecked(TsdfVolume& volume, Image<float> range_mm, const AhatCamera& camera,
                 const Rigid3d& tool_from_ahat, const Image<float>& weight,
                 const ReconstructOptions& options, ReconstructResult& result) {
  const CheckedIntegration r = IntegrateChecked(volume, std::move(range_mm), camera, tool_from_ahat,
                                                weight, options.model_check);
  result.pixels_gated += r.pixels_gated;
  if (r.check.verdict != ModelVerdict::kUnchecked) ++result.frames_model_checked;
  if (r.check.verdict == ModelVerdict::kRefined) ++result.frames_refined;
  if (r.fused) {
    ++result.frames_fused;
  } else {
    ++result.frames_rejected;
    ++result.rejected_by_reason[ToString(r.check.verdict)];
  }
}

}  // namespace

ReconstructResult ReconstructSurface(
    const AhatRecording& recording, const AhatCamera& camera, const ToolGeometry& tool,
    const ReconstructOptions& options,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  options.Check();
  const Clock::time_point start = Clock::now();
  ReconstructResult result;
  std::vector<std::size_t> frames;
  for (std::size_t i = options.first_frame; i < recording.frame_count(); i += options.frame_step) {
    if (options.max_frames && frames.size() >= *options.max_frames) break;
    frames.push_back(i);
  }
  result.frames_considered = frames.size();
  const std::size_t total = 2 * frames.size();  // progress: the tracking pass, then fusion
  std::vector<TrackedFrame> tracked =
      TrackFrames(recording, camera, tool, options, frames, result, [&](std::size_t done) {
        if (progress) progress(done, total);
      });
  if (options.check_pose_consistency) {
    result.frames_pose_checked = FlagPoseJumps(camera, options, tracked);
  }
  if (options.smooth_rotation) {
    result.frames_rotation_smoothed = SmoothToolRotations(camera, options, tracked);
  }
  std::vector<const TrackedFrame*> posed;
  for (const TrackedFrame& f : tracked) {
    if (!f.ahat_from_tool) {
      ++result.frames_skipped;
      ++result.skipped_by_status[ToString(f.status)];
    } else if (f.pose_jump) {
      ++result.frames_rejected;
      ++result.rejected_by_reason[ToString(PoseConsistency::kJump)];
    } else {
      posed.push_back(&f);
    }
  }
  std::optional<TsdfVolume> volume;
  if (options.tsdf.roi_in_tool) volume.emplace(options.tsdf, camera);
  // Without a given ROI, the first posed frames wait (in order) until they have chosen it.
  struct Waiting {
    Image<float> range_mm;
    Image<float> weight;
    Rigid3d tool_from_ahat;
  };
  std::vector<Waiting> waiting;
  std::optional<Eigen::Vector3d> looked_at_in_tool;  // the automatic ROI's centre
  const auto choose_roi = [&] {
    std::vector<RoiView> views;
    for (const Waiting& w : waiting) views.push_back({&w.range_mm, w.tool_from_ahat});
    TsdfOptions tsdf = options.tsdf;
    Eigen::Vector3d looked_at = Eigen::Vector3d::Zero();
    tsdf.roi_in_tool = AutomaticRoi(views, camera, options.auto_roi, &looked_at);
    if (!tsdf.roi_in_tool) {  // nothing valid in any of them: they count as skipped
      result.frames_skipped += waiting.size();
      result.skipped_by_status["no_roi"] += waiting.size();
      waiting.clear();
      return;
    }
    result.roi_automatic = true;
    looked_at_in_tool = looked_at;
    volume.emplace(tsdf, camera);
    for (Waiting& w : waiting) {
      FuseChecked(*volume, std::move(w.range_mm), camera, w.tool_from_ahat, w.weight, options,
                  result);
    }
    waiting.clear();
  };
  BatchTimes times;
  ForEachInBatches<PreparedFrame>(
      posed.size(), kPrepareBatchFrames,
      [&](std::size_t p) {
        PreparedFrame prepared;
        prepared.tracked = posed[p];
        prepared.frame = recording.ReadFrame(posed[p]->index);
        return prepared;
      },
      [&](PreparedFrame& prepared, std::size_t) { Prepare(prepared, camera, options); },
      [&](PreparedFrame& p, std::size_t position) {
        if (progress) progress(frames.size() + position + 1, total);
        const Rigid3d tool_from_ahat = p.tracked->ahat_from_tool->Inverse();
        if (!volume) {
          waiting.push_back({std::move(p.range_mm), std::move(p.weight), tool_from_ahat});
          if (static_cast<int>(waiting.size()) >= options.auto_roi.frames) choose_roi();
          return;
        }
        FuseChecked(*volume, std::move(p.range_mm), camera, tool_from_ahat, p.weight, options,
                    result);
      },
      &times);
  if (!volume && !waiting.empty()) choose_roi();  // fewer posed frames than the vote wants
  result.read_s += times.read_s;
  result.prepare_s += times.prepare_s;
  result.fuse_s += times.consume_s;
  if (progress) progress(total, total);
  if (!volume) {
    throw std::runtime_error("reconstruct: the tool '" + tool.name +
                             "' was not tracked in any frame (no region of interest)");
  }
  result.roi_in_tool = *volume->options().roi_in_tool;
  result.blocks = volume->block_count();
  const Clock::time_point t = Clock::now();
  TsdfMeshOptions mesh_options = options.mesh;
  mesh_options.min_weight = SeldomObservedMinWeight(options, result.frames_fused);
  result.mesh_min_weight = mesh_options.min_weight;
  TriangleMesh mesh = ExtractIsoSurface(*volume, mesh_options);
  result.mesh_vertices_before_component = mesh.vertices.size();
  if (mesh_options.min_weight > options.mesh.min_weight) {
    const std::size_t all = ExtractIsoSurface(*volume, options.mesh).vertices.size();
    result.vertices_seldom_observed = all > mesh.vertices.size() ? all - mesh.vertices.size() : 0;
  }
  if (!options.largest_component) {
    result.mesh = std::move(mesh);
  } else if (looked_at_in_tool) {
    result.mesh =
        ConnectedComponentAround(mesh, *looked_at_in_tool, options.auto_roi.component_radius_mm);
  } else {
    result.mesh = LargestConnectedComponent(mesh);
  }
  if (options.boundary_rings_removed > 0) {
    ErodedMesh eroded = ErodeBoundary(result.mesh, options.boundary_rings_removed);
    result.mesh = std::move(eroded.mesh);
    result.vertices_at_boundary_removed = eroded.vertices_removed;
  }
  result.mesh_s = Seconds(t);
  result.total_s = Seconds(start);
  return result;
}

}  // namespace tofnav
