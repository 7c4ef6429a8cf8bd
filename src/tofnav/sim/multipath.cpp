// SPDX-License-Identifier: BSD-3-Clause
// One-bounce diffuse multipath in screen space (docs/tof_physics.md section 6.2).
#include "tofnav/sim/multipath.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/tof_model.hpp"

namespace tofnav::sim {
namespace {

using Complex = std::complex<double>;

constexpr double kMinCosIncidence = 1e-3;  // the direct irradiance's floor (grazing pixels)

struct Patch {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // x_j in ahat [mm]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // facing the camera
  double range_mm = 0.0;                             // d_j
  Complex weight = 0.0;  // rho_j Omega_j [sr], times the emitter's subsurface response H_j
  double min_r2 = 0.0;   // patch area: r^2 below it is clamped
};

// Pixel (u, v)'s centre-ray normal, turned to face the camera.
Eigen::Vector3d FacingNormal(const MultipathInputs& in, int u, int v) {
  const Eigen::Vector3d n = in.normal_in_ahat(u, v).cast<double>();
  return n.dot(in.ray_in_ahat(u, v)) > 0.0 ? Eigen::Vector3d(-n) : n;
}

// The block's normal, facing the camera: the mean of the centre-ray normals of the stride x stride
// block's pixels that hit the centre pixel's object. A patch emits and receives as the sum of its
// pixels' facets, sum_k Omega_k rho (n_k . u) ~ Omega rho (mean n . u) wherever its facets face u;
// and the facing test, which stands in for the visibility that the screen-space model does not
// trace, must see the surface's shape at the scale of the exchange: on a convex body every chord
// runs inside it, yet one facet of a rough skin tilted 30 deg would pass the test across it.
Eigen::Vector3d BlockNormal(const MultipathInputs& in, const PixelRect& window, int u_centre,
                            int v_centre, int stride) {
  const int object = in.object(u_centre, v_centre);
  const int u0 = std::max(u_centre - stride / 2, window.u0),
            v0 = std::max(v_centre - stride / 2, window.v0);
  const int u1 = std::min(u_centre - stride / 2 + stride, window.u0 + window.width),
            v1 = std::min(v_centre - stride / 2 + stride, window.v0 + window.height);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int v = v0; v < v1; ++v) {
    for (int u = u0; u < u1; ++u) {
      if (in.range_mm(u, v) > 0.0f && in.object(u, v) == object) sum += FacingNormal(in, u, v);
    }
  }
  return sum.squaredNorm() > 1e-12 ? Eigen::Vector3d(sum.normalized())
                                   : FacingNormal(in, u_centre, v_centre);
}

// The subsurface response a scattering at incidence acos(cos_incidence) applies (1 outside the
// physical bias mode or without subsurface scattering).
Complex ScatteringResponse(const Material& material, double cos_incidence,
                           const MultipathInputs& in) {
  if (in.subsurface_modulation_hz <= 0.0 || material.subsurface_fraction <= 0.0) return 1.0;
  return SubsurfaceFactor(material, std::acos(std::clamp(cos_incidence, 0.0, 1.0)),
                          in.subsurface_modulation_hz);
}

// The centre pixel of each stride x stride block of the window that hits a surface.
std::vector<Patch> SamplePatches(const Scene& scene, const PixelRect& window,
                                 const MultipathInputs& in, int stride) {
  std::vector<Patch> patches;
  for (int v = window.v0 + stride / 2; v < window.v0 + window.height; v += stride) {
    for (int u = window.u0 + stride / 2; u < window.u0 + window.width; u += stride) {
      const double d = in.range_mm(u, v), omega = in.solid_angle_sr(u, v);
      const int m = in.material(u, v);
      if (d <= 0.0 || omega <= 0.0 || m < 0) continue;
      const Eigen::Vector3d ray = in.ray_in_ahat(u, v);
      const Eigen::Vector3d n = BlockNormal(in, window, u, v, stride);
      const double cos_theta = std::max(-n.dot(ray), 1e-3);
      const double block_omega = omega * stride * stride;
      const Material& material = scene.materials[static_cast<std::size_t>(m)];
      const Complex response = ScatteringResponse(material, cos_theta, in);
      patches.push_back({d * ray, n, d, material.albedo * block_omega * response,
                         block_omega * d * d / cos_theta});
    }
  }
  return patches;
}

// Indirect irradiance at a receiver per unit source intensity, sum_j rho_j Omega_j cos_j cos_i /
// (pi r^2), with the phase of d_j + r (not d_i). It varies slowly over a surface; the pixel's own
// d_i^2 / cos(theta_i) (the inverse of its direct irradiance) is applied per pixel, so a grazing
// receiver does not lend its large ratio to the pixels it is interpolated into.
Complex IndirectIrradiance(const Patch& receiver, const std::vector<Patch>& patches,
                           double two_pi_over_two_alias) {
  Complex sum = 0.0;
  for (const Patch& p : patches) {
    const Eigen::Vector3d to_receiver = receiver.point - p.point;
    const double r2 = to_receiver.squaredNorm();
    if (r2 <= 0.0) continue;
    const double r = std::sqrt(r2);
    const double cos_j = p.normal.dot(to_receiver) / r,
                 cos_i = -receiver.normal.dot(to_receiver) / r;
    if (cos_j <= 0.0 || cos_i <= 0.0) continue;  // facing away: no exchange
    const double form = cos_j * cos_i / std::max(r2, p.min_r2);
    sum += p.weight * std::polar(form, two_pi_over_two_alias * (p.range_mm + r));
  }
  return sum / std::numbers::pi;
}

}  // namespace

