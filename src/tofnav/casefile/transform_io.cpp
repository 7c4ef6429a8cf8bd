// SPDX-License-Identifier: BSD-3-Clause
// Transform files by extension, and the JSON form with named frames.
#include "tofnav/casefile/transform_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>

#include "tofnav/casefile/transform_matrix.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

std::string LowerExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// Byte offset of `"key"` in the raw text (the JSON library keeps no positions), if present.
std::optional<std::uint64_t> KeyOffset(std::span<const std::uint8_t> bytes, std::string_view key) {
  std::string quoted = "\"";  // built by appends: GCC 12 -O3 warns falsely on "\"" + string
  quoted += key;              // (bug 105651)
  quoted += '"';
  const auto at = std::search(bytes.begin(), bytes.end(), quoted.begin(), quoted.end());
  if (at == bytes.end()) return std::nullopt;
  return static_cast<std::uint64_t>(at - bytes.begin());
}

std::string FrameName(const OrderedJson& doc, std::string_view key,
                      std::span<const std::uint8_t> bytes, const std::filesystem::path& source) {
  const auto it = doc.find(std::string(key));
  if (it == doc.end())
    throw IoError(source, std::nullopt, "missing key \"" + std::string(key) + "\"");
  if (!it->is_string() || !IsFrameName(it->get<std::string>())) {
    throw IoError(source, KeyOffset(bytes, key),
                  "\"" + std::string(key) + "\": expected a frame name (letters, digits, '_')");
  }
  return it->get<std::string>();
}

Eigen::Matrix4d MatrixFromJson(const OrderedJson& rows, std::span<const std::uint8_t> bytes,
                               const std::filesystem::path& source) {
  const auto fail = [&] {
    throw IoError(source, KeyOffset(bytes, "target_from_source"),
                  "\"target_from_source\": expected 4 rows of 4 finite numbers");
  };
  if (!rows.is_array() || rows.size() != 4) fail();
  Eigen::Matrix4d matrix;
  for (int r = 0; r < 4; ++r) {
    const OrderedJson& row = rows[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 4) fail();
    for (int c = 0; c < 4; ++c) {
      const OrderedJson& value = row[static_cast<std::size_t>(c)];
      if (!value.is_number()) fail();
      matrix(r, c) = value.get<double>();
    }
  }
  return matrix;
}

}  // namespace

NamedTransform DecodeTransformJson(std::span<const std::uint8_t> bytes,
                                   const std::filesystem::path& source) {
  const OrderedJson doc = ParseJsonBytes<OrderedJson>(bytes, source);
  if (!doc.is_object()) throw IoError(source, 0, "expected a JSON object");
  for (const auto& [key, value] : doc.items()) {
    if (key != "target_frame" && key != "source_frame" && key != "units" &&
        key != "target_from_source" && key != "quality") {
      throw IoError(source, KeyOffset(bytes, key), "unknown key \"" + key + "\"");
    }
  }
  NamedTransform transform;
  transform.target_frame = FrameName(doc, "target_frame", bytes, source);
  transform.source_frame = FrameName(doc, "source_frame", bytes, source);
  if (doc.contains("units") && doc["units"] != "mm") {
    throw IoError(source, KeyOffset(bytes, "units"), "\"units\": only \"mm\" is supported");
  }
  if (!doc.contains("target_from_source")) {
    throw IoError(source, std::nullopt, "missing key \"target_from_source\"");
  }
  transform.target_from_source =
      RigidFromMatrix(MatrixFromJson(doc["target_from_source"], bytes, source), source,
                      KeyOffset(bytes, "target_from_source"));
  if (doc.contains("quality")) {
    const OrderedJson& quality = doc["quality"];
    if (!quality.is_object()) {
      throw IoError(source, KeyOffset(bytes, "quality"), "\"quality\": expected an object");
    }
    for (const auto& [key, value] : quality.items()) {
      if (!value.is_number() || !std::isfinite(value.get<double>())) {
        throw IoError(source, KeyOffset(bytes, key), "quality \"" + key + "\": expected a number");
      }
      transform.figures.emplace_back(key, value.get<double>());
    }
  }
  return transform;
}

std::string EncodeTransformJson(const NamedTransform& transform) {
  Require(IsFrameName(transform.target_frame) && IsFrameName(transform.source_frame),
          "EncodeTransformJson: frame names must be letters, digits and '_'");
  const Eigen::Matrix4d m = transform.target_from_source.ToMatrix();
  OrderedJson rows = OrderedJson::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  OrderedJson doc{{"target_frame", transform.target_frame},
                  {"source_frame", transform.source_frame},
                  {"units", "mm"},
                  {"target_from_source", rows}};
  if (!transform.figures.empty()) {
    OrderedJson quality = OrderedJson::object();
    for (const auto& [name, value] : transform.figures) {
      Require(std::isfinite(value), "EncodeTransformJson: figures must be finite");
      quality[name] = value;
    }
    doc["quality"] = quality;
  }
  return doc.dump(2) + "\n";
}

NamedTransform ReadTransform(const std::filesystem::path& path) {
  const std::string extension = LowerExtension(path);
  if (extension != ".json" && extension != ".tfm" && extension != ".txt") {
    throw IoError(path, std::nullopt, "unknown transform extension (expected .json, .tfm, .txt)");
  }
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  if (extension == ".json") return DecodeTransformJson(bytes, path);
  if (extension == ".txt") return DecodeTransformText(bytes, path);
  NamedTransform transform;
  transform.target_from_source = DecodeItkTransform(bytes, path);
  return transform;
}

void WriteTransform(const std::filesystem::path& path, const NamedTransform& transform) {
  const std::string extension = LowerExtension(path);
  if (extension == ".json") {
    WriteFileAtomically(path, EncodeTransformJson(transform));
  } else if (extension == ".tfm") {
    WriteFileAtomically(path, EncodeItkTransform(transform.target_from_source));
  } else if (extension == ".txt") {
    WriteFileAtomically(path, EncodeTransformText(transform));
  } else {
    throw IoError(path, std::nullopt, "unknown transform extension (expected .json, .tfm, .txt)");
  }
}

}  // namespace tofnav
