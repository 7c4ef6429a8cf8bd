// SPDX-License-Identifier: BSD-3-Clause
// Recursive-descent reader of the XML plist subset; entities: the five predefined ones only.
#include "tofnav/volume/plist.hpp"

#include <algorithm>
#include <iterator>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr int kMaxPlistDepth = 32;

class PlistParser {
 public:
  PlistParser(std::string_view text, const std::filesystem::path& path, std::uint64_t base)
      : text_(text), path_(path), base_(base) {}

  PlistValue Document() {
    SkipProlog();
    ExpectOpen("plist");
    PlistValue root = Value(0);
    Expect("</plist>");
    return root;
  }

 private:
  [[noreturn]] void Fail(const std::string& message) const {
    throw IoError(path_, base_ + position_, "XML plist: " + message);
  }
  void SkipBlanks() {
    while (position_ < text_.size() &&
           std::string_view(" \t\r\n").find(text_[position_]) != std::string_view::npos) {
      ++position_;
    }
  }
  void SkipPast(std::string_view end) {
    const std::size_t found = text_.find(end, position_);
    if (found == std::string_view::npos) Fail("expected '" + std::string(end) + "'");
    position_ = found + end.size();
  }
  void SkipProlog() {
    for (SkipBlanks(); text_.substr(position_, 2) == "<?" || text_.substr(position_, 2) == "<!";
         SkipBlanks()) {
      SkipPast(text_.substr(position_, 4) == "<!--" ? "-->" : ">");
    }
  }
  bool Accept(std::string_view token) {
    SkipBlanks();
    if (text_.substr(position_, token.size()) != token) return false;
    position_ += token.size();
    return true;
  }
  void Expect(std::string_view token) {
    if (!Accept(token)) Fail("expected '" + std::string(token) + "'");
  }
  void ExpectOpen(std::string_view name) {  // <name ...attributes>
    Expect(std::string("<").append(name));  // (GCC 12 -O3: false -Wrestrict on "<" + string)
    SkipPast(">");
  }
  // Text up to "</name>", with the five predefined XML entities decoded.
  std::string Text(std::string_view name) {
    const std::string close = std::string("</").append(name).append(">");
    const std::size_t end = text_.find(close, position_);
    if (end == std::string_view::npos) Fail("expected '" + close + "'");
    std::string out;
    for (std::size_t n = position_; n < end; ++n) {
      if (text_[n] != '&') {
        out += text_[n];
        continue;
      }
      static constexpr std::pair<std::string_view, char> kEntities[] = {
          {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
      const auto entity =
          std::find_if(std::begin(kEntities), std::end(kEntities),
                       [&](const auto& e) { return text_.substr(n).starts_with(e.first); });
      if (entity == std::end(kEntities)) Fail("unsupported XML entity");
      out += entity->second;
      n += entity->first.size() - 1;
    }
    position_ = end + close.size();
    return out;
  }
  PlistValue Value(int depth) {
    if (depth > kMaxPlistDepth) Fail("nesting too deep");
    PlistValue value;
    if (Accept("<dict/>")) {
      value.kind = PlistValue::Kind::kDict;
    } else if (Accept("<dict>")) {
      value.kind = PlistValue::Kind::kDict;
      while (!Accept("</dict>")) {
        Expect("<key>");
        std::string key = Text("key");
        value.keys.push_back(std::move(key));
        value.items.push_back(Value(depth + 1));
      }
    } else if (Accept("<array/>")) {
      value.kind = PlistValue::Kind::kArray;
    } else if (Accept("<array>")) {
      value.kind = PlistValue::Kind::kArray;
      while (!Accept("</array>")) value.items.push_back(Value(depth + 1));
    } else if (Accept("<true/>") || Accept("<false/>")) {
      value.kind = PlistValue::Kind::kBool;
      value.flag = text_.substr(position_ - 7, 7) == "<true/>";
    } else if (Accept("<string/>")) {
      value.kind = PlistValue::Kind::kString;
    } else if (Accept("<string>") || Accept("<date>")) {
      value.kind = PlistValue::Kind::kString;
      value.text = Text(text_.substr(position_ - 6, 6) == "<date>" ? "date" : "string");
    } else if (Accept("<integer>") || Accept("<real>")) {
      value.kind = PlistValue::Kind::kNumber;
      value.text = Text(text_.substr(position_ - 6, 6) == "<real>" ? "real" : "integer");
    } else {
      Fail("expected a plist value (dict, array, string, integer, real, true, false)");
    }
    return value;
  }

  std::string_view text_;
  const std::filesystem::path& path_;
  std::uint64_t base_;
  std::size_t position_ = 0;
};

}  // namespace

const PlistValue* PlistValue::Find(std::string_view key) const {
  for (std::size_t n = 0; n < keys.size() && n < items.size(); ++n) {
    if (keys[n] == key) return &items[n];
  }
  return nullptr;
}

PlistValue ParsePlist(std::string_view text, const std::filesystem::path& path,
                      std::uint64_t base_offset) {
  return PlistParser(text, path, base_offset).Document();
}

}  // namespace tofnav
