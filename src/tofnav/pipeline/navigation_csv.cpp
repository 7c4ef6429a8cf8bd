// SPDX-License-Identifier: BSD-3-Clause
// The per-frame navigation CSV: one row per frame, written as frames come, read for evaluation.
#include "tofnav/pipeline/navigation_csv.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace tofnav {

std::string NavigationCsvHeader() {
  return "timestamp_s,status,reference_status,reference_age_s,markers,"
         "world_from_image_tx_mm,world_from_image_ty_mm,world_from_image_tz_mm,"
         "world_from_image_qw,world_from_image_qx,world_from_image_qy,world_from_image_qz,"
         "trajectory,entry_world_x_mm,entry_world_y_mm,entry_world_z_mm,target_world_x_mm,"
         "target_world_y_mm,target_world_z_mm,instrument_status,tip_world_x_mm,tip_world_y_mm,"
         "tip_world_z_mm,tip_to_entry_mm,angle_to_axis_deg,remaining_depth_mm,lateral_offset_mm,"
         "reference_rotation_sd_deg,settling\n";
}

std::string NavigationCsvRow(const NavigationState& s, const std::vector<Trajectory>& plan) {
  std::ostringstream row;
  row.precision(10);
  const auto xyz = [&](const std::optional<Eigen::Vector3d>& p) {
    for (int i = 0; i < 3; ++i) row << ',' << (p ? std::to_string((*p)[i]) : "");
  };
  row << s.timestamp_s << ',' << ToString(s.status) << ',' << ToString(s.reference_status) << ','
      << (std::isfinite(s.reference_age_s) ? std::to_string(s.reference_age_s) : "") << ','
      << s.detected_markers;
  xyz(s.world_from_image ? std::optional(s.world_from_image->translation) : std::nullopt);
  const auto q = s.world_from_image ? std::optional(s.world_from_image->rotation) : std::nullopt;
  for (const double v : {q ? q->w() : 0.0, q ? q->x() : 0.0, q ? q->y() : 0.0, q ? q->z() : 0.0}) {
    row << ',' << (q ? std::to_string(v) : "");
  }
  const auto active = static_cast<std::size_t>(s.active_trajectory);
  row << ',' << (active < plan.size() ? plan[active].name : "");
  const bool placed = active < s.plan.size();
  xyz(placed ? std::optional(s.plan[active].entry_in_world) : std::nullopt);
  xyz(placed ? std::optional(s.plan[active].target_in_world) : std::nullopt);
  row << ',' << (s.instrument_status ? ToString(*s.instrument_status) : "");
  xyz(s.tip_in_world);
  const auto& g = s.guidance;
  for (const double v :
       {g ? g->tip_to_entry_mm : 0.0, g ? g->angle_to_axis_rad * 180.0 / std::numbers::pi : 0.0,
        g ? g->remaining_depth_mm : 0.0, g ? g->lateral_offset_mm : 0.0}) {
    row << ',' << (g ? std::to_string(v) : "");
  }
  row << ','
      << (s.reference_rotation_sd_rad
              ? std::to_string(*s.reference_rotation_sd_rad * 180.0 / std::numbers::pi)
              : "")
      << ',' << (s.reference_settling ? 1 : 0) << '\n';
  return row.str();
}

std::vector<PlacedFrame> ReadNavigationCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::string line;
  std::getline(in, line);
  std::map<std::string, std::size_t> column;
  {
    std::istringstream header(line);
    std::string name;
    for (std::size_t i = 0; std::getline(header, name, ','); ++i) column[name] = i;
  }
  const char* needed[] = {"timestamp_s",
                          "world_from_image_tx_mm",
                          "world_from_image_ty_mm",
                          "world_from_image_tz_mm",
                          "world_from_image_qw",
                          "world_from_image_qx",
                          "world_from_image_qy",
                          "world_from_image_qz"};
  for (const char* n : needed) {
    if (!column.contains(n)) {
      throw std::runtime_error(path.string() + ": not a tofnav navigate CSV (no column " + n + ")");
    }
  }
  std::vector<PlacedFrame> frames;
  for (int row = 2; std::getline(in, line); ++row) {
    std::vector<std::string> cells;
    std::istringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
    const auto at = [&](const char* name) -> const std::string& {
      const std::size_t i = column.at(name);
      static const std::string kEmpty;
      return i < cells.size() ? cells[i] : kEmpty;
    };
    if (at("world_from_image_qw").empty()) continue;  // no placement in this frame
    try {
      PlacedFrame f;
      f.timestamp_s = std::stod(at("timestamp_s"));
      const Eigen::Quaterniond q(
          std::stod(at("world_from_image_qw")), std::stod(at("world_from_image_qx")),
          std::stod(at("world_from_image_qy")), std::stod(at("world_from_image_qz")));
      f.world_from_image = Rigid3d(q.normalized(), {std::stod(at("world_from_image_tx_mm")),
                                                    std::stod(at("world_from_image_ty_mm")),
                                                    std::stod(at("world_from_image_tz_mm"))});
      frames.push_back(f);
    } catch (const std::logic_error&) {
      throw std::runtime_error(path.string() + ": row " + std::to_string(row) +
                               ": expected numbers in the time and pose columns");
    }
  }
  return frames;
}

}  // namespace tofnav
