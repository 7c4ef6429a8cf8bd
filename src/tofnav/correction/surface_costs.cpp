// SPDX-License-Identifier: BSD-3-Clause
// The two costs of the identification: surface correctness (Eq. 5) and smoothness (Eq. 6).
#include "tofnav/correction/surface_costs.hpp"

#include <Eigen/Cholesky>
#include <array>
#include <cmath>
#include <stdexcept>

namespace tofnav {
namespace {

using CubicBasis = Eigen::Matrix<double, 10, 1>;
using BasisArray = std::array<double, 10>;

BasisArray Basis(double x, double y) {
  return {1.0, x, y, x * x, x * y, y * y, x * x * x, x * x * y, x * y * y, y * y * y};
}

Eigen::Vector3d ToLocal(const MarkerPatch& patch, const Eigen::Vector3d& point_in_ahat) {
  Eigen::Vector3d local = patch.local_from_ahat * (point_in_ahat - patch.origin_in_ahat);
  local.x() /= patch.scale_mm;
  local.y() /= patch.scale_mm;
  return local;
}

// Signed distance of a point along its nearest skin sample's normal (outside > 0) [mm].
double SignedDistanceTo(const SurfaceIndex& skin, std::uint32_t nearest,
                        const Eigen::Vector3d& point_in_image) {
  return skin.normals()[nearest].dot(point_in_image - skin.points()[nearest]);
}

// The neighbours' decycled ranges for `model`, recomputed only when its cyclic error changed;
// null when there is nothing to keep (no cache, or no cyclic error).
const std::vector<double>* Decycled(const MarkerPatch& patch, const DepthErrorModel& model,
                                    DecycledRanges* cache) {
  if (cache == nullptr || !model.cyclic.enabled()) return nullptr;
  if (cache->key != model.cyclic || cache->range_mm.size() != patch.neighbours.size()) {
    cache->range_mm.resize(patch.neighbours.size());
    for (std::size_t i = 0; i < patch.neighbours.size(); ++i) {
      cache->range_mm[i] = model.cyclic.RemoveMm(patch.neighbours[i].range_mm);
    }
    cache->key = model.cyclic;
  }
  return &cache->range_mm;
}

std::optional<CubicBasis> FitPatchCubic(const MarkerPatch& patch, const DepthErrorModel& model,
                                        DecycledRanges* cache = nullptr) {
  if (patch.neighbours.size() < 20) return std::nullopt;
  const std::vector<double>* decycled = Decycled(patch, model, cache);
  // Normal equations by hand (plain arrays: this is the identification's inner loop).
  std::array<double, 100> ata{};
  BasisArray atb{};
  for (std::size_t k = 0; k < patch.neighbours.size(); ++k) {
    const SurfaceSample& s = patch.neighbours[k];
    const double range_mm =
        decycled != nullptr ? model.CorrectDecycledRangeMm((*decycled)[k], s.incidence_rad, s.ab)
                            : model.CorrectRangeMm(s.range_mm, s.incidence_rad, s.ab);
    const Eigen::Vector3d p = ToLocal(patch, s.ray.cast<double>() * range_mm);  // CorrectedPoint
    const BasisArray b = Basis(p.x(), p.y());
    for (std::size_t i = 0; i < 10; ++i) {
      for (std::size_t j = 0; j <= i; ++j) ata[i * 10 + j] += b[i] * b[j];
      atb[i] += b[i] * p.z();
    }
  }
  Eigen::Matrix<double, 10, 10> a;
  for (Eigen::Index i = 0; i < 10; ++i) {
    for (Eigen::Index j = 0; j <= i; ++j) {
      a(i, j) = a(j, i) = ata[static_cast<std::size_t>(i * 10 + j)];
    }
  }
  const Eigen::LDLT<Eigen::Matrix<double, 10, 10>> ldlt(a);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-12)) return std::nullopt;
  return ldlt.solve(Eigen::Map<const CubicBasis>(atb.data()));
}

// The cubic's unit normal in `ahat` at local (x, y).
Eigen::Vector3d CubicNormal(const MarkerPatch& patch, const CubicBasis& c, double x, double y) {
  const double fx =
      c(1) + 2.0 * c(3) * x + c(4) * y + 3.0 * c(6) * x * x + 2.0 * c(7) * x * y + c(8) * y * y;
  const double fy =
      c(2) + c(4) * x + 2.0 * c(5) * y + c(7) * x * x + 2.0 * c(8) * x * y + 3.0 * c(9) * y * y;
  return (patch.local_from_ahat.transpose() *
          Eigen::Vector3d(-fx / patch.scale_mm, -fy / patch.scale_mm, 1.0))
      .normalized();
}

}  // namespace

