// SPDX-License-Identifier: BSD-3-Clause
// DICOM series reader on GDCM: headers with gdcm::Reader (up to the pixel data), pixels with
// gdcm::ImageReader (any transfer syntax GDCM decodes), geometry and rescale by our own code.
#include "tofnav/volume/dicom.hpp"

#include <gdcmImageReader.h>
#include <gdcmReader.h>
#include <gdcmStringFilter.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/volume/volume_samples.hpp"

namespace tofnav {
namespace {

constexpr double kOrientationTolerance = 1e-4;   // IOP cosines of slices of one stack: equal
constexpr double kPixelSpacingTolerance = 1e-4;  // mm: equal PixelSpacing within DS precision

struct SliceHeader {
  std::filesystem::path path;
  std::string series_uid, modality, description;
  std::optional<std::vector<double>> position, orientation, pixel_spacing;  // IPP, IOP, (dr, dc)
  int rows = 0, columns = 0, frames = 1;
  double slope = 1.0, intercept = 0.0;
  double along_normal_mm = 0.0;  // IPP . n, the sort key
};

// Backslash-separated decimal strings (DS/IS) -> numbers; nullopt when absent or malformed.
std::optional<std::vector<double>> Numbers(const std::string& text, std::size_t count) {
  std::vector<double> values;
  std::size_t start = 0;
  while (start <= text.size() && !text.empty()) {
    std::size_t end = text.find('\\', start);
    if (end == std::string::npos) end = text.size();
    std::string_view item(text.data() + start, end - start);
    while (!item.empty() && (item.front() == ' ' || item.front() == '+')) item.remove_prefix(1);
    while (!item.empty() && (item.back() == ' ' || item.back() == '\0')) item.remove_suffix(1);
    double value = 0.0;
    const auto [ptr, error] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || error != std::errc() || ptr != item.data() + item.size() ||
        !std::isfinite(value)) {
      return std::nullopt;
    }
    values.push_back(value);
    start = end + 1;
  }
  if (values.size() != count) return std::nullopt;
  return values;
}

// Header of one file, or nullopt when it is not a DICOM image (not DICOM, or no pixel rows).
std::optional<SliceHeader> ReadSliceHeader(const std::filesystem::path& path) {
  gdcm::Reader reader;
  reader.SetFileName(path.c_str());
  if (!reader.ReadUpToTag(gdcm::Tag(0x7fe0, 0x0010))) return std::nullopt;
  gdcm::StringFilter strings;
  strings.SetFile(reader.GetFile());
  const auto text = [&](std::uint16_t group, std::uint16_t element) {
    std::string value = strings.ToString(gdcm::Tag(group, element));
    while (!value.empty() && (value.back() == ' ' || value.back() == '\0')) value.pop_back();
    return value;
  };
  SliceHeader slice;
  slice.path = path;
  slice.series_uid = text(0x0020, 0x000e);
  const auto rows = Numbers(text(0x0028, 0x0010), 1);
  const auto columns = Numbers(text(0x0028, 0x0011), 1);
  if (slice.series_uid.empty() || !rows || !columns) return std::nullopt;
  slice.rows = static_cast<int>(std::clamp((*rows)[0], 0.0, 65535.0));
  slice.columns = static_cast<int>(std::clamp((*columns)[0], 0.0, 65535.0));
  slice.modality = text(0x0008, 0x0060);
  slice.description = text(0x0008, 0x103e);
  slice.position = Numbers(text(0x0020, 0x0032), 3);
  slice.orientation = Numbers(text(0x0020, 0x0037), 6);
  slice.pixel_spacing = Numbers(text(0x0028, 0x0030), 2);
  if (const auto frames = Numbers(text(0x0028, 0x0008), 1)) {
    slice.frames = static_cast<int>(std::clamp((*frames)[0], 0.0, 1e6));
  }
  if (const auto slope = Numbers(text(0x0028, 0x1053), 1)) slice.slope = (*slope)[0];
  if (const auto intercept = Numbers(text(0x0028, 0x1052), 1)) slice.intercept = (*intercept)[0];
  return slice;
}

std::vector<SliceHeader> ScanFolder(const std::filesystem::path& folder) {
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) {
    throw IoError(folder, std::nullopt, "expected a folder of DICOM files");
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  std::vector<SliceHeader> slices;
  for (const auto& file : files) {
    if (auto slice = ReadSliceHeader(file)) slices.push_back(std::move(*slice));
  }
  return slices;
}

std::vector<DicomSeriesSummary> Summarise(const std::vector<SliceHeader>& slices) {
  std::map<std::string, DicomSeriesSummary> by_uid;
  for (const SliceHeader& slice : slices) {
    DicomSeriesSummary& s = by_uid[slice.series_uid];
    s = {slice.series_uid, slice.modality, slice.description, s.file_count + 1};
  }
  std::vector<DicomSeriesSummary> out;
  for (auto& [uid, summary] : by_uid) out.push_back(std::move(summary));
  return out;
}

// Stored pixel values of one slice (rows * columns, row-major), before rescale.
std::vector<float> ReadPixels(const SliceHeader& slice) {
  gdcm::ImageReader reader;
  reader.SetFileName(slice.path.c_str());
  if (!reader.Read()) throw IoError(slice.path, std::nullopt, "GDCM cannot decode the image");
  const gdcm::Image& image = reader.GetImage();
  const gdcm::PixelFormat& format = image.GetPixelFormat();
  if (format.GetSamplesPerPixel() != 1) {
    throw IoError(slice.path, std::nullopt, "expected a single-sample (grey) image");
  }
  if (image.GetColumns() != static_cast<unsigned>(slice.columns) ||
      image.GetRows() != static_cast<unsigned>(slice.rows) ||
      (image.GetNumberOfDimensions() == 3 && image.GetDimension(2) != 1)) {
    throw IoError(slice.path, std::nullopt, "pixel data does not match Rows/Columns");
  }
  using Pf = gdcm::PixelFormat;
  static constexpr std::array<std::pair<Pf::ScalarType, SampleType>, 8> kTypes = {
      {{Pf::UINT8, SampleType::kUint8},
       {Pf::INT8, SampleType::kInt8},
       {Pf::UINT16, SampleType::kUint16},
       {Pf::INT16, SampleType::kInt16},
       {Pf::UINT32, SampleType::kUint32},
       {Pf::INT32, SampleType::kInt32},
       {Pf::FLOAT32, SampleType::kFloat32},
       {Pf::FLOAT64, SampleType::kFloat64}}};
  const auto entry = std::find_if(kTypes.begin(), kTypes.end(),
                                  [&](const auto& e) { return e.first == format.GetScalarType(); });
  if (entry == kTypes.end()) {
    throw IoError(slice.path, std::nullopt,
                  std::string("unsupported pixel type ") + format.GetScalarTypeAsString());
  }
  const SampleType type = entry->second;
  const std::size_t count =
      static_cast<std::size_t>(slice.rows) * static_cast<std::size_t>(slice.columns);
  std::vector<std::uint8_t> buffer(image.GetBufferLength());
  if (buffer.size() != count * SampleSize(type) ||
      !image.GetBuffer(reinterpret_cast<char*>(buffer.data()))) {
    throw IoError(slice.path, std::nullopt, "GDCM returned pixel data of an unexpected size");
  }
  std::vector<float> values(count);
  DecodeSamples(buffer, type, std::endian::native, values);
  return values;
}

// Checks that every slice fits one stack and sorts by position along the normal; returns the
// image_from_ijk of the DICOM rule P = IPP + i * dc * X + j * dr * Y (+ k * slice step).
Eigen::Matrix4d SortAndCheckStack(std::vector<SliceHeader>& slices, double max_deviation) {
  const SliceHeader& first = slices.front();
  for (const SliceHeader& slice : slices) {
    if (!slice.position || !slice.orientation || !slice.pixel_spacing) {
      throw IoError(slice.path, std::nullopt,
                    "missing ImagePositionPatient, ImageOrientationPatient or PixelSpacing");
    }
    if (slice.frames != 1)
      throw IoError(slice.path, std::nullopt, "multi-frame images unsupported");
    if (slice.rows < 1 || slice.columns < 1 || slice.rows != first.rows ||
        slice.columns != first.columns) {
      throw IoError(slice.path, std::nullopt, "slice size differs within the series");
    }
    const auto differs = [](const std::vector<double>& a, const std::vector<double>& b,
                            double tolerance) {
      for (std::size_t n = 0; n < a.size(); ++n) {
        if (!(std::abs(a[n] - b[n]) <= tolerance)) return true;
      }
      return false;
    };
    if (differs(*slice.orientation, *first.orientation, kOrientationTolerance)) {
      throw IoError(slice.path, std::nullopt, "ImageOrientationPatient differs within the series");
    }
    if (differs(*slice.pixel_spacing, *first.pixel_spacing, kPixelSpacingTolerance) ||
        !((*slice.pixel_spacing)[0] > 0.0 && (*slice.pixel_spacing)[1] > 0.0)) {
      throw IoError(slice.path, std::nullopt, "PixelSpacing differs or is not positive");
    }
  }
  // Copies: sorting below moves the slices.
  const std::vector<double> iop = *first.orientation;
  const std::vector<double> spacing = *first.pixel_spacing;     // (between rows, between columns)
  const Eigen::Vector3d row_direction(iop[0], iop[1], iop[2]);  // X: along a row (i)
  const Eigen::Vector3d column_direction(iop[3], iop[4], iop[5]);  // Y: down a column (j)
  if (std::abs(row_direction.norm() - 1.0) > 1e-3 ||
      std::abs(column_direction.norm() - 1.0) > 1e-3 ||
      std::abs(row_direction.dot(column_direction)) > 1e-3) {
    throw IoError(slices.front().path, std::nullopt,
                  "ImageOrientationPatient is not two orthonormal vectors");
  }
  const Eigen::Vector3d normal = row_direction.cross(column_direction);
  const auto ipp = [](const SliceHeader& s) {
    return Eigen::Vector3d((*s.position)[0], (*s.position)[1], (*s.position)[2]);
  };
  for (SliceHeader& slice : slices) slice.along_normal_mm = ipp(slice).dot(normal);
  std::stable_sort(slices.begin(), slices.end(), [](const SliceHeader& a, const SliceHeader& b) {
    return a.along_normal_mm < b.along_normal_mm;
  });
  const Eigen::Vector3d origin = ipp(slices.front());
  const Eigen::Vector3d step =
      (ipp(slices.back()) - origin) / static_cast<double>(slices.size() - 1);
  for (std::size_t k = 1; k < slices.size(); ++k) {
    if (!(slices[k].along_normal_mm - slices[k - 1].along_normal_mm > 1e-3 * step.norm())) {
      throw IoError(slices[k].path, std::nullopt,
                    "two slices at the same position (mixed acquisitions?) with " +
                        slices[k - 1].path.filename().string());
    }
  }
  for (std::size_t k = 1; k + 1 < slices.size(); ++k) {
    const double off_mm = (ipp(slices[k]) - (origin + static_cast<double>(k) * step)).norm();
    if (off_mm > max_deviation * step.norm()) {
      throw IoError(slices[k].path, std::nullopt,
                    "slices are not equally spaced: slice " + std::to_string(k) + " lies " +
                        std::to_string(off_mm) + " mm off the even stack (mean spacing " +
                        std::to_string(step.norm()) + " mm; missing slice?)");
    }
  }
  Eigen::Matrix4d image_from_ijk = Eigen::Matrix4d::Identity();
  image_from_ijk.block<3, 1>(0, 0) = row_direction * spacing[1];
  image_from_ijk.block<3, 1>(0, 1) = column_direction * spacing[0];
  image_from_ijk.block<3, 1>(0, 2) = step;
  image_from_ijk.block<3, 1>(0, 3) = origin;
  return image_from_ijk;
}

}  // namespace

