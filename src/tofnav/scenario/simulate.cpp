// SPDX-License-Identifier: BSD-3-Clause
// The simulate composition: pre-operative files, then the frame loop writing three streams.
#include "tofnav/scenario/simulate.hpp"

#include <bit>
#include <cstring>
#include <utility>

#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/scenario/patient_head.hpp"
#include "tofnav/scenario/plan_markups.hpp"
#include "tofnav/scenario/truth_json.hpp"
#include "tofnav/sim/random.hpp"
#include "tofnav/sim/scenario_sanity.hpp"
#include "tofnav/sim/simulator.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {
namespace {

static_assert(std::endian::native == std::endian::little, "truth_range_f32.bin is little-endian");

constexpr const char* kRecordingName = "rm_depth_ahat.bin";
constexpr const char* kCalibrationName = "calibration/rm_depth_ahat";
constexpr const char* kTruthName = "truth.json";
constexpr const char* kTruthRangeName = "truth_range_f32.bin";
constexpr const char* kCtName = "ct.nrrd";
constexpr const char* kSkinName = "skin_truth.ply";
constexpr const char* kPlanName = "plan.mrk.json";
constexpr const char* kLandmarksName = "landmarks.mrk.json";
constexpr const char* kToolsDir = "tools";
constexpr const char* kMeshesDir = "meshes";

// ct.nrrd, skin_truth.ply and plan.mrk.json of the scenario's patient.
void WritePatientFiles(const sim::Scenario& s, const std::filesystem::path& out_dir,
                       std::vector<std::pair<std::string, std::string>>& files) {
  const sim::Patient& patient = *s.patient;
  const TriangleMesh& skin = s.scene.objects[static_cast<std::size_t>(patient.object)].mesh;
  const std::filesystem::path real_ct = CtPathOfHeadSource(patient.head_source);
  if (patient.write_ct && !real_ct.empty()) {  // the real CT is the pre-operative image
    CtVolume volume = ReadVolume(real_ct);
    WriteVolume(out_dir / kCtName, volume, {.sample_type = VolumeSampleType::kInt16});
    files.emplace_back("ct", kCtName);
  } else if (patient.write_ct) {
    sim::SyntheticCt ct = sim::SynthesizeHeadCt(skin, patient.anatomy, patient.ct,
                                                sim::StreamSeed(s.seed, sim::SeedStream::kCtNoise));
    CtVolume volume;
    volume.dims = ct.dims;
    volume.values = std::move(ct.values_hu);
    volume.image_from_ijk = ct.image_from_ijk;
    volume.modality = "CT";
    volume.name = "tofnav synthetic CT (" + patient.head_source + ")";
    WriteVolume(out_dir / kCtName, volume, {.sample_type = VolumeSampleType::kInt16});
    files.emplace_back("ct", kCtName);
  }
  WriteMesh(out_dir / kSkinName, skin);
  files.emplace_back("skin", kSkinName);
  WriteTrajectoryMarkups(out_dir / kPlanName, patient.plan);
  files.emplace_back("plan", kPlanName);
  if (!patient.landmarks.empty()) {  // what tofnav verify asks the user to touch
    WriteLandmarkMarkups(out_dir / kLandmarksName, patient.landmarks);
    files.emplace_back("landmarks", kLandmarksName);
  }
}

// meshes/<object>.ply: every scene object's mesh in its own frame (the mesh truth.json's
// objects.<name> counts), so evaluators need not rebuild the scenario (docs/simulator.md). Object
// names are file names: Scenario::Check limits them to [A-Za-z0-9_-] and makes them unique.
void WriteObjectMeshes(const sim::Scenario& s, const std::filesystem::path& out_dir,
                       std::vector<std::pair<std::string, std::string>>& files) {
  std::filesystem::create_directories(out_dir / kMeshesDir);
  for (const sim::SceneObject& o : s.scene.objects) {
    const std::string name = std::string(kMeshesDir) + "/" + o.name + ".ply";
    WriteMesh(out_dir / name, o.mesh);  // binary PLY, atomic (WriteFileAtomically)
    files.emplace_back("mesh:" + o.name, name);
  }
}

// tools/headframe.json: the headframe tools (HeadframeTools) joined into one rigid tool in the
// frame of the first, the markers of each mapped by first_from_tool (both share the patient's
// mount, so the scene poses give it). Type and diameter of the first tool's first marker.
void WriteHeadframeTool(const sim::Scenario& s, const std::filesystem::path& out_dir,
                        std::vector<std::pair<std::string, std::string>>& files) {
  const std::vector<int> parts = HeadframeTools(s);
  if (parts.empty()) return;
  const sim::Tool& first = s.scene.tools[static_cast<std::size_t>(parts.front())];
  ToolGeometry tool;
  tool.name = kHeadframeToolName;
  tool.marker_type = first.markers.front().shape == sim::MarkerShape::kDisc ? MarkerType::kDisc
                                                                            : MarkerType::kSphere;
  tool.marker_diameter_mm = first.markers.front().diameter_mm;
  for (const int p : parts) {
    const sim::Tool& part = s.scene.tools[static_cast<std::size_t>(p)];
    const Rigid3d first_from_part = first.scene_from_tool.Inverse() * part.scene_from_tool;
    for (const sim::Marker& m : part.markers)
      tool.markers_in_tool.push_back(first_from_part * m.centre_in_tool);
  }
  tool.Check();
  const std::string name = std::string(kToolsDir) + "/" + kHeadframeToolName + ".json";
  std::filesystem::create_directories(out_dir / kToolsDir);
  WriteToolJson(out_dir / name, tool);
  files.emplace_back(std::string("tool:") + kHeadframeToolName, name);
}

// tools/<tool>.json of every scene tool a tracker can use (>= 3 valid markers; a tool failing
// ToolGeometry::Check, e.g. two stickers, is skipped). Type and diameter of the first marker.
void WriteToolFiles(const sim::Scenario& s, const std::filesystem::path& out_dir,
                    std::vector<std::pair<std::string, std::string>>& files) {
  for (const sim::Tool& t : s.scene.tools) {
    if (t.markers.empty()) continue;
    ToolGeometry tool;
    tool.name = t.name;
    tool.marker_type = t.markers.front().shape == sim::MarkerShape::kDisc ? MarkerType::kDisc
                                                                          : MarkerType::kSphere;
    tool.marker_diameter_mm = t.markers.front().diameter_mm;
    for (const sim::Marker& m : t.markers) tool.markers_in_tool.push_back(m.centre_in_tool);
    tool.tip_in_tool = t.tip_in_tool;  // a pointer's true tip (what pivot calibration finds)
    try {
      tool.Check();
    } catch (const std::exception&) {
      continue;
    }
    const std::string name = std::string(kToolsDir) + "/" + t.name + ".json";
    std::filesystem::create_directories(out_dir / kToolsDir);
    WriteToolJson(out_dir / name, tool);
    files.emplace_back("tool:" + t.name, name);
  }
  WriteHeadframeTool(s, out_dir, files);
}

// Adds one to the tools of `frame` whose every marker has a pixel.
void CountFullyVisible(const sim::Scene& scene, const sim::SimulatedFrame& frame,
                       std::vector<std::int64_t>& counts) {
  std::vector<std::size_t> seen(scene.tools.size(), 0);
  for (const sim::MarkerTruth& m : frame.render.markers) {
    if (m.pixel_count > 0) ++seen[static_cast<std::size_t>(m.tool)];
  }
  for (std::size_t t = 0; t < scene.tools.size(); ++t) {
    if (seen[t] == scene.tools[t].markers.size()) ++counts[t];
  }
}

}  // namespace

