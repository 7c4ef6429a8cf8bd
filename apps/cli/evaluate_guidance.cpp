// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate guidance: the plan placed by tofnav navigate against the simulator's truth
// (paper Sec. "Use Cases": entry-point and trajectory-direction error over every trajectory).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "evaluate.hpp"
#include "progress.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/markups_read.hpp"
#include "tofnav/io/reconstruct_evaluate.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

Rigid3d Matrix(const Json& j) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      m(r, c) = j.at(static_cast<std::size_t>(r)).at(static_cast<std::size_t>(c)).get<double>();
    }
  }
  return Rigid3d::FromMatrix(m);
}

// One navigate CSV row with a placed image: its time and world_from_image.
struct PlacedFrame {
  double timestamp_s = 0.0;
  Rigid3d world_from_image;
};

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

// The truth of one frame: rig_from_image (what the display shows relative to the head, free of
// the headset's pose error) and world_from_rig as recorded.
struct TruthFrame {
  double timestamp_s = 0.0;
  Rigid3d world_from_rig_recorded;
  Rigid3d world_from_image_true;
  Rigid3d rig_from_image_true;
};

std::vector<TruthFrame> ReadTruthFrames(const std::filesystem::path& truth_path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(truth_path);
  try {
    const Json truth = Json::parse(bytes.begin(), bytes.end());
    std::string tool;  // any tool rigid with the patient gives the same chain
    for (const auto& [name, t] : truth.at("tools").items()) {
      if (t.value("rigid_with_patient", false) && truth.contains(name + "_from_image")) {
        tool = name;
        break;
      }
    }
    if (tool.empty()) throw std::runtime_error("no tool rigid with the patient");
    const Rigid3d tool_from_image = Matrix(truth.at(tool + "_from_image"));
    const double tick_s = 1e-7;
    std::vector<TruthFrame> frames;
    for (const Json& f : truth.at("frames")) {
      TruthFrame t;
      t.timestamp_s = f.at("timestamp").get<double>() * tick_s;
      t.world_from_rig_recorded = Matrix(f.at("world_from_rig"));
      t.rig_from_image_true =
          Matrix(f.at("rig_from_ahat")) * Matrix(f.at("ahat_from_" + tool)) * tool_from_image;
      t.world_from_image_true = Matrix(f.at("world_from_rig_true")) * t.rig_from_image_true;
      frames.push_back(t);
    }
    return frames;
  } catch (const std::exception& e) {
    throw std::runtime_error(truth_path.string() +
                             ": not a simulation truth.json with a patient: " + e.what());
  }
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
}

OrderedJson StatsJson(const ErrorStats& s) {
  return {{"count", s.count},
          {"median", s.median_mm},
          {"iqr", s.iqr_mm},
          {"rms", s.rms_mm},
          {"p95", s.p95_mm}};
}

