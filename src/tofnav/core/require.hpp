// SPDX-License-Identifier: BSD-3-Clause
// Precondition checks that throw with the caller's location.
#pragma once

#include <source_location>
#include <stdexcept>
#include <string_view>

namespace tofnav {

/// Thrown when a caller breaks a documented precondition (bad argument, bad option).
class PreconditionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Throws PreconditionError("<file>:<line> <function>: <message>") when `condition` is false.
void Require(bool condition, std::string_view message,
             std::source_location where = std::source_location::current());

}  // namespace tofnav
