// SPDX-License-Identifier: BSD-3-Clause
// Tool definitions, marker detection in a frame and multi-tool tracking over frames.
#include <pybind11/stl.h>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/tool_geometry.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav::python {
namespace {

MarkerType MarkerTypeFromString(const std::string& type) {
  if (type == "sphere") return MarkerType::kSphere;
  if (type == "disc" || type == "flat") return MarkerType::kDisc;
  throw py::value_error("marker_type must be 'sphere' or 'disc', not '" + type + "'");
}

ToolGeometry MakeTool(const std::string& name, const ArrayD& markers, const std::string& type,
                      double diameter_mm, int min_visible, double max_fre_mm,
                      const py::object& tip) {
  ToolGeometry tool{.name = name,
                    .markers_in_tool = PointsFromArray(markers, "markers"),
                    .marker_type = MarkerTypeFromString(type),
                    .marker_diameter_mm = diameter_mm,
                    .min_visible = min_visible,
                    .max_fre_mm = max_fre_mm};
  if (!tip.is_none()) tool.tip_in_tool = VectorFromArray(tip.cast<ArrayD>(), "tip");
  tool.Check();
  return tool;
}

void DefineTool(py::module_& m) {
  py::class_<ToolGeometry>(m, "Tool", "rigid marker tool: marker centres in its own frame [mm]")
      .def(py::init(&MakeTool), py::arg("name"), py::arg("markers"),
           py::arg("marker_type") = "sphere", py::arg("marker_diameter_mm") = 11.5,
           py::arg("min_visible") = 3, py::arg("max_fre_mm") = 0.0, py::arg("tip") = py::none())
      .def_readonly("name", &ToolGeometry::name)
      .def_property_readonly(
          "markers", [](const ToolGeometry& t) { return ArrayFromPoints(t.markers_in_tool); })
      .def_property_readonly("marker_type",
                             [](const ToolGeometry& t) {
                               return t.marker_type == MarkerType::kSphere ? "sphere" : "disc";
                             })
      .def_readonly("marker_diameter_mm", &ToolGeometry::marker_diameter_mm)
      .def_readonly("min_visible", &ToolGeometry::min_visible)
      .def_readonly("max_fre_mm", &ToolGeometry::max_fre_mm)
      .def_property_readonly("tip", [](const ToolGeometry& t) -> py::object {
        if (!t.tip_in_tool) return py::none();
        return ArrayFromVector(*t.tip_in_tool);
      });
}

void DefineMarkers(py::module_& m) {
  py::class_<DetectedMarker>(m, "Marker", "a retro-reflective marker seen in one frame")
      .def_property_readonly(
          "pixel", [](const DetectedMarker& d) { return ArrayFromVector(d.pixel); },
          "(u, v) AB-weighted centroid, pixel centres at integers")
      .def_property_readonly("ray",
                             [](const DetectedMarker& d) { return ArrayFromVector(d.ray_in_ahat); })
      .def_readwrite("surface_range_mm", &DetectedMarker::surface_range_mm,
                     "measured range to the marker surface (input of Eq. (2); writable)")
      .def_readonly("area_px", &DetectedMarker::area_px)
      .def_readonly("ab_peak", &DetectedMarker::ab_peak)
      .def_property_readonly(
          "occluded", [](const DetectedMarker& d) { return d.damage.occluded; },
          "part of its rim borders pixels clearly nearer (docs/tracking.md 6)")
      .def_property_readonly(
          "near_blob", [](const DetectedMarker& d) { return d.damage.near_blob; },
          "another blob touches it (docs/tracking.md 6)")
      .def_property_readonly(
          "occluder_px", [](const DetectedMarker& d) { return d.damage.occluder_px; },
          "pixels of the occluder ring clearly nearer than the marker");
  m.def(
      "locate_markers",
      [](const AhatFrame& frame, const AhatCamera& camera, double ab_threshold,
         double relative_threshold, double min_marker_diameter_mm, double max_marker_diameter_mm) {
        const MarkerDetectionOptions options{.ab_threshold = ab_threshold,
                                             .relative_threshold = relative_threshold,
                                             .min_marker_diameter_mm = min_marker_diameter_mm,
                                             .max_marker_diameter_mm = max_marker_diameter_mm};
        return LocateMarkers(frame, camera, options).markers;
      },
      py::arg("frame"), py::arg("camera"), py::arg("ab_threshold") = kMarkerAbThreshold,
      py::arg("relative_threshold") = 0.0, py::arg("min_marker_diameter_mm") = 6.0,
      py::arg("max_marker_diameter_mm") = 16.0, "markers of one frame (LocateMarkers)");
}

void DefineTracker(py::module_& m) {
  py::class_<TrackedTool>(m, "TrackedTool", "one tool in one frame")
      .def_property_readonly(
          "status", [](const TrackedTool& t) { return ToString(t.status()); },
          "'ok', 'partially_occluded', 'ambiguous', 'too_few_markers', 'out_of_view'")
      .def_property_readonly(
          "ahat_from_tool",
          [](const TrackedTool& t) { return OptionalArrayFromRigid(t.measurement.ahat_from_tool); },
          "4 x 4 measured pose, or None")
      .def_property_readonly(
          "filtered_ahat_from_tool",
          [](const TrackedTool& t) { return OptionalArrayFromRigid(t.filtered_ahat_from_tool); })
      .def_property_readonly("fre_rms_mm",
                             [](const TrackedTool& t) { return t.measurement.fre_rms_mm; })
      .def_property_readonly("visible_markers",
                             [](const TrackedTool& t) { return t.measurement.visible_markers; })
      .def_property_readonly("used_markers",
                             [](const TrackedTool& t) { return t.measurement.used_markers; })
      .def_property_readonly(
          "position_sd_mm", [](const TrackedTool& t) { return t.measurement.position_sd_mm; },
          "per-axis sd of the measured position under the noise model (0: unknown)")
      .def_property_readonly("rotation_sd_rad",
                             [](const TrackedTool& t) { return t.measurement.rotation_sd_rad; })
      .def_property_readonly("noise_chi2",
                             [](const TrackedTool& t) { return t.measurement.noise_chi2; })
      .def_property_readonly("marker_detection",
                             [](const TrackedTool& t) { return t.measurement.marker_detection; })
      .def_readonly("gated", &TrackedTool::gated)
      .def_readonly("filtered_rotation_sd_rad", &TrackedTool::filtered_rotation_sd_rad,
                    "expected RMS angle error of the filtered orientation, or None "
                    "(docs/tracking.md 1)");
  py::class_<ToolTracker>(m, "ToolTracker", "tracks a fixed set of tools over frames (Sec. III-C)")
      .def(
          py::init([](std::vector<ToolGeometry> tools, bool filter_enabled, int max_missed_frames) {
            return ToolTracker(std::move(tools), {.filter_enabled = filter_enabled,
                                                  .max_missed_frames = max_missed_frames});
          }),
          py::arg("tools"), py::arg("filter_enabled") = true, py::arg("max_missed_frames") = 5)
      .def(
          "track",
          [](ToolTracker& tracker, const std::vector<DetectedMarker>& markers, double timestamp_s) {
            return tracker.Track(markers, timestamp_s).tools;
          },
          py::arg("markers"), py::arg("timestamp_s"),
          "one frame's markers -> one TrackedTool per tool, in the tools' order")
      .def("reset", &ToolTracker::Reset)
      .def_property_readonly("tools", &ToolTracker::tools);
}

}  // namespace

void DefineTracking(py::module_& m) {
  DefineTool(m);
  DefineMarkers(m);
  DefineTracker(m);
}

}  // namespace tofnav::python
