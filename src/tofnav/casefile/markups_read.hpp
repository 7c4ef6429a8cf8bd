// SPDX-License-Identifier: BSD-3-Clause
// Planned trajectories from 3D Slicer markups: .mrk.json and .fcsv (docs/openigtlink.md 5.4).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "tofnav/imaging/trajectory.hpp"

namespace tofnav {

/// By extension (any case): .json (e.g. plan.mrk.json) or .fcsv. IoError for other extensions,
/// for malformed files and for files holding no trajectory.
std::vector<Trajectory> ReadTrajectories(const std::filesystem::path& path);

/// Markups JSON: every markup of "markups" is read. A "Line" gives one trajectory (defined
/// control point 0 = entry, 1 = target; exactly two defined points); a "Fiducial" list whose
/// defined points are labelled "Entry" and "Target" (any case) gives one; other markups are
/// skipped. "coordinateSystem" is "LPS" (the default) or "RAS" (x and y negated);
/// "coordinateUnits" is "mm" (default) or "um". Points whose "positionStatus" is not "defined"
/// are skipped; other keys are ignored. The name is the markup's "name" (else "trajectory N").
std::vector<Trajectory> DecodeTrajectoryMarkups(std::span<const std::uint8_t> bytes,
                                                const std::filesystem::path& source = "<json>");

/// Legacy fiducial CSV: "# CoordinateSystem = LPS | RAS | 1 | 0" (missing: RAS, the legacy
/// default; IJK is an IoError), "# columns = ..." (default id,x,y,z,ow,ox,oy,oz,vis,sel,lock,
/// label,desc,associatedNodeID), then one row per point; consecutive rows pair up as (entry,
/// target). The name is the entry's label (else "trajectory N"). An odd row count is an IoError.
std::vector<Trajectory> DecodeTrajectoryFcsv(std::span<const std::uint8_t> bytes,
                                             const std::filesystem::path& source = "<fcsv>");

/// A markups control point with its label (JSON "label", .fcsv label column), LPS [mm].
struct MarkupPoint {
  std::string label;
  Eigen::Vector3d lps_mm = Eigen::Vector3d::Zero();
};

/// Every defined control point of every markup (JSON), or every row (.fcsv), in file order, in
/// LPS mm by the same rules: fiducials for paired-point registration, landmarks for tofnav
/// verify. IoError when there is none.
std::vector<MarkupPoint> ReadLabelledMarkupPoints(const std::filesystem::path& path);
std::vector<MarkupPoint> DecodeLabelledMarkupPointsJson(
    std::span<const std::uint8_t> bytes, const std::filesystem::path& source = "<json>");
std::vector<MarkupPoint> DecodeLabelledMarkupPointsFcsv(
    std::span<const std::uint8_t> bytes, const std::filesystem::path& source = "<fcsv>");
/// The same without labels.
std::vector<Eigen::Vector3d> ReadMarkupPoints(const std::filesystem::path& path);
std::vector<Eigen::Vector3d> DecodeMarkupPointsJson(std::span<const std::uint8_t> bytes,
                                                    const std::filesystem::path& source = "<json>");
std::vector<Eigen::Vector3d> DecodeMarkupPointsFcsv(std::span<const std::uint8_t> bytes,
                                                    const std::filesystem::path& source = "<fcsv>");

}  // namespace tofnav