void MultipathOptions::Check() const {
  Require(gain >= 0.0 && std::isfinite(gain), "MultipathOptions.gain must be >= 0");
  Require(source_stride_px >= 1 && source_stride_px <= 128 && receiver_stride_px >= 1 &&
              receiver_stride_px <= 128,
          "MultipathOptions: strides must lie in [1, 128] px");
}

void AddMultipath(const MultipathOptions& options, const Scene& scene, const PixelRect& window,
                  const MultipathInputs& in, double alias_mm, Image<Complex>& phasor) {
  options.Check();
  if (options.gain <= 0.0 || window.width <= 0 || window.height <= 0) return;
  const std::vector<Patch> patches = SamplePatches(scene, window, in, options.source_stride_px);
  const int stride = options.receiver_stride_px;
  const int cols = (window.width + stride - 1) / stride,
            rows = (window.height + stride - 1) / stride;
  const double k = 2.0 * std::numbers::pi / (2.0 * alias_mm);
  // Indirect irradiance at block centres; weight 0 where the centre ray hits nothing.
  Image<Complex> irradiance(cols, rows, Complex(0.0));
  Image<double> valid(cols, rows, 0.0);
  ParallelFor(0, rows, [&](std::int64_t row) {
    const int j = static_cast<int>(row);
    for (int i = 0; i < cols; ++i) {
      const int u = std::min(window.u0 + i * stride + stride / 2, window.u0 + window.width - 1);
      const int v = std::min(window.v0 + j * stride + stride / 2, window.v0 + window.height - 1);
      const double d = in.range_mm(u, v);
      if (d <= 0.0 || in.material(u, v) < 0) continue;
      const Eigen::Vector3d ray = in.ray_in_ahat(u, v);
      const Eigen::Vector3d n = BlockNormal(in, window, u, v, stride);
      irradiance(i, j) = IndirectIrradiance({d * ray, n, d, Complex(0.0), 0.0}, patches, k);
      valid(i, j) = 1.0;
    }
  });
  // Bilinear interpolation over the valid receivers, then the pixel's own direct irradiance
  // (d_i^2 / cos theta_i) and d_i phase.
  ParallelFor(window.v0, window.v0 + window.height, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    const double y = (v - window.v0 + 0.5) / stride - 0.5;
    const int j0 = std::clamp(static_cast<int>(std::floor(y)), 0, rows - 1);
    const int j1 = std::min(j0 + 1, rows - 1);
    const double fy = std::clamp(y - j0, 0.0, 1.0);
    for (int u = window.u0; u < window.u0 + window.width; ++u) {
      const double d = in.range_mm(u, v);
      if (d <= 0.0) continue;
      const double x = (u - window.u0 + 0.5) / stride - 0.5;
      const int i0 = std::clamp(static_cast<int>(std::floor(x)), 0, cols - 1);
      const int i1 = std::min(i0 + 1, cols - 1);
      const double fx = std::clamp(x - i0, 0.0, 1.0);
      const double w[4] = {(1 - fx) * (1 - fy) * valid(i0, j0), fx * (1 - fy) * valid(i1, j0),
                           (1 - fx) * fy * valid(i0, j1), fx * fy * valid(i1, j1)};
      const double w_sum = w[0] + w[1] + w[2] + w[3];
      if (w_sum <= 0.0) continue;
      const Eigen::Vector3d ray = in.ray_in_ahat(u, v);
      const double cos_theta_i =
          std::max(std::abs(in.normal_in_ahat(u, v).cast<double>().dot(ray)), kMinCosIncidence);
      // The receiver's own scattering delays the indirect light as it does the direct light.
      const int m = in.material(u, v);
      const Complex receiver =
          m < 0 ? Complex(1.0)
                : ScatteringResponse(scene.materials[static_cast<std::size_t>(m)], cos_theta_i, in);
      const Complex g = (w[0] * irradiance(i0, j0) + w[1] * irradiance(i1, j0) +
                         w[2] * irradiance(i0, j1) + w[3] * irradiance(i1, j1)) /
                        w_sum * (d * d / cos_theta_i);
      phasor(u, v) += options.gain * in.diffuse_share(u, v) * std::abs(phasor(u, v)) * g *
                      std::polar(1.0, k * d) * (receiver / std::abs(receiver));
    }
  });
}

}  // namespace tofnav::sim
