// SPDX-License-Identifier: BSD-3-Clause
// Occluders: capsule, hand, drape and instrument geometry, pass motions, and the hand's shadow in
// a rendered frame against an analytic ray-capsule test.
#include "tofnav/sim/occluders.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "sim_test_scenes.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav::sim {
namespace {

// Distance from p to the segment a-b.
double SegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Smallest distance between the line through the origin along unit d and the segment a-b (the
// hand lies in front of the camera, so the line's nearest points have t > 0).
double RaySegmentDistance(const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b) {
  const Eigen::Vector3d a_across = a - a.dot(d) * d, e = b - a;
  const Eigen::Vector3d e_across = e - e.dot(d) * d;
  const double s = std::clamp(-a_across.dot(e_across) / e_across.squaredNorm(), 0.0, 1.0);
  return (a_across + s * e_across).norm();
}

TEST(Occluders, CapsuleHasItsRadiusAroundTheAxisAndFacesOut) {
  const TriangleMesh mesh = CapsuleMesh(40.0, 200.0, 32);
  const Eigen::Vector3d a(-80.0, 0.0, 0.0), b(80.0, 0.0, 0.0);  // axis between the cap centres
  double min_x = 0.0, max_x = 0.0;
  for (const Eigen::Vector3d& v : mesh.vertices) {
    EXPECT_NEAR(SegmentDistance(v, a, b), 20.0, 1e-9);
    min_x = std::min(min_x, v.x());
    max_x = std::max(max_x, v.x());
  }
  EXPECT_NEAR(min_x, -100.0, 1e-9);
  EXPECT_NEAR(max_x, 100.0, 1e-9);
  for (const Eigen::Vector3i& t : mesh.triangles) {  // winding: away from the axis
    const Eigen::Vector3d p0 = mesh.vertices[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d p1 = mesh.vertices[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d p2 = mesh.vertices[static_cast<std::size_t>(t[2])];
    const Eigen::Vector3d centre = (p0 + p1 + p2) / 3.0;
    const Eigen::Vector3d axis_point(std::clamp(centre.x(), -80.0, 80.0), 0.0, 0.0);
    const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
    if (n.norm() > 1e-9) {
      EXPECT_GT(n.dot(centre - axis_point), 0.0);
    }
  }
  EXPECT_THROW(CapsuleMesh(50.0, 40.0), PreconditionError);
}

TEST(Occluders, HandSpansForearmAndHand) {
  const HandOptions o;  // forearm 65 x 250 mm, hand 45 x 180 mm
  const TriangleMesh hand = HandMesh(o);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const Eigen::Vector3d& v : hand.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_NEAR(lo.x(), -250.0, 1e-9);
  EXPECT_NEAR(hi.x(), 180.0 - 22.5, 1e-9);
  EXPECT_NEAR(hi.y(), 32.5, 1e-9);  // the forearm is the thicker part
  EXPECT_NEAR(lo.z(), -32.5, 1e-9);
}

TEST(Occluders, DrapeLeavesItsOpeningFoldsWithinTheAmplitudeAndRepeatsWithItsSeed) {
  DrapeOptions o;
  const TriangleMesh drape = DrapeMesh(o);
  double max_abs_z = 0.0, min_opening = 1e9;
  for (const Eigen::Vector3d& v : drape.vertices) {
    max_abs_z = std::max(max_abs_z, std::abs(v.z()));
    min_opening = std::min(min_opening, std::hypot(v.x() / o.opening_semi_axes_mm.x(),
                                                   v.y() / o.opening_semi_axes_mm.y()));
    EXPECT_LE(std::abs(v.x()), 0.5 * o.width_mm + 1e-9);
    EXPECT_LE(std::abs(v.y()), 0.5 * o.height_mm + 1e-9);
  }
  EXPECT_NEAR(min_opening, 1.0, 1e-9);  // the opening's rim, nothing inside
  EXPECT_LE(max_abs_z, o.wrinkle_amplitude_mm);
  EXPECT_GT(max_abs_z, 0.3 * o.wrinkle_amplitude_mm);  // it is wrinkled
  for (const Eigen::Vector3d& n : drape.vertex_normals) EXPECT_GT(n.z(), 0.5);
  EXPECT_EQ(DrapeMesh(o).vertices, drape.vertices);
  o.seed = 2;
  EXPECT_NE(DrapeMesh(o).vertices, drape.vertices);
  o.wrinkle_amplitude_mm = 0.0;
  for (const Eigen::Vector3d& v : DrapeMesh(o).vertices) EXPECT_EQ(v.z(), 0.0);
}

TEST(Occluders, InstrumentRodRunsFromUnderTheArrayToItsTip) {
  const InstrumentOptions o;  // spheres-four, rod 4 x 200 mm
  const Eigen::Vector3d tip = InstrumentTipInTool(o);
  const Tool tool = ToolPreset(o.preset, "instrument", 0);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Marker& m : tool.markers) centroid += m.centre_in_tool / 4.0;
  EXPECT_NEAR(tip.x(), centroid.x(), 1e-9);
  EXPECT_NEAR(tip.y(), centroid.y() - 200.0, 1e-9);
  EXPECT_NEAR(tip.z(), -3.0, 1e-9);  // 1 mm behind the z = 0 plane
  double min_y = 1e9;
  for (const Eigen::Vector3d& v : InstrumentRodMesh(o).vertices) {
    min_y = std::min(min_y, v.y());
    EXPECT_LE(v.z(), -1.0 + 1e-9);  // clear of the markers (spheres reach down to z = 2.25)
  }
  EXPECT_NEAR(min_y, tip.y(), 1e-9);
}

TEST(Occluders, PassesEnterHoverLeaveAndPark) {
  const Rigid3d parked(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 5000.0, 0.0));
  Pass pass;
  pass.enter_slot = 100;
  pass.move_slots = 10;
  pass.hover_slots = 20;
  pass.hover = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 400.0));
  pass.approach_mm = {-300.0, 0.0, 0.0};
  pass.leave_mm = {0.0, 300.0, 0.0};
  const Motion motion = PassesMotion(parked, {pass});
  const auto at = [&](std::int64_t slot) { return MotionPose(motion, slot, 45.0, 0).translation; };
  EXPECT_EQ(at(0), parked.translation);
  EXPECT_EQ(at(99), parked.translation);
  EXPECT_EQ(at(100), Eigen::Vector3d(-300.0, 0.0, 400.0));
  EXPECT_TRUE(at(105).isApprox(Eigen::Vector3d(-150.0, 0.0, 400.0)));  // halfway in
  EXPECT_EQ(at(110), pass.hover.translation);
  EXPECT_EQ(at(130), pass.hover.translation);
  EXPECT_EQ(at(140), Eigen::Vector3d(0.0, 300.0, 400.0));
  EXPECT_EQ(at(141), parked.translation);
  EXPECT_EQ(MotionKeySlots(motion), (std::vector<std::int64_t>{0, 99, 100, 110, 130, 140, 141}));
  Pass overlapping = pass;
  overlapping.enter_slot = 120;
  EXPECT_THROW(PassesMotion(parked, {pass, overlapping}), PreconditionError);
}

