// SPDX-License-Identifier: BSD-3-Clause
// JSON configuration files for the subcommands: --config FILE, --print-config, and the effective
// options every output records (docs/pipeline.md, "Configuration files").
#pragma once

#include <CLI/CLI.hpp>
#include <istream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tofnav {

/// CLI11's configuration formatter for JSON. A file holds the options by long name without
/// dashes ("ab-threshold": 1280; positionals by name), either at the top level or in the
/// section of the command ({"track": {...}} or {"evaluate": {"suite": {...}}}), so that one file
/// can configure several commands; sections of other tofnav commands are skipped. Other nested
/// objects are CLI11 subcommand sections. null (or []) leaves an option unset.
class JsonConfig : public CLI::Config {
 public:
  /// `section`: the command's path, e.g. {"evaluate", "suite"}.
  explicit JsonConfig(std::vector<std::string> section) : section_(std::move(section)) {}
  /// The options as JSON, inside the command's section; `default_also`: unset options with
  /// their defaults (null where there is none).
  std::string to_config(const CLI::App* app, bool default_also, bool write_description,
                        std::string prefix) const override;
  /// Throws CLI::ConfigError naming the key, or the line and column of a syntax error.
  std::vector<CLI::ConfigItem> from_config(std::istream& input) const override;

 private:
  std::vector<std::string> section_;
};

/// Adds --config FILE and --print-config to `app` (named "tofnav <command>...") and makes every
/// option added afterwards show its default in --help. Call before adding options.
void AddConfigOptions(CLI::App& app);

/// An enum option given by name (case-insensitive), so that --help, --print-config and the
/// recorded options show "zdepth", not 1.
template <class Enum>
CLI::Option* AddEnumOption(CLI::App& app, const std::string& name, Enum& value,
                           const std::map<std::string, Enum>& names, const std::string& help) {
  std::vector<std::string> keys;
  std::string current;
  for (const auto& [key, v] : names) {
    keys.push_back(key);
    if (v == value) current = key;
  }
  return app
      .add_option_function<std::string>(
          name, [&value, names](const std::string& key) { value = names.at(key); }, help)
      ->check(CLI::IsMember(keys, CLI::ignore_case))
      ->default_str(current);
}

/// The options `app` ran with (command line over file over defaults), flat: the "options"
/// object of --json summaries and of the files the commands write.
nlohmann::ordered_json EffectiveOptions(const CLI::App& app);

/// `json` with "options": EffectiveOptions(app) added, as the --json summaries print it.
nlohmann::ordered_json WithOptions(nlohmann::ordered_json json, const CLI::App& app);

/// Parses the command line (and the --config file). Returns the exit code when the command is
/// done: --help, --print-config (prints the effective options), or an error (one line on
/// stderr; a configuration error names the file).
std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv);

}  // namespace tofnav

/// CLI11_PARSE with --config and --print-config.
#define TOFNAV_PARSE(app, argc, argv)                                                     \
  if (const std::optional<int> tofnav_exit = ::tofnav::ParseCommandLine(app, argc, argv)) \
  return *tofnav_exit
