// SPDX-License-Identifier: BSD-3-Clause
// The two costs of the identification: surface correctness (Eq. 5) and smoothness (Eq. 6).
#pragma once

#include <optional>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/registration/icp.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

/// A patch's neighbour ranges with the cyclic error removed, for the cyclic error `key`: an
/// identification's cost evaluations change the coefficients far more often than the cyclic
/// error (its numerical derivatives by C1, C3, C4), and the removal (three sines per sample) was
/// the largest share of its first stage. The default key (no cyclic error) matches no model that
/// has one, so an empty cache is filled on first use.
struct DecycledRanges {
  CyclicRangeError key;
  std::vector<double> range_mm;  // per neighbour
};

/// Eq. (6) terms of one marker: the head points around it corrected with Eq. (4), a cubic
/// polynomial surface z = f(x, y) fitted to them by least squares in the patch's local frame,
/// and the signed distance (along the local z) of each marker point to it [mm]. Empty when the
/// patch has too few neighbours or the fit is singular. `decycled`, when given, keeps the
/// neighbours' decycled ranges between calls on this patch (the same figures, faster).
std::vector<double> SmoothnessDistances(const MarkerPatch& patch, const DepthErrorModel& model,
                                        DecycledRanges* decycled = nullptr);

/// Replaces each neighbour's incidence angle by that of the cubic surface (as in
/// SmoothnessDistances) fitted to the neighbours corrected with `model`: per-pixel normals of a
/// noisy range overestimate theta on average (the error of an arccos of a noisy unit vector is
/// one-sided), which biases C3 and C2 low; the fitted surface averages the noise out. Returns
/// false (and changes nothing) when the fit is singular.
bool SetIncidenceFromPatchSurface(MarkerPatch& patch, const DepthErrorModel& model);

/// The unit normal, in `ahat`, of the cubic surface fitted to the neighbours corrected with
/// `model`, below `point_in_ahat` (a sticker's centre: the skin it lies on). nullopt when the fit
/// is singular or the patch has fewer than 20 neighbours.
std::optional<Eigen::Vector3d> PatchSurfaceNormal(const MarkerPatch& patch,
                                                  const Eigen::Vector3d& point_in_ahat,
                                                  const DepthErrorModel& model);

/// Eq. (5) of one frame.
struct CorrectnessOptions {
  IcpOptions icp = [] {
    IcpOptions o;
    o.max_distance_schedule_mm = {6.0, 3.0};
    return o;
  }();
  /// Marker points with no skin point this close count as this far (keeps the residual count
  /// fixed for the optimiser) [mm].
  double max_distance_mm = 8.0;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct CorrectnessFrame {
  Rigid3d image_from_ahat;  // the ICP result (the guess when it failed)
  bool converged = false;
  std::vector<double> distances;  // signed, per marker point (outside the skin > 0) [mm]
};

/// Signed point-to-plane distance of `point_in_image` to the nearest skin sample (outside > 0),
/// or `max_mm` when no sample lies within `max_mm` (keeps the residual count fixed) [mm].
double SkinSignedDistance(const SurfaceIndex& skin, const Eigen::Vector3d& point_in_image,
                          double max_mm);
/// The same when the nearest skin sample is already known (exactly the same figure).
double SkinSignedDistanceTo(const SurfaceIndex& skin, std::uint32_t nearest,
                            const Eigen::Vector3d& point_in_image, double max_mm);

/// Corrects the frame's head samples with `model` (Eq. 4), registers them to the skin by the
/// registration module's point-to-plane ICP from `image_from_ahat_guess`, and measures each
/// Eq. (2)-corrected marker point's signed distance to the skin (point-to-plane to the nearest
/// skin sample).
CorrectnessFrame CorrectnessDistances(const IdentificationFrame& frame,
                                      const DepthErrorModel& model, const SurfaceIndex& skin,
                                      const Rigid3d& image_from_ahat_guess,
                                      const CorrectnessOptions& options = {});

/// sqrt(mean(d^2)), 0 for none.
double Rms(const std::vector<double>& values);

}  // namespace tofnav
