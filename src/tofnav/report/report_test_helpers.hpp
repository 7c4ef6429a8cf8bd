// SPDX-License-Identifier: BSD-3-Clause
// Test-only helpers for the report/ suites.
#pragma once

#include <string>

namespace tofnav::testing {

/// How often `needle` occurs in `text`, without overlaps.
inline int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos;
       at = text.find(needle, at + needle.size())) {
    ++n;
  }
  return n;
}

}  // namespace tofnav::testing
