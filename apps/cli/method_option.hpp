// SPDX-License-Identifier: BSD-3-Clause
// The --method tofnav|paper option shared by identify, reconstruct, register and track.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "tofnav/pipeline/paper_method.hpp"

namespace tofnav {

/// tofnav (default) or paper: the paper's method as published (pipeline/paper_method.hpp,
/// docs/paper_method.md); it overrides the options it names.
inline CLI::Option* AddMethodOption(CLI::App& app, Method& method) {
  return app
      .add_option_function<std::string>(
          "--method", [&method](const std::string& v) { method = *ParseMethod(v); },
          "tofnav, or paper: the paper's method as published, as a baseline "
          "(docs/paper_method.md; it overrides tofnav's additions)")
      ->check(CLI::IsMember({"tofnav", "paper"}))
      ->default_str(ToString(method));
}

}  // namespace tofnav
