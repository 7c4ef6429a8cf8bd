// SPDX-License-Identifier: BSD-3-Clause
// Removal of one-bounce diffuse multipath from an AHAT range image (docs/correction.md 7).
// The forward model of the simulator (sim/multipath.cpp) is not reused, on purpose: the tests hold
// this inverse against that rendering, and a shared piece would hide a shared mistake.
#include "tofnav/correction/multipath_correction.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/parallel_for.hpp"
#include "tofnav/correction/intensity_ab.hpp"

namespace tofnav {
namespace {

using Complex = std::complex<double>;

struct Patch {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // in ahat [mm]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, facing the camera
  double range_mm = 0.0;
  double weight_sr = 0.0;  // rho Omega: albedo times the block's solid angle
  double min_r2 = 0.0;     // the patch's area [mm^2]: closer exchanges are clamped to it
};

// Solid angle of pixel (u, v) from the spread of its neighbours' unit rays [sr]; 0 at the border
// of the valid rays.
double PixelSolidAngle(const AhatCamera& camera, int u, int v) {
  if (u < 1 || v < 1 || u + 1 >= camera.width() || v + 1 >= camera.height()) return 0.0;
  if (!camera.IsValid(u - 1, v) || !camera.IsValid(u + 1, v) || !camera.IsValid(u, v - 1) ||
      !camera.IsValid(u, v + 1)) {
    return 0.0;
  }
  const Eigen::Vector3d du =
      0.5 * (camera.PixelRay(u + 1, v) - camera.PixelRay(u - 1, v)).cast<double>();
  const Eigen::Vector3d dv =
      0.5 * (camera.PixelRay(u, v + 1) - camera.PixelRay(u, v - 1)).cast<double>();
  return du.cross(dv).norm();
}

double CosIncidence(const Eigen::Vector3f& normal, const Eigen::Vector3f& ray, double floor) {
  if (normal.squaredNorm() < 0.5f) return floor;
  return std::max(static_cast<double>(std::abs(normal.dot(ray))), floor);
}

// One patch per stride x stride block: the valid pixel nearest to the block's centre, and the
// block's pixels on its surface (range within 3 % of it). Position: that pixel's point; normal: the
// least-variance axis of the surface pixels' points (a plane fitted over the whole block is far
// less noisy than per-pixel normals, whose noise biases 1 / cos(theta) upwards); albedo: the mean
// of rho = AB d^2 / (K cos(theta) V) over the surface pixels (d in metres), capped at max_albedo;
// solid angle: the centre pixel's times the surface pixels. `delay` (may be null): the surfaces'
// scattering delays; the patch's phase range is its range plus twice its own (what it adds to the
// light it re-emits, on top of the direct light's single delay that `range` no longer carries).
std::optional<Patch> BlockPatch(const Image<float>& range, const Image<float>& ab,
                                const Image<float>* delay, const AhatCamera& camera,
                                const MultipathCorrectionOptions& o, int u0, int v0, int s) {
  const int u1 = std::min(u0 + s, range.width()), v1 = std::min(v0 + s, range.height());
  int best_u = -1, best_v = -1, best_dist = 1 << 30;
  for (int v = v0; v < v1; ++v) {
    for (int u = u0; u < u1; ++u) {
      if (range(u, v) <= 0.0f || !camera.IsValid(u, v)) continue;
      const int dist = std::abs(2 * (u - u0) + 1 - s) + std::abs(2 * (v - v0) + 1 - s);
      if (dist < best_dist) {
        best_dist = dist;
        best_u = u;
        best_v = v;
      }
    }
  }
  if (best_u < 0) return std::nullopt;
  const double d_centre = range(best_u, best_v);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  double reflectance_sum = 0.0;  // sum of rho cos(theta)
  int count = 0;
  for (int v = v0; v < v1; ++v) {
    for (int u = u0; u < u1; ++u) {
      const double d = range(u, v);
      if (d <= 0.0 || !camera.IsValid(u, v) || std::abs(d - d_centre) > 0.03 * d_centre) continue;
      const Eigen::Vector3d ray = camera.PixelRay(u, v).cast<double>();
      const Eigen::Vector3d p = d * ray;
      sum += p;
      outer += p * p.transpose();
      const double z = std::max(ray.z(), 1e-3);
      const double falloff = o.falloff_power == 2.0 ? z * z : std::pow(z, o.falloff_power);
      const double d_m = d * 1e-3;
      reflectance_sum += ab(u, v) * d_m * d_m / (o.ab_scale * falloff);
      ++count;
    }
  }
  if (count < 3) return std::nullopt;
  const Eigen::Vector3d mean = sum / count;
  const Eigen::Matrix3d cov = outer / count - mean * mean.transpose();
  const auto eig = DecomposeSymmetric(cov);
  const Eigen::Vector3d ray = camera.PixelRay(best_u, best_v).cast<double>();
  Eigen::Vector3d n = eig.vectors.col(0);
  if (n.dot(ray) > 0.0) n = -n;
  const double omega = PixelSolidAngle(camera, best_u, best_v);
  if (omega <= 0.0) return std::nullopt;
  const double cos_theta = std::max(-n.dot(ray), 0.2);
  const double albedo = std::min(reflectance_sum / count / cos_theta, o.max_albedo);
  const double block_omega = omega * count;
  const double phase_range = d_centre + (delay ? 2.0 * (*delay)(best_u, best_v) : 0.0);
  return Patch{d_centre * ray, n, phase_range, albedo * block_omega,
               block_omega * d_centre * d_centre / cos_theta};
}

// The patch of every stride x stride block, row by row (nullopt where a block has none).
std::vector<std::optional<Patch>> BlockGrid(const Image<float>& range, const Image<float>& ab,
                                            const Image<float>* delay, const AhatCamera& camera,
                                            const MultipathCorrectionOptions& o, int stride,
                                            const Image<std::uint8_t>* needed = nullptr) {
  const int cols = (range.width() + stride - 1) / stride,
            rows = (range.height() + stride - 1) / stride;
  std::vector<std::optional<Patch>> grid(static_cast<std::size_t>(cols) * rows);
  ParallelFor(0, rows, [&](std::int64_t row) {
    const int j = static_cast<int>(row);
    for (int i = 0; i < cols; ++i) {
      if (needed && (*needed)(i, j) == 0) continue;
      grid[static_cast<std::size_t>(j) * cols + i] =
          BlockPatch(range, ab, delay, camera, o, i * stride, j * stride, stride);
    }
  });
  return grid;
}

// Indirect irradiance at a receiver per unit source intensity, (1 / pi) sum_j rho_j Omega_j
// cos_j cos_i / r^2 exp(i k (d_j + r)): both surfaces must face each other; visibility between
// them is not tested (the screen-space approximation).
Complex IndirectIrradiance(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                           const std::vector<Patch>& patches, double k) {
  Complex sum = 0.0;
  for (const Patch& p : patches) {
    const Eigen::Vector3d to_receiver = point - p.point;
    const double r2 = to_receiver.squaredNorm();
    if (r2 <= 0.0) continue;
    const double r = std::sqrt(r2);
    const double cos_j = p.normal.dot(to_receiver) / r, cos_i = -normal.dot(to_receiver) / r;
    if (cos_j <= 0.0 || cos_i <= 0.0) continue;
    sum += std::polar(p.weight_sr * cos_j * cos_i / std::max(r2, p.min_r2), k * (p.range_mm + r));
  }
  return sum / std::numbers::pi;
}

// One pass: `measured` corrected with the indirect light that the scene `geometry` (a range image
// of the same pixels, 0 = none, less each surface's scattering delay) and its direct AB predict.
// `direct_ab` is updated to the measured AB divided by |1 + q|: the indirect light also brightens a
// pixel, which would overstate its albedo as an emitter in the next pass.
Image<float> CorrectOnce(const Image<float>& measured, const Image<float>& geometry,
                         const Image<float>& measured_ab, Image<float>& direct_ab,
                         const AhatCamera& camera, const MultipathCorrectionOptions& options,
                         const RangeNormalOptions& normal_options, const MultipathHints& hints,
                         MultipathCorrectionStats* stats) {
  const int w = geometry.width(), h = geometry.height();
  const std::vector<std::optional<Patch>> sources = BlockGrid(
      geometry, direct_ab, hints.scatter_delay_mm, camera, options, options.source_stride_px);
  std::vector<Patch> patches;
  for (const auto& p : sources) {
    if (p) patches.push_back(*p);
  }
  const double k = 2.0 * std::numbers::pi / (2.0 * options.alias_mm);
  const int stride = options.receiver_stride_px;
  const int cols = (w + stride - 1) / stride, rows = (h + stride - 1) / stride;
  // Receivers needed: blocks with a wanted pixel and their neighbours (the interpolation's).
  Image<std::uint8_t> needed(cols, rows, hints.wanted ? 0 : 1);
  if (hints.wanted) {
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        if ((*hints.wanted)(u, v) == 0) continue;
        const int bi = u / stride, bj = v / stride;
        for (int j = std::max(bj - 1, 0); j <= std::min(bj + 1, rows - 1); ++j) {
          for (int i = std::max(bi - 1, 0); i <= std::min(bi + 1, cols - 1); ++i) needed(i, j) = 1;
        }
      }
    }
  }
  // Per-pixel normals, where needed: the range outside the needed blocks is left out of them (a
  // block's margin is wider than the normals' smoothing and differencing reach, so the wanted
  // pixels' normals are those of the whole range).
  Image<Eigen::Vector3f> computed;
  if (!hints.normal) {
    const int reach = normal_options.smoothing_radius_px + normal_options.difference_step_px;
    if (hints.wanted && reach < stride) {
      Image<float> near = geometry;
      for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
          if (needed(u / stride, v / stride) == 0) near(u, v) = 0.0f;
        }
      }
      computed = ComputeRangeNormalVectors(near, camera, normal_options);
    } else {
      computed = ComputeRangeNormalVectors(geometry, camera, normal_options);
    }
  }
  const Image<Eigen::Vector3f>& normal = hints.normal ? *hints.normal : computed;
  // Indirect irradiance at the block centres that hold a surface (the emitters' grid when the
  // strides agree).
  const std::vector<std::optional<Patch>> receivers =
      stride == options.source_stride_px
          ? std::vector<std::optional<Patch>>()
          : BlockGrid(geometry, direct_ab, nullptr, camera, options, stride, &needed);
  const std::vector<std::optional<Patch>>& grid = receivers.empty() ? sources : receivers;
  Image<Complex> irradiance(cols, rows, Complex(0.0));
  Image<double> valid(cols, rows, 0.0);
  ParallelFor(0, rows, [&](std::int64_t row) {
    const int j = static_cast<int>(row);
    for (int i = 0; i < cols; ++i) {
      if (needed(i, j) == 0) continue;
      const std::optional<Patch>& receiver = grid[static_cast<std::size_t>(j) * cols + i];
      if (!receiver) continue;
      irradiance(i, j) = IndirectIrradiance(receiver->point, receiver->normal, patches, k);
      valid(i, j) = 1.0;
    }
  });
  // Per pixel: the interpolated irradiance times the inverse of the pixel's direct irradiance
  // (d^2 / cos theta) is the indirect-to-direct phasor ratio q, relative to the direct phase
  // 2 k d; the measured phase is that of (1 + q), so the direct range is d - arg(1 + q) / (2 k).
  Image<float> out(w, h);
  if (hints.indirect_ratio) *hints.indirect_ratio = Image<float>(w, h, 0.0f);
  Image<float> next_ab = direct_ab;
  std::vector<std::int64_t> corrected(static_cast<std::size_t>(h), 0),
      dropped(static_cast<std::size_t>(h), 0);
  std::vector<double> shift(static_cast<std::size_t>(h), 0.0);
  ParallelFor(0, h, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    const double y = (v + 0.5) / stride - 0.5;
    const int j0 = std::clamp(static_cast<int>(std::floor(y)), 0, rows - 1);
    const int j1 = std::min(j0 + 1, rows - 1);
    const double fy = std::clamp(y - j0, 0.0, 1.0);
    for (int u = 0; u < w; ++u) {
      const double d = geometry(u, v);
      if (d <= 0.0 || !camera.IsValid(u, v)) continue;
      if (hints.wanted && (*hints.wanted)(u, v) == 0) {
        out(u, v) = measured(u, v);
        continue;
      }
      const double x = (u + 0.5) / stride - 0.5;
      const int i0 = std::clamp(static_cast<int>(std::floor(x)), 0, cols - 1);
      const int i1 = std::min(i0 + 1, cols - 1);
      const double fx = std::clamp(x - i0, 0.0, 1.0);
      const double wt[4] = {(1 - fx) * (1 - fy) * valid(i0, j0), fx * (1 - fy) * valid(i1, j0),
                            (1 - fx) * fy * valid(i0, j1), fx * fy * valid(i1, j1)};
      const double w_sum = wt[0] + wt[1] + wt[2] + wt[3];
      if (w_sum <= 0.0) {
        out(u, v) = measured(u, v);
        continue;
      }
      const double cos_theta =
          CosIncidence(normal(u, v), camera.PixelRay(u, v), options.min_cos_incidence);
      const Complex q = (wt[0] * irradiance(i0, j0) + wt[1] * irradiance(i1, j0) +
                         wt[2] * irradiance(i0, j1) + wt[3] * irradiance(i1, j1)) /
                        w_sum * (d * d / cos_theta) * std::polar(1.0, -k * d);
      const double ratio = std::abs(q);
      if (hints.indirect_ratio) (*hints.indirect_ratio)(u, v) = static_cast<float>(ratio);
      if (ratio > options.max_indirect_ratio) {
        ++dropped[static_cast<std::size_t>(v)];
        continue;
      }
      const double delta = std::arg(1.0 + q) / (2.0 * k);
      out(u, v) = static_cast<float>(measured(u, v) - delta);
      next_ab(u, v) = static_cast<float>(measured_ab(u, v) / std::abs(1.0 + q));
      ++corrected[static_cast<std::size_t>(v)];
      shift[static_cast<std::size_t>(v)] += delta;
    }
  });
  direct_ab = std::move(next_ab);
  if (stats) {
    *stats = {};
    double total = 0.0;
    for (int v = 0; v < h; ++v) {
      stats->pixels_corrected += corrected[static_cast<std::size_t>(v)];
      stats->pixels_dropped += dropped[static_cast<std::size_t>(v)];
      total += shift[static_cast<std::size_t>(v)];
    }
    if (stats->pixels_corrected > 0) {
      stats->mean_shift_mm = total / static_cast<double>(stats->pixels_corrected);
    }
  }
  return out;
}

