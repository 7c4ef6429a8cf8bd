// SPDX-License-Identifier: BSD-3-Clause
#include "config_json.hpp"

#include <algorithm>
#include <iostream>
#include <memory>
#include <sstream>
#include <string_view>
#include <utility>

#include "commands.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

// "1280" -> 1280, "true" -> true; anything that would not read back identically stays a string.
OrderedJson Typed(const std::string& s) {
  if (s == "true" || s == "false") return s == "true";
  const OrderedJson number = OrderedJson::parse(s, nullptr, false);
  if (number.is_number() && number.dump() == s) return number;
  return s;
}

// CLI11 writes a container's default as "[a,b]".
std::vector<std::string> SplitListDefault(std::string text) {
  if (text.size() >= 2 && text.front() == '[' && text.back() == ']') {
    text = text.substr(1, text.size() - 2);
  }
  std::vector<std::string> items;
  if (text.empty()) return items;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) items.push_back(item);
  return items;
}

// The option's value (given, else its default; null when it has none).
OrderedJson OptionValue(const CLI::Option& opt) {
  const bool flag = opt.get_expected_min() == 0;
  const bool list = opt.get_items_expected_max() > 1;
  std::vector<std::string> values;
  if (opt.count() > 0) {
    values = opt.reduced_results();
  } else if (list) {
    values = SplitListDefault(opt.get_default_str());
  } else if (!opt.get_default_str().empty()) {
    values = {opt.get_default_str()};
  }
  if (flag) return !values.empty() && CLI::detail::to_flag_value(values.back()) > 0;
  if (values.empty()) return nullptr;
  if (!list) return Typed(values.back());
  OrderedJson array = OrderedJson::array();
  for (const std::string& v : values) array.push_back(Typed(v));
  return array;
}

OrderedJson OptionsObject(const CLI::App& app, bool default_also) {
  OrderedJson out = OrderedJson::object();
  for (const CLI::Option* opt : app.get_options()) {
    if (!opt->get_configurable() || (!default_also && opt->count() == 0)) continue;
    out[opt->get_single_name()] = OptionValue(*opt);
  }
  for (const CLI::App* sub : app.get_subcommands({})) {
    out[sub->get_name()] = OptionsObject(*sub, default_also);
  }
  return out;
}

std::string Joined(const std::vector<std::string>& path) {
  std::string text;
  for (const std::string& key : path) text += (text.empty() ? "" : ".") + key;
  return text;
}

std::string InputText(const OrderedJson& value, const std::vector<std::string>& path) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number() || value.is_boolean()) return value.dump();
  throw CLI::ConfigError("key '" + Joined(path) +
                         "': expected a number, a string, a boolean or an array of them");
}

bool IsPrefix(const std::vector<std::string>& prefix, const std::vector<std::string>& of) {
  return prefix.size() <= of.size() && std::equal(prefix.begin(), prefix.end(), of.begin());
}

// Adds the options of `object` (at `path` in the file; `parents`: CLI11 subcommand sections).
void Collect(const OrderedJson& object, const std::vector<std::string>& section,
             const std::vector<std::string>& path, const std::vector<std::string>& parents,
             std::vector<CLI::ConfigItem>& items) {
  for (const auto& [key, value] : object.items()) {
    std::vector<std::string> key_path = path;
    key_path.push_back(key);
    if (value.is_object()) {
      if (parents.empty() && IsPrefix(key_path, section)) {
        Collect(value, section, key_path, parents, items);         // this command's section
      } else if (!(parents.empty() && IsCommandPath(key_path))) {  // not another command's
        std::vector<std::string> sub = parents;
        sub.push_back(key);
        Collect(value, section, key_path, sub, items);
      }
      continue;
    }
    CLI::ConfigItem item;
    item.parents = parents;
    item.name = key;
    if (value.is_array()) {
      for (const OrderedJson& element : value) item.inputs.push_back(InputText(element, key_path));
    } else if (!value.is_null()) {
      item.inputs.push_back(InputText(value, key_path));
    }
    if (!item.inputs.empty()) items.push_back(std::move(item));
  }
}

std::string ConfigFile(const CLI::App& app) {
  const CLI::Option* config = app.get_config_ptr();
  return config != nullptr && config->count() > 0 ? config->as<std::string>() : std::string();
}

// CLI11's wording for a key no option takes.
std::string ConfigMessage(std::string message) {
  const std::string_view extras = "INI was not able to parse ";
  if (message.rfind(extras, 0) == 0) {
    return "unknown option '" + message.substr(extras.size()) + "'";
  }
  return message;
}

}  // namespace

std::string JsonConfig::to_config(const CLI::App* app, bool default_also, bool, std::string) const {
  OrderedJson out = OptionsObject(*app, default_also);
  for (auto key = section_.rbegin(); key != section_.rend(); ++key) out = OrderedJson{{*key, out}};
  return out.dump(2) + "\n";
}

std::vector<CLI::ConfigItem> JsonConfig::from_config(std::istream& input) const {
  OrderedJson document;
  try {
    document = OrderedJson::parse(input);
  } catch (const OrderedJson::parse_error& e) {
    const std::string what = e.what();
    throw CLI::ConfigError("invalid JSON: " + what.substr(what.find(']') + 2));
  }
  if (!document.is_object()) throw CLI::ConfigError("expected a JSON object of options");
  std::vector<CLI::ConfigItem> collected;
  Collect(document, section_, {}, {}, collected);
  return collected;
}

void AddConfigOptions(CLI::App& app) {
  app.option_defaults()->always_capture_default();
  std::vector<std::string> section;
  std::stringstream name(app.get_name());
  for (std::string word; name >> word;) section.push_back(word);
  if (!section.empty()) section.erase(section.begin());  // "tofnav"
  app.config_formatter(std::make_shared<JsonConfig>(section));
  app.allow_config_extras(CLI::config_extras_mode::error);
  app.set_config("--config", "",
                 "JSON file of options, as --print-config writes it (the command line overrides "
                 "it; docs/pipeline.md)");
  app.set_version_flag("--version", TOFNAV_VERSION);
  const std::string print_help = "print the effective options as JSON and exit";
  app.add_flag("--print-config", print_help)->configurable(false);
}

OrderedJson EffectiveOptions(const CLI::App& app) { return OptionsObject(app, true); }

OrderedJson WithOptions(OrderedJson json, const CLI::App& app) {
  json["options"] = EffectiveOptions(app);
  return json;
}

std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv) {
  const bool print = std::any_of(argv + 1, argv + argc, [](const char* arg) {
    return std::string_view(arg) == "--print-config";
  });
  for (CLI::Option* opt : app.get_options({})) {
    if (opt->get_default_str() == "[]") opt->default_str("");  // no "=[]" in --help
    if (print) opt->required(false);  // the options of a configuration need not be complete
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    const std::string file = ConfigFile(app);
    std::cerr << app.get_name() << ": error: ";
    if (dynamic_cast<const CLI::ConfigError*>(&e) || dynamic_cast<const CLI::FileError*>(&e)) {
      std::cerr << "config " << file << ": " << ConfigMessage(e.what()) << "\n";
    } else {
      std::cerr << e.what() << (file.empty() ? "" : " (with --config " + file + ")") << "\n";
    }
    return e.get_exit_code();
  }
  if (!print) return std::nullopt;
  std::cout << app.config_to_str(true, false);
  return 0;
}

}  // namespace tofnav
