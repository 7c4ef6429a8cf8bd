// SPDX-License-Identifier: BSD-3-Clause
// The intra-operative Navigator (Sec. III-C, Eq. 8), planned trajectories and guidance.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>
#include <vector>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/casefile/transform_io.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/pipeline/navigator.hpp"

namespace tofnav::python {
namespace {

py::object OptionalVector(const std::optional<Eigen::Vector3d>& v) {
  if (!v) return py::none();
  return ArrayFromVector(*v);
}

Navigator MakeNavigator(const AhatCamera& camera, const ToolGeometry& reference,
                        const ArrayD& tool_from_image, std::vector<Trajectory> plan,
                        std::optional<ToolGeometry> instrument,
                        std::optional<MarkerRangeModel> marker_range, double stale_after_s,
                        bool filter_enabled, double ab_threshold,
                        const py::object& instrument_axis) {
  NavigationCase navigation_case{.reference = reference,
                                 .instrument = std::move(instrument),
                                 .marker_range = marker_range.value_or(MarkerRangeModel{}),
                                 .tool_from_image = RigidFromArray(tool_from_image),
                                 .plan = std::move(plan)};
  NavigatorOptions options;
  options.markers.ab_threshold = ab_threshold;
  options.tracking.filter_enabled = filter_enabled;
  options.stale_after_s = stale_after_s;
  if (!instrument_axis.is_none()) {
    options.instrument_axis_in_tool =
        VectorFromArray(instrument_axis.cast<ArrayD>(), "instrument_axis");
  }
  return Navigator(camera, std::move(navigation_case), options);
}

void DefinePlan(py::module_& m) {
  py::class_<Trajectory>(m, "Trajectory", "a planned straight trajectory in image (LPS, mm)")
      .def(py::init([](std::string name, const ArrayD& entry, const ArrayD& target) {
             return Trajectory{std::move(name), VectorFromArray(entry, "entry"),
                               VectorFromArray(target, "target")};
           }),
           py::arg("name"), py::arg("entry"), py::arg("target"))
      .def_readonly("name", &Trajectory::name)
      .def_property_readonly("entry",
                             [](const Trajectory& t) { return ArrayFromVector(t.entry_lps_mm); })
      .def_property_readonly("target",
                             [](const Trajectory& t) { return ArrayFromVector(t.target_lps_mm); });
  m.def("read_trajectories", &ReadTrajectories, py::arg("path"),
        "3D Slicer markups (.mrk.json line or Entry/Target points, .fcsv) -> [Trajectory]");
  m.def(
      "read_transform",
      [](const std::filesystem::path& path) {
        return ArrayFromRigid(ReadTransform(path).target_from_source);
      },
      py::arg("path"), "transform file (.json, .tfm, .txt) -> 4 x 4 target_from_source");

  py::class_<Guidance>(m, "Guidance", "an instrument against a planned trajectory [mm, rad]")
      .def_readonly("tip_to_entry_mm", &Guidance::tip_to_entry_mm)
      .def_readonly("angle_to_axis_rad", &Guidance::angle_to_axis_rad)
      .def_readonly("remaining_depth_mm", &Guidance::remaining_depth_mm)
      .def_readonly("lateral_offset_mm", &Guidance::lateral_offset_mm);
  m.def(
      "compute_guidance",
      [](const ArrayD& tip, const ArrayD& axis, const ArrayD& entry, const ArrayD& target) {
        return ComputeGuidance(VectorFromArray(tip, "tip"), VectorFromArray(axis, "axis"),
                               VectorFromArray(entry, "entry"), VectorFromArray(target, "target"));
      },
      py::arg("tip"), py::arg("axis"), py::arg("entry"), py::arg("target"),
      "guidance of a tip and axis against entry -> target, all in one frame (ComputeGuidance)");
}

void DefineState(py::module_& m) {
  py::class_<PlacedTrajectory>(m, "PlacedTrajectory", "a planned trajectory placed by Eq. (8)")
      .def_property_readonly(
          "entry_in_world",
          [](const PlacedTrajectory& p) { return ArrayFromVector(p.entry_in_world); })
      .def_property_readonly(
          "target_in_world",
          [](const PlacedTrajectory& p) { return ArrayFromVector(p.target_in_world); })
      .def_property_readonly(
          "entry_in_tool",
          [](const PlacedTrajectory& p) { return ArrayFromVector(p.entry_in_tool); })
      .def_property_readonly("target_in_tool", [](const PlacedTrajectory& p) {
        return ArrayFromVector(p.target_in_tool);
      });
  using S = NavigationState;
  py::class_<S>(m, "NavigationState", "what the Navigator knows after one frame")
      .def_readonly("timestamp_s", &S::timestamp_s)
      .def_property_readonly(
          "status", [](const S& s) { return ToString(s.status); },
          "'TRACKING', 'HOLDING', 'REFERENCE_LOST' or 'NO_WORLD_POSE'")
      .def_property_readonly("reference_status",
                             [](const S& s) { return ToString(s.reference_status); })
      .def_readonly("reference_age_s", &S::reference_age_s)
      .def_readonly("reference_rotation_sd_rad", &S::reference_rotation_sd_rad,
                    "expected RMS angle error of the placing reference orientation, or None")
      .def_readonly("reference_settling", &S::reference_settling,
                    "that error is above the settled limit (docs/navigation.md 1.2)")
      .def_readonly("detected_markers", &S::detected_markers)
      .def_property_readonly("ahat_from_tool",
                             [](const S& s) { return OptionalArrayFromRigid(s.ahat_from_tool); })
      .def_property_readonly("world_from_rig",
                             [](const S& s) { return OptionalArrayFromRigid(s.world_from_rig); })
      .def_property_readonly(
          "world_from_image", [](const S& s) { return OptionalArrayFromRigid(s.world_from_image); },
          "Eq. (8): world_from_rig rig_from_ahat ahat_from_tool tool_from_image, or None")
      .def_readonly("plan", &S::plan)
      .def_property_readonly("instrument_status",
                             [](const S& s) -> py::object {
                               if (!s.instrument_status) return py::none();
                               return py::str(ToString(*s.instrument_status));
                             })
      .def_property_readonly(
          "ahat_from_instrument",
          [](const S& s) { return OptionalArrayFromRigid(s.ahat_from_instrument); })
      .def_property_readonly(
          "tool_from_instrument",
          [](const S& s) { return OptionalArrayFromRigid(s.tool_from_instrument); })
      .def_property_readonly("tip_in_world",
                             [](const S& s) { return OptionalVector(s.tip_in_world); })
      .def_readonly("active_trajectory", &S::active_trajectory)
      .def_readonly("guidance", &S::guidance);
}

}  // namespace

void DefineNavigation(py::module_& m) {
  DefinePlan(m);
  DefineState(m);
  py::class_<Navigator>(m, "Navigator",
                        "phase 3 per frame: markers, Eq. (2), tracking, Eq. (8), plan, guidance")
      .def(py::init(&MakeNavigator), py::arg("camera"), py::arg("reference"),
           py::arg("tool_from_image"), py::arg("plan") = std::vector<Trajectory>{},
           py::arg("instrument") = py::none(), py::arg("marker_range") = py::none(),
           py::arg("stale_after_s") = 0.1, py::arg("filter_enabled") = false,
           py::arg("ab_threshold") = kMarkerAbThreshold, py::arg("instrument_axis") = py::none())
      .def("process", &Navigator::Process, py::arg("frame"),
           "one frame (in time order) -> NavigationState (Navigator::Process)")
      .def(
          "place",
          [](Navigator& navigator, double timestamp_s, const std::vector<TrackedTool>& tools,
             const py::object& world_from_rig, int detected_markers) {
            return navigator.Place(timestamp_s, TrackingFrame{timestamp_s, tools},
                                   OptionalRigidFromObject(world_from_rig), detected_markers);
          },
          py::arg("timestamp_s"), py::arg("tracked"), py::arg("world_from_rig"),
          py::arg("detected_markers") = 0,
          "Eq. (8) and the plan from a ToolTracker result ([reference, instrument?] TrackedTool, "
          "f_rf already applied) and the frame's world_from_rig (Navigator::Place)")
      .def("select_trajectory", &Navigator::SelectTrajectory, py::arg("index"));
}

}  // namespace tofnav::python
