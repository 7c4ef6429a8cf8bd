// SPDX-License-Identifier: BSD-3-Clause
// Precondition checks that throw with the caller's location.
#include "tofnav/core/require.hpp"

#include <filesystem>
#include <string>

namespace tofnav {

void Require(bool condition, std::string_view message, SourceLocation where) {
  if (condition) return;
  std::string text = std::filesystem::path(where.file).filename().string();
  text += ':' + std::to_string(where.line) + ' ' + where.function + ": ";
  text += message;
  throw PreconditionError(text);
}

}  // namespace tofnav
