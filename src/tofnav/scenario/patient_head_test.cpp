// SPDX-License-Identifier: BSD-3-Clause
// ct: heads: the skin of a CT becomes the head, centred where the phantom's anatomy was.
#include "tofnav/scenario/patient_head.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "tofnav/imaging/skin.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/scenario/physical_skin.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/synthetic_ct.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {
namespace {

// The phantom's CT at 3 mm with its LPS origin moved by `shift_mm`, written as NRRD.
std::filesystem::path WriteShiftedPhantomCt(const std::filesystem::path& dir,
                                            const Eigen::Vector3d& shift_mm) {
  const sim::PatientHead phantom = sim::PhantomHead();
  sim::SyntheticCtOptions options;
  options.spacing_mm = 3.0;
  options.subsamples = 1;
  sim::SyntheticCt ct = sim::SynthesizeHeadCt(phantom.skin_in_image, phantom.anatomy, options, 1);
  CtVolume volume;
  volume.dims = ct.dims;
  volume.values = std::move(ct.values_hu);
  volume.image_from_ijk = ct.image_from_ijk;
  volume.image_from_ijk.block<3, 1>(0, 3) += shift_mm;
  volume.modality = "CT";
  const std::filesystem::path path = dir / "head.nrrd";
  WriteVolume(path, volume, {.sample_type = VolumeSampleType::kInt16});
  return path;
}

Eigen::Vector3d BoxCentre(const TriangleMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
  return box.center();
}

TEST(LoadPatientHead, ACtHeadIsItsSkinAndTakesThePhantomsPlaceInBuiltins) {
  constexpr double kSkinShiftTolMm = 1.5;  // half a 3 mm voxel: threshold and clustering
  const testing::TempDir dir("ct_head");
  const Eigen::Vector3d shift(40.0, -25.0, 300.0);
  const std::filesystem::path path = WriteShiftedPhantomCt(dir.path(), shift);
  const sim::PatientHead head = LoadPatientHead("ct:" + path.string());
  const sim::PatientHead phantom = sim::PhantomHead();
  EXPECT_EQ(CtPathOfHeadSource(head.source), path);
  EXPECT_TRUE(CtPathOfHeadSource(phantom.source).empty());
  ASSERT_FALSE(head.skin_in_image.triangles.empty());
  const Eigen::Vector3d moved = BoxCentre(head.skin_in_image) - BoxCentre(phantom.skin_in_image);
  EXPECT_LT((moved - shift).norm(), kSkinShiftTolMm) << moved.transpose();

  // In a built-in, the CT head's anatomy centre lands where the phantom's does.
  const sim::Scenario with_ct = sim::BuiltinScenario("evd-usecase", &head);
  const sim::Scenario with_phantom = sim::BuiltinScenario("evd-usecase");
  const auto head_centre_in_mount = [](const sim::Scenario& s, const sim::PatientHead& h) {
    const sim::SceneObject& o = s.scene.objects[static_cast<std::size_t>(s.patient->object)];
    return Eigen::Vector3d(o.scene_from_object * h.anatomy.centre_in_image);
  };
  EXPECT_LT(
      (head_centre_in_mount(with_ct, head) - head_centre_in_mount(with_phantom, phantom)).norm(),
      kSkinShiftTolMm);
  EXPECT_THROW(sim::BuiltinScenario("materials", &head), PreconditionError);
}

TEST(LoadPatientHead, ACtHeadIsRenderedWithoutTheImagesNoise) {
  const testing::TempDir dir("ct_head_noise");
  const std::filesystem::path path = WriteShiftedPhantomCt(dir.path(), Eigen::Vector3d::Zero());
  const sim::PatientHead head = LoadPatientHead("ct:" + path.string());
  SkinOptions options;
  options.decimation_cell_mm = 1.0;  // as LoadPatientHead extracts it
  const TriangleMesh iso = ExtractSkin(ReadVolume(path), options).mesh;
  const TriangleMesh physical = SmoothPhysicalSkin(iso);
  ASSERT_EQ(head.skin_in_image.vertices.size(), physical.vertices.size());
  double largest_move_mm = 0.0;
  for (std::size_t i = 0; i < physical.vertices.size(); ++i) {
    EXPECT_EQ(head.skin_in_image.vertices[i], physical.vertices[i]) << i;
    largest_move_mm = std::max(largest_move_mm, (physical.vertices[i] - iso.vertices[i]).norm());
  }
  EXPECT_GT(largest_move_mm, 0.0);  // the 3 mm voxels' steps are smoothed
}

TEST(LoadPatientHead, RefusesUnknownSpecs) {
  EXPECT_THROW(LoadPatientHead("skull"), PreconditionError);
  EXPECT_THROW(LoadPatientHead("ct:/nonexistent/head.nrrd"), IoError);
}

}  // namespace
}  // namespace tofnav