// The hand across the view 400 mm away in front of a wall at 700 mm: every pixel whose centre ray
// passes within a capsule's radius of its axis (ray-capsule test) shows the hand, no other does.
TEST(Occluders, HandHidesExactlyThePixelsOfItsCapsules) {
  // Rim pixels can differ: the 32-segment capsules' facets cut 0.16 mm (forearm) inside the true
  // surface, about 0.1 px at 400 mm. 0.5 % of the hand's pixels covers such rims.
  constexpr double kMaxMismatchFraction = 0.005;
  Scene scene = testing::BoardScene(DiffuseMaterial(0.5), 700.0);
  const int skin = scene.AddMaterial(SkinMaterial());
  const Rigid3d ahat_from_hand(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                               Eigen::Vector3d(40.0, -20.0, 400.0));
  const int hand = scene.AddObject("hand", HandMesh(), skin, ahat_from_hand);
  std::mt19937_64 rng(3);
  const RenderResult r =
      RenderAhatFrame(scene, testing::TestCamera(), Rigid3d::Identity(), IdealRenderOptions(), rng);
  const HandOptions o;
  const Eigen::Vector3d forearm[2] = {ahat_from_hand * Eigen::Vector3d(-250.0 + 32.5, 0, 0),
                                      ahat_from_hand * Eigen::Vector3d(-32.5, 0, 0)};
  const Eigen::Vector3d palm[2] = {ahat_from_hand * Eigen::Vector3d::Zero(),
                                   ahat_from_hand * Eigen::Vector3d(180.0 - 45.0, 0, 0)};
  int hand_pixels = 0, mismatches = 0;
  for (int v = 0; v < r.truth_object.height(); ++v) {
    for (int u = 0; u < r.truth_object.width(); ++u) {
      if (r.truth_object(u, v) < 0) continue;  // outside the lens's field
      const Eigen::Vector3d d = testing::TestCamera().PixelRay(u, v).cast<double>().normalized();
      const bool expected =
          RaySegmentDistance(d, forearm[0], forearm[1]) < 0.5 * o.forearm_diameter_mm ||
          RaySegmentDistance(d, palm[0], palm[1]) < 0.5 * o.hand_diameter_mm;
      const bool seen = r.truth_object(u, v) == hand;
      hand_pixels += expected ? 1 : 0;
      mismatches += expected != seen ? 1 : 0;
    }
  }
  std::printf("hand: %d pixels expected, %d differ\n", hand_pixels, mismatches);
  EXPECT_GT(hand_pixels, 5000);  // a hand at 400 mm fills a good part of the view
  EXPECT_LE(mismatches, kMaxMismatchFraction * hand_pixels);
}

}  // namespace
}  // namespace tofnav::sim
