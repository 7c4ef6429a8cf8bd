// SPDX-License-Identifier: BSD-3-Clause
// Internal to report/: the sections of the stages without meshes (f_rf, depth, tracking, guidance).
#include <map>

#include "tofnav/report/report_internal.hpp"
#include "tofnav/report/svg_plot.hpp"

namespace tofnav::report_internal {
namespace {

// One series per distinct `group` value, in order of first appearance.
std::vector<PlotSeries> GroupSeries(const std::vector<std::string>& group,
                                    const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<PlotSeries> series;
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < group.size(); ++i) {
    const auto [it, added] = index.emplace(group[i], series.size());
    if (added) series.push_back({.name = group[i], .colour = SeriesColour(series.size())});
    series[it->second].x.push_back(x[i]);
    series[it->second].y.push_back(y[i]);
  }
  return series;
}

}  // namespace

std::string MarkerErrorSection(const Context& c) {
  const Json& stage = c.Stage("marker_error");
  if (const std::string reason = NotRunReason(stage); !reason.empty()) return NotRun(reason);
  const Json& paper = c.Paper("marker_error");
  std::string s =
      Table({"figure", "ours", "paper"},
            {CompareRow("stage frames", stage, paper, "frames"),
             CompareRow("max |bias| before [mm]", stage, paper, "bias_before_max_abs_mm"),
             CompareRow("max |bias| after [mm]", stage, paper, "bias_after_max_abs_mm")});
  return s + OrNotRun([&] {
           const Csv curve = ReadCsv(Artefact(c, stage, "curve_csv"));
           const PlotSeries series[] = {{.name = "f_rf",
                                         .x = curve.Column("range_mm"),
                                         .y = curve.Column("error_mm"),
                                         .colour = std::string(kAfterColour)}};
           return Figure("fig-marker-curve", "The fitted retro-reflector range error f_rf (Eq. 1).",
                         SvgLinePlot(series, {.title = "Marker range error f_rf",
                                              .x_label = "measured range [mm]",
                                              .y_label = "range error [mm]"}));
         });
}

std::string DepthSection(const Context& c) {
  const Json& stage = c.Stage("depth");
  if (const std::string reason = NotRunReason(stage); !reason.empty()) return NotRun(reason);
  const Json& paper = c.Paper("depth");
  const Json& model = Field(stage, "model");
  std::string s =
      "<p>Model <b>" + EscapeXml(Text(model, "name")) +
      "</b>: C1 = " + Cell(Number(model, "C1_mm")) + " mm, C2 = " + Cell(Number(model, "C2")) +
      ", C3 = " + Cell(Number(model, "C3_mm_per_rad")) +
      " mm/rad, C4 = " + Cell(Number(model, "C4_mm")) + " mm, from " +
      Cell(Number(stage, "frames")) +
      " frames (Eq. 3; C4 ln(AB_ref / AB) in place of C2 d in the intensity form).</p>\n";
  if (const Json& cyclic = Field(model, "cyclic_error"); Number(cyclic, "amplitude_mm") > 0.0) {
    s += "<p>The sensor's cyclic error, fitted with it: " + Cell(Number(cyclic, "amplitude_mm")) +
         " mm at a period of " + Cell(Number(cyclic, "period_mm")) + " mm, phase " +
         Cell(Number(cyclic, "phase_rad")) + " rad (docs/correction.md 2.2).</p>\n";
  }
  std::vector<std::vector<std::string>> rows;
  if (Field(stage, "objects").is_array()) {
    for (const Json& object : Field(stage, "objects")) {
      const std::string name = Text(object, "name");
      const bool target = Field(object, "target") == true;
      const Json& theirs = PaperEntry(paper, "objects", name, target);
      rows.push_back(
          {EscapeXml(name) + (target ? " *" : ""), Cell(Number(object, "pixels")),
           Cell(Number(object, "before_median_mm")), Cell(Number(object, "before_iqr_mm")),
           Cell(Number(object, "after_median_mm")), Cell(Number(object, "after_iqr_mm")),
           Cell(Number(object, "reduction_percent")), Cell(Number(theirs, "before_median_mm")),
           Cell(Number(theirs, "after_median_mm")), Cell(Number(theirs, "reduction_percent"))});
    }
  }
  s += Table({"object", "pixels", "before median [mm]", "before IQR [mm]", "after median [mm]",
              "after IQR [mm]", "reduction [%]", "paper before [mm]", "paper after [mm]",
              "paper reduction [%]"},
             rows);
  s += "<p class=\"meta\">* the objects the model is identified for.</p>\n";
  const Json& histogram = Field(stage, "histogram");
  const std::vector<double> edges = Numbers(histogram, "bin_edges_mm");
  if (edges.size() < 2) return s + NotRun("no depth-error histogram in demo.json");
  const PlotSeries series[] = {
      {.name = "before", .y = Numbers(histogram, "before"), .colour = std::string(kBeforeColour)},
      {.name = "after", .y = Numbers(histogram, "after"), .colour = std::string(kAfterColour)}};
  return s + Figure("fig-depth-histogram",
                    "Depth error of the head pixels before and after the correction (Eq. 4).",
                    SvgHistogram(edges, series,
                                 {.title = "Head depth error",
                                  .x_label = "depth error [mm]",
                                  .y_label = "pixels"}));
}