// The ranges of the surfaces themselves: `range` less each pixel's scattering delay (a pixel the
// delay would move to or behind the camera keeps its range).
Image<float> SurfaceRanges(const Image<float>& range, const Image<float>& delay) {
  Image<float> out = range;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float d = out.pixels()[i] - delay.pixels()[i];
    if (out.pixels()[i] > 0.0f && d > 0.0f) out.pixels()[i] = d;
  }
  return out;
}

}  // namespace

void MultipathCorrectionOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("MultipathCorrectionOptions: ") + what);
  };
  require(ab_scale > 0.0 && std::isfinite(ab_scale), "ab_scale must be > 0");
  require(falloff_power >= 0.0 && falloff_power <= 10.0, "falloff_power must lie in [0, 10]");
  require(max_albedo > 0.0 && max_albedo <= 10.0, "max_albedo must lie in (0, 10]");
  require(source_stride_px >= 2 && source_stride_px <= 128 && receiver_stride_px >= 2 &&
              receiver_stride_px <= 128,
          "strides must lie in [2, 128] px");
  require(min_cos_incidence > 0.0 && min_cos_incidence <= 1.0,
          "min_cos_incidence must lie in (0, 1]");
  require(max_indirect_ratio > 0.0, "max_indirect_ratio must be > 0");
  require(alias_mm > 0.0 && std::isfinite(alias_mm), "alias_mm must be > 0");
  require(passes >= 1 && passes <= 10, "passes must lie in [1, 10]");
  require(skin_delay_mm >= 0.0 && skin_delay_mm <= 100.0, "skin_delay_mm must lie in [0, 100]");
}