void DicomSeriesOptions::Check() const {
  Require(max_slice_deviation > 0.0 && max_slice_deviation < 0.5,
          "DicomSeriesOptions::max_slice_deviation must be in (0, 0.5)");
}

std::vector<DicomSeriesSummary> ListDicomSeries(const std::filesystem::path& folder) {
  return Summarise(ScanFolder(folder));
}

CtVolume ReadDicomSeries(const std::filesystem::path& folder, const DicomSeriesOptions& options) {
  options.Check();
  std::vector<SliceHeader> all = ScanFolder(folder);
  const std::vector<DicomSeriesSummary> series = Summarise(all);
  if (series.empty()) throw IoError(folder, std::nullopt, "no DICOM image files in the folder");
  std::string uid = options.series_instance_uid;
  if (uid.empty()) {
    if (series.size() > 1) {
      std::string list;
      for (const auto& s : series) {
        list += "\n  " + s.series_instance_uid + " (" + s.modality + ", " +
                std::to_string(s.file_count) + " files, \"" + s.description + "\")";
      }
      throw IoError(folder, std::nullopt,
                    "several DICOM series; choose one by SeriesInstanceUID:" + list);
    }
    uid = series.front().series_instance_uid;
  }
  std::vector<SliceHeader> slices;
  for (SliceHeader& slice : all) {
    if (slice.series_uid == uid) slices.push_back(std::move(slice));
  }
  if (slices.empty()) throw IoError(folder, std::nullopt, "no DICOM series with UID " + uid);
  if (slices.size() < 2) {
    throw IoError(slices.front().path, std::nullopt,
                  "a DICOM series needs at least 2 slices to define the slice spacing");
  }
  CtVolume volume;
  volume.image_from_ijk = SortAndCheckStack(slices, options.max_slice_deviation);
  volume.dims = {slices.front().columns, slices.front().rows, static_cast<int>(slices.size())};
  volume.modality = slices.front().modality;
  volume.name =
      slices.front().description.empty() ? folder.filename().string() : slices.front().description;
  volume.geometry_source = "dicom series (IPP/IOP, " + std::to_string(slices.size()) + " slices)";
  const std::size_t per_slice =
      static_cast<std::size_t>(volume.nx()) * static_cast<std::size_t>(volume.ny());
  volume.values.resize(per_slice * slices.size());
  for (std::size_t k = 0; k < slices.size(); ++k) {
    const std::vector<float> stored = ReadPixels(slices[k]);
    for (std::size_t n = 0; n < per_slice; ++n) {  // HU = slope * stored + intercept, per slice
      volume.values[k * per_slice + n] =
          NarrowToFloat(slices[k].slope * stored[n] + slices[k].intercept);
    }
  }
  return volume;  // valid by construction: orthonormal IOP, positive spacings, distinct slices
}

}  // namespace tofnav
