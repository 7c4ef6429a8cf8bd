// SPDX-License-Identifier: BSD-3-Clause
// Transform files: the 3D Slicer .tfm oracle (docs/openigtlink.md 5.3), round trips, rejections.
#include "tofnav/casefile/transform_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <numbers>
#include <string>

#include "matchers.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr double kExactRad = 1e-12, kExactMm = 1e-12;  // decimal text of doubles: round-off only

std::span<const std::uint8_t> Bytes(const std::string& text) {
  return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

std::string Tfm(const std::string& parameters, const std::string& fixed = "0 0 0",
                const std::string& type = "AffineTransform_double_3_3") {
  return "#Insight Transform File V1.0\n#Transform 0\nTransform: " + type +
         "\nParameters: " + parameters + "\nFixedParameters: " + fixed + "\n";
}

/// 3D Slicer's RAS from our LPS (and back): diag(-1, -1, 1).
const Rigid3d kRasFromLps(Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi,
                                                               Eigen::Vector3d::UnitZ())),
                          Eigen::Vector3d::Zero());

Rigid3d Translation(double x, double y, double z) {
  return {Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, y, z)};
}

// Oracle (docs/openigtlink.md sec. 5.3): a ToParent translation of +10 mm along R is stored as
// "1 0 0 0 1 0 0 0 1 10 0 0"; +10 mm along S as "... 0 0 -10".
TEST(ItkTransform, SlicerOracleTranslationAlongRight) {
  const Rigid3d parent_from_child = DecodeItkTransform(Bytes(Tfm("1 0 0 0 1 0 0 0 1 10 0 0")));
  EXPECT_THAT(parent_from_child, RigidNear(Translation(-10, 0, 0), kExactRad, kExactMm));  // LPS
  EXPECT_THAT(kRasFromLps * parent_from_child * kRasFromLps.Inverse(),
              RigidNear(Translation(10, 0, 0), 1e-12, 1e-12));  // Slicer's ToParent in RAS
  EXPECT_EQ(EncodeItkTransform(Translation(-10, 0, 0)), Tfm("1 0 0 0 1 0 0 0 1 10 0 0"));
}

TEST(ItkTransform, SlicerOracleTranslationAlongSuperior) {
  const Rigid3d parent_from_child = DecodeItkTransform(Bytes(Tfm("1 0 0 0 1 0 0 0 1 0 0 -10")));
  EXPECT_THAT(parent_from_child, RigidNear(Translation(0, 0, 10), kExactRad, kExactMm));
  EXPECT_EQ(EncodeItkTransform(Translation(0, 0, 10)), Tfm("1 0 0 0 1 0 0 0 1 0 0 -10"));
}

TEST(ItkTransform, NonZeroCentreIsApplied) {
  // A = 90 deg about z, t = (1, 2, 3), c = (10, 20, 30): y = A (x - c) + t + c.
  const Rigid3d parent_from_child =
      DecodeItkTransform(Bytes(Tfm("0 -1 0 1 0 0 0 0 1 1 2 3", "10 20 30")));
  const Eigen::Vector3d x(5.0, -7.0, 11.0);
  const Eigen::Vector3d y = Eigen::Vector3d(-(x.y() - 20), x.x() - 10, x.z() - 30) +
                            Eigen::Vector3d(1, 2, 3) + Eigen::Vector3d(10, 20, 30);
  EXPECT_LT((parent_from_child * y - x).norm(), 1e-12);  // the file maps parent to child
}

TEST(ItkTransform, RoundTripsAndAcceptsSlicerVariants) {
  const Rigid3d b_from_a(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 3).normalized())),
      Eigen::Vector3d(12.5, -300.25, 41.0));
  EXPECT_THAT(DecodeItkTransform(Bytes(EncodeItkTransform(b_from_a))),
              RigidNear(b_from_a, 1e-12, 1e-9));
  const std::string composite =
      "#Insight Transform File V1.0\n#Transform 0\nTransform: CompositeTransform_double_3\n" +
      Tfm("1 0 0 0 1 0 0 0 1 10 0 0", "0 0 0", "AffineTransform_float_3_3").substr(29);
  EXPECT_THAT(DecodeItkTransform(Bytes(composite)), RigidNear(Translation(-10, 0, 0), 0, 1e-12));
}

TEST(ItkTransform, RejectsWhatIsNotOneRigidTransform) {
  const auto offset_of = [](const std::string& text) -> std::optional<std::uint64_t> {
    try {
      DecodeItkTransform(Bytes(text), "x.tfm");
    } catch (const IoError& e) {
      return e.offset();
    }
    ADD_FAILURE() << "accepted: " << text;
    return std::nullopt;
  };
  EXPECT_EQ(offset_of(Tfm("2 0 0 0 1 0 0 0 1 0 0 0")), 80u);  // a scaling: at "Parameters:"
  EXPECT_TRUE(offset_of(Tfm("1 0 0 0 1 0 0 0 1 0 0", "0 0 0")).has_value());  // 11 numbers
  EXPECT_TRUE(offset_of(Tfm("1 0 0 0 1 0 0 0 1 nan 0 0")).has_value());
  EXPECT_TRUE(offset_of(Tfm("0 0 0 0 0 0", "0 0 0", "Euler3DTransform_double")).has_value());
  EXPECT_TRUE(offset_of(Tfm("1 0 0 0 1 0 0 0 1 0 0 0") + Tfm("1 0 0 0 1 0 0 0 1 0 0 0").substr(29))
                  .has_value());                                              // two transforms
  EXPECT_EQ(offset_of(Tfm("1 0 0 0 1 0 0 0 1 0 0 0").substr(0, 100)), 100u);  // truncated
  EXPECT_EQ(offset_of("hello"), 0u);
}

