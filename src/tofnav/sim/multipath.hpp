// SPDX-License-Identifier: BSD-3-Clause
// One-bounce diffuse multipath in screen space (docs/tof_physics.md section 6.2).
#pragma once

#include <complex>

#include "tofnav/core/image.hpp"
#include "tofnav/sim/image_filters.hpp"
#include "tofnav/sim/scene.hpp"

namespace tofnav::sim {

/// Every visible surface patch re-emits (Lambertian) the light it receives from the camera's
/// source, and every pixel receives a second path from every patch: half path length
/// (d_j + |x_i - x_j| + d_i) / 2, amplitude by the form factor times rho_j times `gain`. Patches
/// and receivers are sampled on coarse pixel grids (visibility between them is not tested: the
/// screen-space approximation of Fuchs 2010); the receivers' phasor ratio is interpolated to every
/// pixel. A patch faces the way its block's surface does on average (the mean normal of the
/// block's pixels on the centre pixel's object), not the way one pixel's facet does: the facing
/// test stands in for visibility, and a rough convex surface's facets must not lend each other
/// light through the body (docs/simulator.md 6.9.1). gain 0 switches it off.
struct MultipathOptions {
  /// Scale of the form factor's indirect light; 0 switches it off. 0.7 puts the Table I phantoms'
  /// IQRs before correction within the published ones (docs/simulator.md 10). Dimensionless
  double gain = 0.7;
  int source_stride_px = 16;    // one emitting patch per stride x stride pixel block
  int receiver_stride_px = 16;  // one receiver per block, interpolated in between
  void Check() const;
};

/// What the one-bounce pass reads of a rendered frame (the centre ray of each pixel).
struct MultipathInputs {
  const Image<float>& range_mm;                  // first-hit range, 0 = none
  const Image<Eigen::Vector3f>& normal_in_ahat;  // first-hit normal
  const Image<std::int16_t>& material;           // Scene::materials index, -1 none
  const Image<std::int16_t>& object;             // Scene::objects index, -1 none
  const Image<Eigen::Vector3d>& ray_in_ahat;     // unit centre ray
  const Image<double>& solid_angle_sr;           // of the pixel, 0 where unknown
  const Image<double>& diffuse_share;            // Lambertian part of the pixel's direct AB
  /// Modulation frequency [Hz] of the subsurface responses that each scattering applies to the
  /// indirect light (physical bias mode); 0: no surface delays its light.
  double subsurface_modulation_hz = 0.0;
};

/// Adds the one-bounce paths to `phasor` (amplitude * exp(i 2 pi d / L) per pixel) over `window`.
/// The added phasor of pixel i is gain * s_i |phasor_i| * sum_j F_ij exp(i 2 pi (d_j + r_ij + d_i)
/// / (2 L)), with F_ij = rho_j Omega_j cos_j cos_i d_i^2 / (pi r_ij^2 cos theta_i): the ratio of
/// indirect to direct irradiance at x_i, which keeps the pixel's own albedo, subsurface and
/// radiometry factors. s_i is the Lambertian share of the pixel's direct return: a
/// retro-reflector sends light back towards where it came from, so of the light arriving from
/// another surface only its diffuse base (rho) reaches the camera (docs/simulator.md, multipath).
/// Emitters use rho_j alone for the same reason: what a retro-reflector returns goes back to the
/// source, not to the other surfaces.
/// With `subsurface_modulation_hz` set, the indirect light is scattered, and delayed, twice: the
/// emitter's subsurface response H_j multiplies each patch's light and the receiver's own phase
/// arg H_i the sum (the direct light carries H_i once; docs/tof_physics.md 6.2).
void AddMultipath(const MultipathOptions& options, const Scene& scene, const PixelRect& window,
                  const MultipathInputs& in, double alias_mm, Image<std::complex<double>>& phasor);

}  // namespace tofnav::sim