int RunEvaluateGuidance(int argc, char** argv) {
  CLI::App app{
      "Entry-point and direction error of the plan placed by tofnav navigate, against a "
      "simulation's truth (every trajectory, every placed frame)",
      "tofnav evaluate guidance"};
  std::filesystem::path nav_path, truth_dir, plan_path;
  bool json = false, quiet = false;
  app.add_option("navigation", nav_path, "per-frame CSV of tofnav navigate --out")->required();
  app.add_option("--truth", truth_dir, "simulation folder (truth.json, plan.mrk.json)")->required();
  app.add_option("--plan", plan_path, "the plan navigate used (default: TRUTH/plan.mrk.json)");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the figures as JSON");
  CLI11_PARSE(app, argc, argv);
  if (plan_path.empty()) plan_path = truth_dir / "plan.mrk.json";

  const std::vector<PlacedFrame> placed = ReadNavigationCsv(nav_path);
  const std::vector<TruthFrame> truth = ReadTruthFrames(truth_dir / "truth.json");
  const std::vector<Trajectory> plan = ReadTrajectories(plan_path);
  if (placed.empty()) throw std::runtime_error(nav_path.string() + ": no frame placed the plan");
  constexpr double kSameFrameS = 1e-4;  // timestamps are 100 ns ticks
  std::vector<double> entry_display, entry_world, direction;
  std::map<std::string, std::vector<double>> entry_by_name, direction_by_name;
  std::size_t unmatched = 0, done = 0;
  ProgressBar progress("evaluate guidance", quiet || json);
  for (const PlacedFrame& p : placed) {
    progress.Update(++done, placed.size());
    const auto it =
        std::lower_bound(truth.begin(), truth.end(), p.timestamp_s - kSameFrameS,
                         [](const TruthFrame& t, double s) { return t.timestamp_s < s; });
    if (it == truth.end() || std::abs(it->timestamp_s - p.timestamp_s) > kSameFrameS) {
      ++unmatched;
      continue;
    }
    // Shown relative to the head: the recorded head pose cancels within a frame (Eq. 8).
    const Rigid3d rig_from_image = it->world_from_rig_recorded.Inverse() * p.world_from_image;
    for (const Trajectory& t : plan) {
      const double e =
          (rig_from_image * t.entry_lps_mm - it->rig_from_image_true * t.entry_lps_mm).norm();
      const double w =
          (p.world_from_image * t.entry_lps_mm - it->world_from_image_true * t.entry_lps_mm).norm();
      const Eigen::Vector3d axis = t.target_lps_mm - t.entry_lps_mm;
      const double d =
          AngleDeg(rig_from_image.rotation * axis, it->rig_from_image_true.rotation * axis);
      entry_display.push_back(e);
      entry_world.push_back(w);
      direction.push_back(d);
      entry_by_name[t.name].push_back(e);
      direction_by_name[t.name].push_back(d);
    }
  }
  progress.Finish();
  if (entry_display.empty()) {
    throw std::runtime_error(nav_path.string() + ": no frame matches the truth's timestamps");
  }
  const ErrorStats entry = ComputeErrorStats(entry_display);
  const ErrorStats world = ComputeErrorStats(entry_world);
  const ErrorStats angle = ComputeErrorStats(direction);
  if (json) {
    OrderedJson out{{"frames", placed.size() - unmatched},
                    {"unmatched_frames", unmatched},
                    {"trajectories", plan.size()},
                    {"entry_error_mm", StatsJson(entry)},
                    {"entry_error_world_mm", StatsJson(world)},
                    {"direction_error_deg", StatsJson(angle)},
                    {"per_trajectory", OrderedJson::array()}};
    for (const Trajectory& t : plan) {
      out["per_trajectory"].push_back(
          {{"name", t.name},
           {"entry_error_mm", StatsJson(ComputeErrorStats(entry_by_name[t.name]))},
           {"direction_error_deg", StatsJson(ComputeErrorStats(direction_by_name[t.name]))}});
    }
    std::cout << out.dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "frames " << placed.size() - unmatched << " (unmatched " << unmatched << "), "
            << plan.size() << " trajectories\n"
            << "trajectory        entry median / p95 [mm]   direction median / p95 [deg]\n";
  for (const Trajectory& t : plan) {
    const ErrorStats e = ComputeErrorStats(entry_by_name[t.name]);
    const ErrorStats d = ComputeErrorStats(direction_by_name[t.name]);
    std::cout << "  " << t.name << "\t" << e.median_mm << " / " << e.p95_mm << "\t\t" << d.median_mm
              << " / " << d.p95_mm << "\n";
  }
  std::cout << "all: entry median " << entry.median_mm << " mm (p95 " << entry.p95_mm << ", RMS "
            << entry.rms_mm << "), in world (with the headset's pose error) " << world.median_mm
            << " mm; direction median " << angle.median_mm << " deg (p95 " << angle.p95_mm << ")\n";
  return EXIT_SUCCESS;
}

[[maybe_unused]] const bool kRegistered = RegisterEvaluator(
    {"guidance", "plan placed by tofnav navigate against a simulation's truth (entry, direction)",
     RunEvaluateGuidance});

}  // namespace
}  // namespace tofnav
