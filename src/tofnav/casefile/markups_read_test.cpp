// SPDX-License-Identifier: BSD-3-Clause
// Planned trajectories from markups: the simulator's plan read back, LPS/RAS, .fcsv, rejections.
#include "tofnav/casefile/markups_read.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "tofnav/io/io_error.hpp"
#include "tofnav/scenario/plan_markups.hpp"

namespace tofnav {
namespace {

std::span<const std::uint8_t> Bytes(const std::string& text) {
  return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

std::string ErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const IoError& e) {
    return e.what();
  }
  return "no error";
}

// The simulator's plan.mrk.json (writer in plan_markups.cpp) reads back bit for bit.
TEST(TrajectoryMarkups, ReadsTheSimulatorsPlanExactly) {
  const std::vector<sim::Trajectory> plan = {
      {"right_kocher", {31.123456789012345, -52.5, 70.25}, {1.0 / 3.0, -12.0, 18.5}},
      {"left_kocher", {-30.0, -50.0, 1e-7}, {-2.0, -11.0, 19.0}}};
  const std::string text = EncodeTrajectoryMarkups(plan);
  const std::vector<Trajectory> read = DecodeTrajectoryMarkups(Bytes(text));
  ASSERT_EQ(read.size(), plan.size());
  for (std::size_t i = 0; i < plan.size(); ++i) {
    EXPECT_EQ(read[i].name, plan[i].name);
    EXPECT_EQ(read[i].entry_lps_mm, plan[i].entry_in_image);  // exact: shortest round trip
    EXPECT_EQ(read[i].target_lps_mm, plan[i].target_in_image);
  }
}

TEST(TrajectoryMarkups, ConvertsRasSkipsUndefinedAndDefaultsToLps) {
  const std::string text = R"({"markups":[
    {"type":"Line","name":"ras","coordinateSystem":"RAS","controlPoints":[
      {"position":[1,2,3],"positionStatus":"defined"},
      {"position":[9,9,9],"positionStatus":"preview"},
      {"position":[4,5,6]}]},
    {"type":"Fiducial","name":"landmarks","controlPoints":[{"label":"nasion","position":[0,0,0]}]},
    {"type":"Line","coordinateUnits":"um","controlPoints":[
      {"position":[1000,2000,3000]},{"position":[-1000,0,500]}],"extra":{"ignored":true}},
    {"type":"Fiducial","name":"pair","controlPoints":[
      {"label":"Target","position":[7,8,9]},{"label":"ENTRY","position":[1,1,1]}]}]})";
  const std::vector<Trajectory> plan = DecodeTrajectoryMarkups(Bytes(text));
  ASSERT_EQ(plan.size(), 3U);
  EXPECT_EQ(plan[0].name, "ras");
  EXPECT_EQ(plan[0].entry_lps_mm, Eigen::Vector3d(-1, -2, 3));  // RAS -> LPS: x, y negated
  EXPECT_EQ(plan[0].target_lps_mm, Eigen::Vector3d(-4, -5, 6));
  EXPECT_EQ(plan[1].name, "trajectory 2");  // unnamed: numbered among the trajectories
  EXPECT_EQ(plan[1].entry_lps_mm, Eigen::Vector3d(1, 2, 3));  // um -> mm, LPS by default
  EXPECT_EQ(plan[1].target_lps_mm, Eigen::Vector3d(-1, 0, 0.5));
  EXPECT_EQ(plan[2].name, "pair");
  EXPECT_EQ(plan[2].entry_lps_mm, Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(plan[2].target_lps_mm, Eigen::Vector3d(7, 8, 9));
}

TEST(TrajectoryMarkups, RejectsWhatCannotBeATrajectory) {
  using ::testing::HasSubstr;
  const auto decode = [](const std::string& text) {
    return ErrorOf([&] { DecodeTrajectoryMarkups(Bytes(text), "plan.mrk.json"); });
  };
  EXPECT_THAT(decode(R"({"markups":[)"), HasSubstr("plan.mrk.json"));
  EXPECT_THAT(decode(R"({"markups":[)"), HasSubstr("at byte 12"));
  EXPECT_THAT(decode(R"({"markups":[{"type":"Line","controlPoints":[{"position":[1,2,3]}]}]})"),
              HasSubstr("exactly 2 defined control points"));
  EXPECT_THAT(decode(R"({"markups":[{"type":"Line","coordinateSystem":"IJK"}]})"),
              HasSubstr("coordinateSystem"));
  EXPECT_THAT(decode(R"({"markups":[{"type":"Line","controlPoints":[{"position":[1,2]},)"
                     R"({"position":[1,2,3]}]}]})"),
              HasSubstr("markups[0]: controlPoints[0].position: expected 3 numbers"));
  EXPECT_THAT(decode(R"({"markups":[{"type":"Fiducial","controlPoints":[)"
                     R"({"label":"entry","position":[1,2,3]}]}]})"),
              HasSubstr("both an Entry and a Target"));
  EXPECT_THAT(decode(R"({"markups":[{"type":"ROI"}]})"), HasSubstr("no trajectory"));
  EXPECT_THAT(decode(R"([1,2])"), HasSubstr("expected a JSON object"));
}

