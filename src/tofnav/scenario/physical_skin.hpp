// SPDX-License-Identifier: BSD-3-Clause
// The patient's physical skin from an image's iso-surface: the image's noise taken out.
#pragma once

#include <optional>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

struct PhysicalSkinOptions {
  /// Gaussian weight of the local fit [mm]: removes the iso-surface's bumps at 2-5 mm
  /// wavelengths (an image's noise at the air-skin edge), which real skin does not have
  /// (docs/simulator.md "The patient's skin"). 0: the iso-surface unchanged.
  double sigma_mm = 4.0;
  /// No vertex moves further [mm]; <= 0: no limit. Unset: `noise_sigmas` times the surface's
  /// own noise, the median over its vertices of the fits' weighted RMS residual. Noise moves an
  /// iso-surface within a few of its own RMS; anatomy the fit cannot follow (an ear's rim, the
  /// nostrils) bends it further and is kept.
  std::optional<double> max_move_mm;
  double noise_sigmas = 3.0;
  void Check() const;  // throws PreconditionError naming the field
};

/// Each vertex projected onto the quadric height field fitted, with Gaussian weights of
/// `sigma_mm` out to 3 sigma, to the vertices around it that face the same way (a moving
/// least-squares surface), its move along the local normal capped (`max_move_mm`); triangles
/// kept, vertex normals recomputed. Deterministic for any thread count.
TriangleMesh SmoothPhysicalSkin(const TriangleMesh& iso_surface,
                                const PhysicalSkinOptions& options = {});

}  // namespace tofnav
