// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/volume/dicom.hpp"

#include <gdcmAttribute.h>
#include <gdcmUIDGenerator.h>
#include <gdcmWriter.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;
constexpr double kDsMm = 1e-4;  // GDCM writes positions as DS text (at most 16 characters)

constexpr int kColumns = 4, kRows = 3, kSlices = 5;
constexpr double kColumnSpacingMm = 0.7, kRowSpacingMm = 0.9, kSliceStepMm = 1.3;
const char* const kUid = "1.2.826.0.1.3680043.2.1125.1.1";

// An oblique stack: rows and columns rotated away from the patient axes.
const Eigen::Matrix3d kRotation =
    Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
const Eigen::Vector3d kFirstPosition(-40.0, 12.5, 80.25);

double TruthHu(int i, int j, int k) { return 100.0 * k + 10.0 * j + i - 500.0; }

struct Slice {
  std::string uid = kUid;
  Eigen::Vector3d position;
  Eigen::Matrix3d rotation = kRotation;
  double slope = 1.0, intercept = 0.0;
  int k = 0;  // truth slice index for the pixel values
};

// One CT slice written data element by data element with gdcm::Writer (GDCM's ImageWriter
// drops the z of the origin for 2-D images and writes enhanced multi-frame for 3-D ones).
void WriteSlice(const std::filesystem::path& path, const Slice& s) {
  gdcm::Writer writer;
  gdcm::DataSet& data = writer.GetFile().GetDataSet();
  const auto put = [&data](auto attribute) { data.Replace(attribute.GetAsDataElement()); };
  put(gdcm::Attribute<0x0008, 0x0016>{"1.2.840.10008.5.1.4.1.1.2"});  // CT Image Storage
  put(gdcm::Attribute<0x0008, 0x0018>{gdcm::UIDGenerator().Generate()});
  put(gdcm::Attribute<0x0008, 0x0060>{"CT"});
  put(gdcm::Attribute<0x0020, 0x000e>{s.uid});
  put(gdcm::Attribute<0x0020, 0x0032>{{s.position.x(), s.position.y(), s.position.z()}});
  put(gdcm::Attribute<0x0020, 0x0037>{{s.rotation(0, 0), s.rotation(1, 0), s.rotation(2, 0),
                                       s.rotation(0, 1), s.rotation(1, 1), s.rotation(2, 1)}});
  put(gdcm::Attribute<0x0028, 0x0002>{1});
  put(gdcm::Attribute<0x0028, 0x0004>{"MONOCHROME2"});
  put(gdcm::Attribute<0x0028, 0x0010>{kRows});
  put(gdcm::Attribute<0x0028, 0x0011>{kColumns});
  put(gdcm::Attribute<0x0028, 0x0030>{{kRowSpacingMm, kColumnSpacingMm}});
  put(gdcm::Attribute<0x0028, 0x0100>{16});
  put(gdcm::Attribute<0x0028, 0x0101>{16});
  put(gdcm::Attribute<0x0028, 0x0102>{15});
  put(gdcm::Attribute<0x0028, 0x0103>{1});
  put(gdcm::Attribute<0x0028, 0x1052>{s.intercept});
  put(gdcm::Attribute<0x0028, 0x1053>{s.slope});
  std::vector<std::int16_t> stored;
  for (int j = 0; j < kRows; ++j) {
    for (int i = 0; i < kColumns; ++i) {
      stored.push_back(static_cast<std::int16_t>((TruthHu(i, j, s.k) - s.intercept) / s.slope));
    }
  }
  gdcm::DataElement pixels(gdcm::Tag(0x7fe0, 0x0010));
  pixels.SetVR(gdcm::VR::OW);
  pixels.SetByteValue(reinterpret_cast<const char*>(stored.data()),
                      static_cast<std::uint32_t>(stored.size() * sizeof(std::int16_t)));
  data.Replace(pixels);
  writer.GetFile().GetHeader().SetDataSetTransferSyntax(
      gdcm::TransferSyntax::ExplicitVRLittleEndian);
  writer.SetFileName(path.c_str());
  ASSERT_TRUE(writer.Write()) << path;
}

