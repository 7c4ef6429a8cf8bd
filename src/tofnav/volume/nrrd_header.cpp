// SPDX-License-Identifier: BSD-3-Clause
// NRRD header parsing: our own reading of the fields in teem's format description
// (teem.sourceforge.net/nrrd/format.html); unknown fields and key:=value pairs are ignored.
#include "tofnav/volume/nrrd_header.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <string_view>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr std::int64_t kMaxSkip = std::int64_t{1} << 40;

class Parser {
 public:
  Parser(const std::filesystem::path& path, std::uint64_t offset) : path_(path), offset_(offset) {}
  [[noreturn]] void Fail(const std::string& message) const {
    throw IoError(path_, offset_, message);
  }
  void set_offset(std::uint64_t offset) { offset_ = offset; }

  std::int64_t Integer(std::string_view text, const char* what) const {
    std::int64_t value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size()) {
      Fail(std::string("expected an integer for ") + what + ", found '" + std::string(text) + "'");
    }
    return value;
  }
  double Real(std::string_view text, const char* what) const {
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size()) {
      Fail(std::string("expected a number for ") + what + ", found '" + std::string(text) + "'");
    }
    return value;
  }
  // "(x,y,z)" with optional blanks; "none" gives nullopt.
  std::optional<Eigen::Vector3d> Vector(std::string_view text, const char* what) const {
    if (text == "none") return std::nullopt;
    if (text.size() < 2 || text.front() != '(' || text.back() != ')') {
      Fail(std::string("expected (x,y,z) or none for ") + what);
    }
    text = text.substr(1, text.size() - 2);
    Eigen::Vector3d v;
    for (int n = 0; n < 3; ++n) {
      const std::size_t comma = n < 2 ? text.find(',') : text.size();
      if (comma == std::string_view::npos || (n == 2 && text.find(',') != std::string_view::npos)) {
        Fail(std::string("expected 3 components in ") + what);
      }
      v[n] = Real(Trim(text.substr(0, comma)), what);
      if (!std::isfinite(v[n])) Fail(std::string("non-finite component in ") + what);
      text = n < 2 ? text.substr(comma + 1) : std::string_view();
    }
    return v;
  }
  static std::string_view Trim(std::string_view text) {
    while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) {
      text.remove_suffix(1);
    }
    return text;
  }
  // Whitespace-separated items; a parenthesised vector is one item even with blanks inside.
  std::vector<std::string_view> Items(std::string_view text) const {
    std::vector<std::string_view> items;
    std::size_t n = 0;
    while (n < text.size()) {
      if (text[n] == ' ' || text[n] == '\t') {
        ++n;
        continue;
      }
      const std::size_t end = text[n] == '(' ? text.find(')', n) : text.find_first_of(" \t", n);
      if (text[n] == '(' && end == std::string_view::npos) Fail("unbalanced '(' in vector list");
      const std::size_t stop = end == std::string_view::npos ? text.size() : end + (text[n] == '(');
      items.push_back(text.substr(n, stop - n));
      n = stop;
    }
    return items;
  }

 private:
  const std::filesystem::path& path_;
  std::uint64_t offset_;
};

std::optional<SampleType> ParseType(std::string_view name) {
  struct Aliases {
    SampleType type;
    std::array<std::string_view, 6> names;
  };
  static constexpr std::array<Aliases, 10> kTypes = {
      {{SampleType::kInt8, {"signed char", "int8", "int8_t"}},
       {SampleType::kUint8, {"uchar", "unsigned char", "uint8", "uint8_t"}},
       {SampleType::kInt16,
        {"short", "short int", "signed short", "signed short int", "int16", "int16_t"}},
       {SampleType::kUint16,
        {"ushort", "unsigned short", "unsigned short int", "uint16", "uint16_t"}},
       {SampleType::kInt32, {"int", "signed int", "int32", "int32_t"}},
       {SampleType::kUint32, {"uint", "unsigned int", "uint32", "uint32_t"}},
       {SampleType::kInt64,
        {"longlong", "long long", "long long int", "signed long long", "int64", "int64_t"}},
       {SampleType::kUint64,
        {"ulonglong", "unsigned long long", "unsigned long long int", "uint64", "uint64_t"}},
       {SampleType::kFloat32, {"float"}},
       {SampleType::kFloat64, {"double"}}}};
  for (const Aliases& aliases : kTypes) {
    for (const std::string_view alias : aliases.names) {
      if (!alias.empty() && alias == name) return aliases.type;
    }
  }
  return std::nullopt;
}

// Diagonal taking the named space to LPS.
std::optional<Eigen::Vector3d> ParseSpace(std::string_view name) {
  if (name == "left-posterior-superior" || name == "LPS") return Eigen::Vector3d(1, 1, 1);
  if (name == "right-anterior-superior" || name == "RAS") return Eigen::Vector3d(-1, -1, 1);
  if (name == "left-anterior-superior" || name == "LAS") return Eigen::Vector3d(1, -1, 1);
  return std::nullopt;
}

// Fields seen while parsing that have no "absent" value in NrrdHeader.
struct Seen {
  bool type = false;
  bool endian = false;
};