void SimulateOptions::Check() const {
  Require(!frames || *frames >= 1, "SimulateOptions.frames must be >= 1");
  Require(!bitrate_bps || *bitrate_bps >= 10000, "SimulateOptions.bitrate_bps must be >= 10000");
}

SimulateResult RunSimulation(sim::Scenario scenario, const std::filesystem::path& out_dir,
                             const SimulateOptions& options) {
  options.Check();
  if (options.frames) scenario.frames = *options.frames;
  if (options.seed) scenario.seed = *options.seed;
  scenario.Check();
  sim::RequireMarkersClear(scenario);
  std::filesystem::create_directories(out_dir);

  sim::Simulator simulator(scenario, options.camera);
  if (scenario.camera.device) {  // the device's own bytes (its f32 extrinsics unrounded)
    WriteHl2ssMode2AsFolder(out_dir / "calibration",
                            ReadHl2ssCalibrationAsMode2(scenario.camera.device_folder));
  } else {
    WriteHl2ssCalibration(out_dir / "calibration", simulator.calibration());
  }
  TruthRunInfo info;
  info.profile = Hl2ssStreamProfileName(options.profile);
  info.files = {{"recording", kRecordingName}, {"calibration", kCalibrationName}};
  if (options.truth_depth) info.files.emplace_back("truth_range", kTruthRangeName);
  if (scenario.patient) WritePatientFiles(scenario, out_dir, info.files);
  WriteObjectMeshes(scenario, out_dir, info.files);
  WriteToolFiles(scenario, out_dir, info.files);

  Hl2ssWriterOptions writer_options;
  writer_options.profile_z = options.profile.profile_z;
  writer_options.profile_ab = options.profile.profile_ab;
  writer_options.bitrate_bps = options.bitrate_bps;
  Hl2ssRecordingWriter recording(out_dir / kRecordingName, writer_options);
  SimulationTruthWriter truth(out_dir / kTruthName, scenario, info);
  std::optional<AtomicFileWriter> truth_range;
  if (options.truth_depth) truth_range.emplace(out_dir / kTruthRangeName);

  SimulateResult result;
  result.fully_visible_frames.assign(scenario.scene.tools.size(), 0);
  const auto total = static_cast<std::size_t>(scenario.frames);
  std::uint64_t first_ticks = 0, last_ticks = 0;
  while (!simulator.done()) {
    const sim::SimulatedFrame frame = simulator.Next();
    recording.Append(frame.render.frame);
    truth.Append(frame);
    CountFullyVisible(scenario.scene, frame, result.fully_visible_frames);
    if (truth_range) {
      const std::span<const float> range = frame.render.truth_range_mm.pixels();
      truth_range->Write({reinterpret_cast<const std::uint8_t*>(range.data()), range.size_bytes()});
    }
    if (frame.index == 0) first_ticks = frame.render.frame.host_ticks;
    last_ticks = frame.render.frame.host_ticks;
    ++result.frames;
    if (options.progress) options.progress(static_cast<std::size_t>(result.frames), total);
  }
  result.dropped_slots = simulator.dropped_slots();
  recording.Close();
  truth.Close(result.dropped_slots);
  if (truth_range) truth_range->Commit();
  result.duration_s = static_cast<double>(last_ticks - first_ticks) * kSecondsPerHostTick;
  for (const auto& [role, name] : info.files) result.files.emplace_back(name);
  for (std::size_t t = 0; t < scenario.scene.tools.size(); ++t) {
    if (result.fully_visible_frames[t] > 0) continue;
    const sim::Tool& tool = scenario.scene.tools[t];
    result.warnings.push_back("tool '" + tool.name + "' is never fully visible (all " +
                              std::to_string(tool.markers.size()) + " markers) in the " +
                              std::to_string(result.frames) + " rendered frames");
  }
  result.files.emplace_back(kTruthName);
  return result;
}

}  // namespace tofnav
