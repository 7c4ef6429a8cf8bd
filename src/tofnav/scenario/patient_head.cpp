// SPDX-License-Identifier: BSD-3-Clause
// Patient heads named by a scenario or on the command line: phantom, a skin mesh or a real CT.
#include "tofnav/scenario/patient_head.hpp"

#include "tofnav/core/require.hpp"
#include "tofnav/imaging/skin.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/scenario/physical_skin.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {
namespace {

constexpr std::string_view kMesh = "mesh:", kCt = "ct:";

// Skin meshes of a 0.5 mm CT have millions of triangles; 1 mm clustering keeps the shape to a
// fraction of a voxel and makes ray casting fast.
constexpr double kCtSkinDecimationMm = 1.0;

}  // namespace

sim::PatientHead LoadPatientHead(const std::string& spec, const std::filesystem::path& base,
                                 const sim::HeadPhantomOptions& phantom) {
  if (spec == "phantom") return sim::PhantomHead(phantom);
  if (spec.starts_with(kMesh)) {
    const std::filesystem::path path = base / spec.substr(kMesh.size());
    return sim::MeshHead(ReadMesh(path), std::string(kMesh) + path.string());
  }
  if (spec.starts_with(kCt)) {
    const std::filesystem::path path = base / spec.substr(kCt.size());
    SkinOptions options;
    options.decimation_cell_mm = kCtSkinDecimationMm;
    const SkinResult skin = ExtractSkin(ReadVolume(path), options);
    // The patient is smooth where the image's iso-surface carries the image's noise
    // (docs/simulator.md "The patient's skin").
    return sim::MeshHead(SmoothPhysicalSkin(skin.mesh), std::string(kCt) + path.string());
  }
  Require(false, "head '" + spec + "': expected \"phantom\", \"mesh:<path>\" or \"ct:<path>\"");
  return {};
}

std::filesystem::path CtPathOfHeadSource(const std::string& source) {
  return source.starts_with(kCt) ? std::filesystem::path(source.substr(kCt.size()))
                                 : std::filesystem::path();
}

}  // namespace tofnav