TEST(TrajectoryFcsv, PairsRowsAndConvertsTheCoordinateSystem) {
  const std::string header =
      "# Markups fiducial file version = 4.11\n# CoordinateSystem = LPS\n"
      "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n";
  const std::string rows =
      "vtkMRMLMarkupsFiducialNode_0,1.5,-2,3,0,0,0,1,1,1,0,\"right, Kocher\",\"a, b\",\n"
      "vtkMRMLMarkupsFiducialNode_1,4,5,6e1,0,0,0,1,1,1,0,target,,\r\n";
  const std::vector<Trajectory> lps = DecodeTrajectoryFcsv(Bytes(header + rows));
  ASSERT_EQ(lps.size(), 1U);
  EXPECT_EQ(lps[0].name, "right, Kocher");
  EXPECT_EQ(lps[0].entry_lps_mm, Eigen::Vector3d(1.5, -2, 3));
  EXPECT_EQ(lps[0].target_lps_mm, Eigen::Vector3d(4, 5, 60));
  // Legacy files: no CoordinateSystem line (or "0") means RAS; a reordered columns line.
  const std::vector<Trajectory> ras =
      DecodeTrajectoryFcsv(Bytes("# columns = label,z,y,x\ne,3,2,1\nt,6,5,4\n"));
  ASSERT_EQ(ras.size(), 1U);
  EXPECT_EQ(ras[0].name, "e");
  EXPECT_EQ(ras[0].entry_lps_mm, Eigen::Vector3d(-1, -2, 3));
  EXPECT_EQ(ras[0].target_lps_mm, Eigen::Vector3d(-4, -5, 6));
}

TEST(TrajectoryFcsv, RejectsOddRowsIjkAndBadNumbers) {
  using ::testing::HasSubstr;
  const auto decode = [](const std::string& text) {
    return ErrorOf([&] { DecodeTrajectoryFcsv(Bytes(text), "plan.fcsv"); });
  };
  EXPECT_THAT(decode("a,1,2,3\n"), HasSubstr("odd number of points"));
  EXPECT_THAT(decode("# CoordinateSystem = 2\n"), HasSubstr("IJK unsupported"));
  EXPECT_THAT(decode("a,1,2,3\nb,1,x,3\n"), HasSubstr("at byte 8"));
  EXPECT_THAT(decode("a,1,2,3\nb,1,x,3\n"), HasSubstr("found 'x'"));
  EXPECT_THAT(decode("a,1,2\n"), HasSubstr("expected x, y and z"));
  EXPECT_THAT(decode("# nothing\n"), HasSubstr("no points"));
  EXPECT_THAT(ErrorOf([] { ReadTrajectories("plan.csv"); }),
              HasSubstr("unknown markups extension"));
}

TEST(MarkupPoints, EveryDefinedPointInLps) {
  const std::string json = R"({"markups":[{"type":"Fiducial","coordinateSystem":"RAS",
    "controlPoints":[{"position":[1,2,3]},{"position":[0,0,0],"positionStatus":"undefined"}]},
    {"type":"Fiducial","controlPoints":[{"position":[4,5,6]}]}]})";
  EXPECT_EQ(DecodeMarkupPointsJson(Bytes(json)),
            (std::vector<Eigen::Vector3d>{{-1, -2, 3}, {4, 5, 6}}));
  EXPECT_EQ(DecodeMarkupPointsFcsv(Bytes("# CoordinateSystem = LPS\na,1,2,3\nb,4,5,6\nc,7,8,9\n")),
            (std::vector<Eigen::Vector3d>{{1, 2, 3}, {4, 5, 6}, {7, 8, 9}}));
  const std::vector<MarkupPoint> labelled =
      DecodeLabelledMarkupPointsFcsv(Bytes("# CoordinateSystem = LPS\n"
                                           "1,1,2,3,0,0,0,1,1,1,0,a\n2,4,5,6,0,0,0,1,1,1,0,b\n"));
  ASSERT_EQ(labelled.size(), 2u);
  EXPECT_EQ(labelled[1].label, "b");
  EXPECT_EQ(labelled[1].lps_mm, Eigen::Vector3d(4, 5, 6));
  EXPECT_THAT(ErrorOf([] { DecodeMarkupPointsJson(Bytes(R"({"markups":[]})")); }),
              ::testing::HasSubstr("no defined control point"));
}

}  // namespace
}  // namespace tofnav