Image<float> SkinScatterDelay(const Image<std::uint8_t>& skin, double delay_mm) {
  if (delay_mm == 0.0) return {};
  Image<float> out(skin.width(), skin.height(), 0.0f);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (skin.pixels()[i] != 0) out.pixels()[i] = static_cast<float>(delay_mm);
  }
  return out;
}

Image<float> RemoveMultipath(const Image<float>& range_mm, const Image<std::uint16_t>& ab,
                             const AhatCamera& camera, const MultipathCorrectionOptions& options,
                             const RangeNormalOptions& normal_options, const MultipathHints& hints,
                             MultipathCorrectionStats* stats) {
  options.Check();
  const int w = range_mm.width(), h = range_mm.height();
  if (ab.width() != w || ab.height() != h || camera.width() != w || camera.height() != h) {
    throw std::invalid_argument("RemoveMultipath: range, AB and camera sizes differ");
  }
  if ((hints.normal && (hints.normal->width() != w || hints.normal->height() != h)) ||
      (hints.wanted && (hints.wanted->width() != w || hints.wanted->height() != h)) ||
      (hints.scatter_delay_mm &&
       (hints.scatter_delay_mm->width() != w || hints.scatter_delay_mm->height() != h))) {
    throw std::invalid_argument("RemoveMultipath: the hints' sizes differ from the range's");
  }
  if (stats) *stats = {};
  if (!options.enabled) return range_mm;
  // Fixed-point iteration: the measured geometry is itself distorted by the multipath (most where
  // the indirect light dominates, at grazing edges, which then emit from the wrong places), so
  // each pass predicts the indirect light from the previous pass's corrected ranges and normals.
  Image<float> corrected = range_mm;
  // The albedos read a lossy stream's square code at its interval's centre: its floor c^2 lies
  // 6-13 % below the true AB on skin, and the removal then predicted as much less indirect light
  // (docs/correction.md 7.2).
  const Image<float> measured_ab = DecodedAb(ab, hints.ab_square_code);
  Image<float> direct_ab = measured_ab;
  for (int pass = 0; pass < options.passes; ++pass) {
    // The first pass has the caller's normals; every pass but the last corrects every pixel (the
    // next pass's emitters).
    MultipathHints pass_hints;
    pass_hints.scatter_delay_mm = hints.scatter_delay_mm;
    if (pass == 0) pass_hints.normal = hints.normal;
    if (pass + 1 == options.passes) {
      pass_hints.wanted = hints.wanted;
      pass_hints.indirect_ratio = hints.indirect_ratio;
    }
    const Image<float> surfaces =
        hints.scatter_delay_mm ? SurfaceRanges(corrected, *hints.scatter_delay_mm) : Image<float>();
    Image<float> next =
        CorrectOnce(range_mm, hints.scatter_delay_mm ? surfaces : corrected, measured_ab, direct_ab,
                    camera, options, normal_options, pass_hints, stats);
    if (options.damped && pass > 0 && pass + 1 < options.passes) {
      for (std::size_t i = 0; i < next.size(); ++i) {
        const float before = corrected.pixels()[i], after = next.pixels()[i];
        if (before > 0.0f && after > 0.0f) next.pixels()[i] = 0.5f * (before + after);
      }
    }
    corrected = std::move(next);
  }
  return corrected;
}

}  // namespace tofnav
