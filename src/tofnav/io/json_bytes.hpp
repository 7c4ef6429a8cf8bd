// SPDX-License-Identifier: BSD-3-Clause
// Internal to io/: a JSON document from bytes, with malformed input as an IoError at its offset.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "tofnav/io/io_error.hpp"

namespace tofnav {

/// `Json` is nlohmann::json or nlohmann::ordered_json.
template <typename Json>
Json ParseJsonBytes(std::span<const std::uint8_t> bytes, const std::filesystem::path& source) {
  try {
    return Json::parse(bytes.begin(), bytes.end());
  } catch (const typename Json::parse_error& e) {
    const std::uint64_t offset = std::min<std::uint64_t>(e.byte > 0 ? e.byte - 1 : 0, bytes.size());
    throw IoError(source, offset, std::string("malformed JSON: ") + e.what());
  } catch (const typename Json::exception& e) {  // e.g. a number beyond the double range
    throw IoError(source, std::nullopt, std::string("malformed JSON: ") + e.what());
  }
}

/// The same over text.
template <typename Json>
Json ParseJsonText(std::string_view text, const std::filesystem::path& source) {
  return ParseJsonBytes<Json>(
      std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), source);
}

}  // namespace tofnav
