// SPDX-License-Identifier: BSD-3-Clause
// A tiny Apple XML plist parser: the subset InVesalius writes (dict, key, string, integer, real,
// array, true, false, date). Internal to io/.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tofnav {

/// One value of an Apple XML property list.
struct PlistValue {
  enum class Kind { kString, kNumber, kBool, kArray, kDict } kind = Kind::kString;
  std::string text;  // string content, or the number's literal
  bool flag = false;
  std::vector<PlistValue> items;  // array elements, or dict values in file order
  std::vector<std::string> keys;  // dict only: keys[n] names items[n]

  /// The dict value named `key`, or nullptr.
  const PlistValue* Find(std::string_view key) const;
};

/// Parses a whole plist document (prolog, <plist>, one value). IoError naming `path` at
/// `base_offset` + position on anything else; nesting deeper than 32 levels is refused.
PlistValue ParsePlist(std::string_view text, const std::filesystem::path& path,
                      std::uint64_t base_offset);

}  // namespace tofnav
