// SPDX-License-Identifier: BSD-3-Clause
// Precondition checks that throw with the caller's location.
#pragma once

#include <stdexcept>
#include <string_view>

namespace tofnav {

/// Thrown when a caller breaks a documented precondition (bad argument, bad option).
class PreconditionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The caller's position. (std::source_location is missing from clang 14 with libstdc++ 12, which
/// the fuzz build uses; the compiler builtins behind it work in both GCC and clang.)
struct SourceLocation {
  static constexpr SourceLocation Current(const char* file = __builtin_FILE(),
                                          int line = __builtin_LINE(),
                                          const char* function = __builtin_FUNCTION()) {
    return {file, line, function};
  }
  const char* file;
  int line;
  const char* function;
};

/// Throws PreconditionError("<file>:<line> <function>: <message>") when `condition` is false.
void Require(bool condition, std::string_view message,
             SourceLocation where = SourceLocation::Current());

}  // namespace tofnav