std::string TrackingSection(const Context& c) {
  const Json& stage = c.Stage("tracking");
  if (const std::string reason = NotRunReason(stage); !reason.empty()) return NotRun(reason);
  const Json& paper = c.Paper("tracking");
  std::vector<std::vector<std::string>> rows;
  if (Field(stage, "tools").is_array()) {
    for (const Json& tool : Field(stage, "tools")) {
      const std::string name = Text(tool, "name");
      const Json& theirs = PaperEntry(paper, "tools", name, true);
      rows.push_back(
          {EscapeXml(name), Cell(Number(tool, "frames")), Cell(Number(tool, "tracked_percent")),
           Cell(Number(tool, "position_rms_mm")), Cell(Number(tool, "rotation_rms_deg")),
           Cell(Number(tool, "wrong_identities")), Cell(Number(theirs, "position_rms_mm")),
           Cell(Number(theirs, "rotation_rms_deg"))});
    }
  }
  std::string s = Table({"tool", "frames", "tracked [%]", "position RMS [mm]", "rotation RMS [deg]",
                         "wrong identities", "paper position [mm]", "paper rotation [deg]"},
                        rows);
  return s + OrNotRun([&] {
           const Csv errors = ReadCsv(Artefact(c, stage, "error_csv"));
           const std::vector<std::string> tools = errors.TextColumn("tool");
           const std::vector<double> t_s = errors.Column("t_s");
           const std::vector<PlotSeries> position =
               GroupSeries(tools, t_s, errors.Column("position_error_mm"));
           const std::vector<PlotSeries> rotation =
               GroupSeries(tools, t_s, errors.Column("rotation_error_deg"));
           return Figure("fig-tracking-position", "Position error of each tool over the recording.",
                         SvgLinePlot(position, {.title = "Tracking position error",
                                                .x_label = "time [s]",
                                                .y_label = "position error [mm]"})) +
                  Figure("fig-tracking-rotation", "Rotation error of each tool over the recording.",
                         SvgLinePlot(rotation, {.title = "Tracking rotation error",
                                                .x_label = "time [s]",
                                                .y_label = "rotation error [deg]"}));
         });
}

std::string GuidanceSection(const Context& c) {
  const Json& stage = c.Stage("guidance");
  if (const std::string reason = NotRunReason(stage); !reason.empty()) return NotRun(reason);
  const Json& paper = c.Paper("guidance");
  std::vector<std::string> names;
  PlotSeries entry{.name = "ours", .colour = std::string(kBeforeColour)};
  PlotSeries angle{.name = "ours", .colour = std::string(kBeforeColour)};
  PlotSeries paper_entry{.name = "paper", .colour = std::string(kAfterColour)};
  PlotSeries paper_angle{.name = "paper", .colour = std::string(kAfterColour)};
  std::vector<std::vector<std::string>> rows;
  if (Field(stage, "trajectories").is_array()) {
    for (const Json& trajectory : Field(stage, "trajectories")) {
      names.push_back(Text(trajectory, "name"));
      const Json& theirs = PaperEntry(paper, "trajectories", names.back(), false);
      entry.y.push_back(Number(trajectory, "entry_error_mm"));
      angle.y.push_back(Number(trajectory, "angle_error_deg"));
      paper_entry.y.push_back(Number(theirs, "entry_error_mm"));
      paper_angle.y.push_back(Number(theirs, "angle_error_deg"));
      rows.push_back({EscapeXml(names.back()), Cell(entry.y.back()), Cell(angle.y.back()),
                      Cell(paper_entry.y.back()), Cell(paper_angle.y.back())});
    }
  }
  rows.push_back({"<b>median</b>", Cell(Number(stage, "entry_median_mm")),
                  Cell(Number(stage, "angle_median_deg")), Cell(Number(paper, "entry_median_mm")),
                  Cell(Number(paper, "angle_median_deg"))});
  std::string s = Table({"trajectory", "entry error [mm]", "angle error [deg]", "paper entry [mm]",
                         "paper angle [deg]"},
                        rows);
  const auto with_paper = [](const PlotSeries& ours, const PlotSeries& theirs) {
    for (double v : theirs.y) {
      if (!std::isnan(v)) return std::vector<PlotSeries>{ours, theirs};
    }
    return std::vector<PlotSeries>{ours};
  };
  s += Figure(
      "fig-guidance-entry", "Entry-point error of each planned trajectory.",
      SvgBarChart(names, with_paper(entry, paper_entry),
                  {.width_px = 460, .title = "Entry-point error", .y_label = "entry error [mm]"}));
  return s + Figure("fig-guidance-angle", "Direction error of each planned trajectory.",
                    SvgBarChart(names, with_paper(angle, paper_angle),
                                {.width_px = 460,
                                 .title = "Trajectory angle error",
                                 .y_label = "angle error [deg]"}));
}

}  // namespace tofnav::report_internal