std::vector<double> SmoothnessDistances(const MarkerPatch& patch, const DepthErrorModel& model,
                                        DecycledRanges* decycled) {
  std::vector<double> out;
  if (patch.marker_points.empty()) return out;
  const std::optional<CubicBasis> coefficients = FitPatchCubic(patch, model, decycled);
  if (!coefficients) return out;
  out.reserve(patch.marker_points.size());
  for (const Eigen::Vector3d& m : patch.marker_points) {
    const Eigen::Vector3d p = ToLocal(patch, m);
    const BasisArray b = Basis(p.x(), p.y());
    out.push_back(p.z() - Eigen::Map<const CubicBasis>(b.data()).dot(*coefficients));
  }
  return out;
}

bool SetIncidenceFromPatchSurface(MarkerPatch& patch, const DepthErrorModel& model) {
  const std::optional<CubicBasis> c = FitPatchCubic(patch, model);
  if (!c) return false;
  for (SurfaceSample& s : patch.neighbours) {
    const Eigen::Vector3d p = ToLocal(patch, CorrectedPoint(s, model));
    const Eigen::Vector3d n = CubicNormal(patch, *c, p.x(), p.y());
    const double cosine = std::abs(n.dot(s.ray.cast<double>().normalized()));
    s.incidence_rad = static_cast<float>(std::acos(std::min(1.0, cosine)));
  }
  return true;
}

std::optional<Eigen::Vector3d> PatchSurfaceNormal(const MarkerPatch& patch,
                                                  const Eigen::Vector3d& point_in_ahat,
                                                  const DepthErrorModel& model) {
  const std::optional<CubicBasis> c = FitPatchCubic(patch, model);
  if (!c) return std::nullopt;
  const Eigen::Vector3d p = ToLocal(patch, point_in_ahat);
  return CubicNormal(patch, *c, p.x(), p.y());
}

void CorrectnessOptions::Check() const {
  icp.Check();
  if (!(max_distance_mm > 0.0)) {
    throw std::invalid_argument("CorrectnessOptions::max_distance_mm must be > 0");
  }
}

double SkinSignedDistance(const SurfaceIndex& skin, const Eigen::Vector3d& point_in_image,
                          double max_mm) {
  const std::optional<Neighbour> nn = skin.Nearest(point_in_image, max_mm);
  if (!nn) return max_mm;
  return SignedDistanceTo(skin, nn->index, point_in_image);
}

double SkinSignedDistanceTo(const SurfaceIndex& skin, std::uint32_t nearest,
                            const Eigen::Vector3d& point_in_image, double max_mm) {
  // As SurfaceIndex::Nearest bounds its search: the nearest counts only strictly inside max_mm.
  const Eigen::Vector3d d = point_in_image - skin.points()[nearest];
  if (!(d.x() * d.x() + d.y() * d.y() + d.z() * d.z() < max_mm * max_mm)) return max_mm;
  return SignedDistanceTo(skin, nearest, point_in_image);
}

CorrectnessFrame CorrectnessDistances(const IdentificationFrame& frame,
                                      const DepthErrorModel& model, const SurfaceIndex& skin,
                                      const Rigid3d& image_from_ahat_guess,
                                      const CorrectnessOptions& options) {
  CorrectnessFrame out;
  out.image_from_ahat = image_from_ahat_guess;
  Points3d head;
  head.reserve(frame.head.size());
  for (const SurfaceSample& s : frame.head) head.push_back(CorrectedPoint(s, model));
  if (static_cast<int>(head.size()) >= options.icp.min_correspondences) {
    const IcpResult icp = AlignPointToPlane(head, {}, skin, image_from_ahat_guess, options.icp);
    if (icp.converged) {
      out.image_from_ahat = icp.target_from_source;
      out.converged = true;
    }
  }
  out.distances.reserve(frame.marker_points.size());
  for (const Eigen::Vector3d& m : frame.marker_points) {
    out.distances.push_back(
        SkinSignedDistance(skin, out.image_from_ahat * m, options.max_distance_mm));
  }
  return out;
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

}  // namespace tofnav