class DicomSeries : public ::testing::Test {
 protected:
  // Writes slices k = 0..count-1 in a shuffled file order, alternating two rescale pairs.
  void WriteStack(int count, const std::string& uid = kUid) {
    for (int k = 0; k < count; ++k) {
      Slice s;
      s.uid = uid;
      s.k = k;
      s.position = kFirstPosition + k * kSliceStepMm * kRotation.col(2);
      s.slope = k % 2 == 0 ? 1.0 : 0.5;
      s.intercept = k % 2 == 0 ? -1024.0 : -1000.0;
      WriteSlice(folder_ / (uid.substr(uid.size() - 1) + "_" + std::to_string(count - 1 - k)), s);
    }
  }
  testing::TempDir temp_{std::string("dicom_test_") +
                         ::testing::UnitTest::GetInstance()->current_test_info()->name()};
  const std::filesystem::path& folder_ = temp_.path();
};

TEST_F(DicomSeries, ObliqueStackIsSortedByPositionWithPerSliceRescale) {
  WriteStack(kSlices);
  WriteFileAtomically(folder_ / "notes.txt", std::string("not DICOM"));
  const CtVolume v = ReadDicomSeries(folder_);
  ASSERT_EQ(v.dims, (std::array<int, 3>{kColumns, kRows, kSlices}));
  EXPECT_EQ(v.modality, "CT");
  for (int k = 0; k < kSlices; ++k) {
    for (int j = 0; j < kRows; ++j) {
      for (int i = 0; i < kColumns; ++i) {
        EXPECT_EQ(v.at(i, j, k), TruthHu(i, j, k));
        const Eigen::Vector3d expected = kFirstPosition + kRotation.col(0) * i * kColumnSpacingMm +
                                         kRotation.col(1) * j * kRowSpacingMm +
                                         kRotation.col(2) * k * kSliceStepMm;
        EXPECT_LT((v.VoxelCentre(i, j, k) - expected).norm(), kDsMm);
      }
    }
  }
}

TEST_F(DicomSeries, SingleSliceIsRefused) {
  WriteStack(1);
  EXPECT_THAT([&] { ReadDicomSeries(folder_); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("at least 2 slices")));
}

TEST_F(DicomSeries, SeveralSeriesAreListedAndOneCanBeChosen) {
  const std::string other = "1.2.826.0.1.3680043.2.1125.1.2";
  WriteStack(3);
  WriteStack(4, other);
  const auto series = ListDicomSeries(folder_);
  ASSERT_EQ(series.size(), 2u);
  EXPECT_EQ(series[1].file_count, 4);
  EXPECT_THAT([&] { ReadDicomSeries(folder_); }, ::testing::ThrowsMessage<IoError>(::testing::AllOf(
                                                     HasSubstr(kUid), HasSubstr(other))));
  EXPECT_EQ(ReadDicomSeries(folder_, {.series_instance_uid = other}).nz(), 4);
}

TEST_F(DicomSeries, UnevenOrDuplicatePositionsAreRefusedButJitterIsAccepted) {
  WriteStack(kSlices);
  Slice jitter;
  jitter.k = 2;
  jitter.position = kFirstPosition + (2 * kSliceStepMm + 0.005) * kRotation.col(2);
  WriteSlice(folder_ / "1_2", jitter);                // replaces slice 2
  EXPECT_EQ(ReadDicomSeries(folder_).nz(), kSlices);  // 0.005 mm < 1% of 1.3 mm
  Slice gap = jitter;
  gap.position = kFirstPosition + 2.5 * kSliceStepMm * kRotation.col(2);
  WriteSlice(folder_ / "extra", gap);  // 6 slices whose spacing varies
  EXPECT_THAT([&] { ReadDicomSeries(folder_); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("not equally spaced")));
  gap.position = kFirstPosition + 3 * kSliceStepMm * kRotation.col(2);  // = slice 3
  WriteSlice(folder_ / "extra", gap);
  EXPECT_THAT([&] { ReadDicomSeries(folder_); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("same position")));
}

TEST_F(DicomSeries, MixedOrientationIsRefused) {
  WriteStack(3);
  Slice tilted;
  tilted.k = 3;
  tilted.rotation = Eigen::Matrix3d::Identity();
  tilted.position = kFirstPosition + 3 * kSliceStepMm * kRotation.col(2);
  WriteSlice(folder_ / "tilted", tilted);
  EXPECT_THAT([&] { ReadDicomSeries(folder_); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("ImageOrientationPatient differs")));
}

TEST_F(DicomSeries, FolderWithoutImagesIsRefused) {
  WriteFileAtomically(folder_ / "a.txt", std::string("text"));
  EXPECT_THAT([&] { ReadDicomSeries(folder_); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("no DICOM image files")));
  EXPECT_THROW(ReadDicomSeries(folder_ / "missing"), IoError);
}

}  // namespace
}  // namespace tofnav