void ParseField(Parser& p, NrrdHeader& h, Seen& seen, std::string name, std::string_view value) {
  std::erase(name, ' ');
  if (name == "type") {
    const auto type = ParseType(value);
    if (!type) p.Fail("unsupported NRRD type '" + std::string(value) + "'");
    h.type = *type;
    seen.type = true;
  } else if (name == "dimension") {
    h.dimension = static_cast<int>(std::clamp<std::int64_t>(p.Integer(value, "dimension"), -1, 99));
    if (h.dimension != 3 && h.dimension != 4) p.Fail("expected dimension 3 or 4");
  } else if (name == "sizes") {
    for (const auto item : p.Items(value)) {
      const std::int64_t size = p.Integer(item, "sizes");
      if (size < 1 || size > 0x7fffffff) p.Fail("sizes must be in 1 .. 2^31-1");
      h.sizes.push_back(static_cast<std::uint64_t>(size));
    }
  } else if (name == "space") {
    h.to_lps = ParseSpace(value);
    h.space_name = value;
    if (!h.to_lps) p.Fail("unsupported space '" + std::string(value) + "' (LPS, RAS, LAS)");
  } else if (name == "spacedimension") {
    if (p.Integer(value, "space dimension") != 3) p.Fail("expected space dimension 3");
    if (!h.to_lps) {
      h.to_lps = Eigen::Vector3d(1, 1, 1);  // ITK reads a bare space dimension as LPS
      h.space_name = "space dimension 3, LPS assumed";
    }
  } else if (name == "spacedirections") {
    h.directions.emplace();
    for (const auto item : p.Items(value)) {
      h.directions->push_back(p.Vector(item, "space directions"));
    }
  } else if (name == "spaceorigin") {
    h.origin = p.Vector(value, "space origin");
    if (!h.origin) p.Fail("space origin cannot be none");
  } else if (name == "spacings") {
    for (const auto item : p.Items(value)) h.spacings.push_back(p.Real(item, "spacings"));
  } else if (name == "endian") {
    if (value != "little" && value != "big") p.Fail("expected endian little or big");
    h.endian = value == "little" ? std::endian::little : std::endian::big;
    seen.endian = true;
  } else if (name == "encoding") {
    h.encoding = value == "gz" ? "gzip" : std::string(value);
    if (h.encoding != "raw" && h.encoding != "gzip") {
      p.Fail("unsupported encoding '" + std::string(value) + "' (raw, gzip)");
    }
  } else if (name == "datafile") {
    h.data_file = value;
  } else if (name == "byteskip") {
    h.byte_skip = p.Integer(value, "byte skip");
    if (h.byte_skip < -1 || h.byte_skip > kMaxSkip) p.Fail("byte skip out of range");
  } else if (name == "lineskip") {
    h.line_skip = p.Integer(value, "line skip");
    if (h.line_skip < 0 || h.line_skip > kMaxSkip) p.Fail("line skip out of range");
  }  // other fields (kinds, centers, units, content, ...) do not change the geometry
}

}  // namespace

NrrdHeader ParseNrrdHeader(std::span<const std::uint8_t> bytes, const std::filesystem::path& path) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  Parser p(path, 0);
  if (text.size() < 9 || text.substr(0, 7) != "NRRD000" || text[7] < '1' || text[7] > '5' ||
      (text[8] != '\n' && text[8] != '\r')) {
    p.Fail("expected NRRD magic NRRD0001..NRRD0005");
  }
  NrrdHeader h;
  Seen seen;
  std::size_t position = text.find('\n') + 1;
  while (position < text.size()) {
    const std::size_t newline = text.find('\n', position);
    const std::size_t end = newline == std::string_view::npos ? text.size() : newline;
    const std::string_view line = Parser::Trim(text.substr(position, end - position));
    p.set_offset(position);
    position = newline == std::string_view::npos ? text.size() : newline + 1;
    if (line.empty()) {
      h.blank_line = true;
      break;
    }
    if (line.front() == '#' || line.find(":=") != std::string_view::npos) continue;
    const std::size_t colon = line.find(": ");
    if (colon == std::string_view::npos) p.Fail("expected '<field>: <value>' header line");
    ParseField(p, h, seen, std::string(line.substr(0, colon)),
               Parser::Trim(line.substr(colon + 2)));
  }
  h.end_offset = position;
  p.set_offset(position);
  if (!seen.type || h.dimension == 0 || h.encoding.empty()) {
    p.Fail("header lacks a required field (type, dimension, encoding)");
  }
  if (h.sizes.size() != static_cast<std::size_t>(h.dimension)) {
    p.Fail("sizes must list dimension values");
  }
  if (!seen.endian && SampleSize(h.type) > 1) p.Fail("header lacks endian for a multi-byte type");
  if (h.directions && h.directions->size() != h.sizes.size()) {
    p.Fail("space directions must list dimension entries");
  }
  if (h.directions && !h.to_lps) p.Fail("space directions given without space");
  if (!h.spacings.empty() && h.spacings.size() != h.sizes.size()) {
    p.Fail("spacings must list dimension values");
  }
  if (h.space_name.empty()) h.space_name = "no space field, LPS assumed";
  return h;
}

}  // namespace tofnav