TEST(TransformJson, RoundTripsWithFramesAndFigures) {
  NamedTransform t;
  t.target_frame = "tool";
  t.source_frame = "image";
  t.target_from_source =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(0, 1, 1).normalized())),
              Eigen::Vector3d(-1.5, 400.0, 7.25));
  t.figures = {{"rmse_mm", 0.41}, {"inlier_fraction", 0.93}};
  const std::string text = EncodeTransformJson(t);
  EXPECT_THAT(text, testing::HasSubstr("\"target_frame\": \"tool\""));
  const NamedTransform back = DecodeTransformJson(Bytes(text));
  EXPECT_EQ(back.target_frame, "tool");
  EXPECT_EQ(back.source_frame, "image");
  EXPECT_THAT(back.target_from_source, RigidNear(t.target_from_source, 1e-12, 1e-12));
  EXPECT_EQ(back.figures, t.figures);  // order kept
}

TEST(TransformJson, RejectsTyposBadMatricesAndBrokenSyntax) {
  const std::string rows = "[[1,0,0,5],[0,1,0,0],[0,0,1,0],[0,0,0,1]]";
  const auto error = [](const std::string& text) -> std::string {
    try {
      DecodeTransformJson(Bytes(text), "t.json");
    } catch (const IoError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(DecodeTransformJson(Bytes(R"({"target_frame":"tool","source_frame":"image",)"
                                      R"("target_from_source":)" +
                                      rows + "}"))
                .target_from_source.translation.x(),
            5.0);
  EXPECT_THAT(
      error(R"({"target_frame":"tool","source_frame":"image","target_fromsource":)" + rows + "}"),
      testing::HasSubstr("unknown key \"target_fromsource\""));
  EXPECT_THAT(
      error(R"({"target_frame":"tool","source_frame":"im age","target_from_source":)" + rows + "}"),
      testing::HasSubstr("source_frame"));
  EXPECT_THAT(error(R"({"target_frame":"tool","source_frame":"image","units":"m",)"
                    R"("target_from_source":)" +
                    rows + "}"),
              testing::HasSubstr("units"));
  EXPECT_THAT(error(R"({"target_frame":"tool","source_frame":"image","target_from_source":)"
                    R"([[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})"),
              testing::HasSubstr("not a rigid transform"));
  EXPECT_THAT(error(R"({"target_frame":"tool","source_frame":"image","target_from_source":[[1]]})"),
              testing::HasSubstr("4 rows of 4"));
  EXPECT_THAT(error(R"({"target_frame": })"), testing::HasSubstr("t.json: at byte 17"));
  EXPECT_THAT(error("[1, 2]"), testing::HasSubstr("expected a JSON object"));
}

TEST(TransformText, RoundTripsWithAndWithoutNames) {
  NamedTransform t;
  t.target_frame = "tool";
  t.source_frame = "image";
  t.target_from_source =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX())),
              Eigen::Vector3d(1, 2, 3));
  const std::string text = EncodeTransformText(t);
  EXPECT_THAT(text, testing::StartsWith("# tofnav transform tool_from_image [mm]"));
  const NamedTransform back = DecodeTransformText(Bytes(text));
  EXPECT_EQ(back.target_frame, "tool");
  EXPECT_EQ(back.source_frame, "image");
  EXPECT_THAT(back.target_from_source, RigidNear(t.target_from_source, 1e-12, 1e-12));
  const NamedTransform bare = DecodeTransformText(Bytes("1 0 0 4\n0 1 0 5\n0 0 1 6\n0 0 0 1\n"));
  EXPECT_TRUE(bare.target_frame.empty());
  EXPECT_THAT(bare.target_from_source, RigidNear(Translation(4, 5, 6), 0, 0));
  EXPECT_THROW(DecodeTransformText(Bytes("1 0 0 4\n0 1 0 5\n0 0 1 6\n0 0 0\n")), IoError);
  EXPECT_THROW(DecodeTransformText(Bytes("1 0 0 4\n0 1 0 5\n0 0 1 6\n0 0 1 1\n")), IoError);
  EXPECT_THROW(DecodeTransformText(Bytes("1 0 0 4\n0 1 0 5\n0 0 1 6\n0 0 0 1 7\n")), IoError);
}

TEST(TransformFiles, ReadBackByExtension) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("tofnav_transform_io_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  NamedTransform t;
  t.target_frame = "tool";
  t.source_frame = "image";
  t.target_from_source = Translation(1, -2, 3);
  for (const char* name : {"a.json", "b.TFM", "c.txt"}) {
    WriteTransform(dir / name, t);
    EXPECT_THAT(ReadTransform(dir / name).target_from_source,
                RigidNear(t.target_from_source, 0, 1e-12))
        << name;
  }
  EXPECT_EQ(ReadTransform(dir / "c.txt").source_frame, "image");
  EXPECT_THROW(ReadTransform(dir / "a.xml"), IoError);
  EXPECT_THROW(WriteTransform(dir / "a.xml", t), IoError);
  t.target_frame = "bad name";
  EXPECT_THROW(WriteTransform(dir / "d.json", t), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tofnav
