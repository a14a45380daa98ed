#include "coapt/core/config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "coapt/core/error.hpp"

namespace coapt::config {
namespace {

std::string format_number(double value) {
  return fmt::format("{:g}", value);
}

template <class T>
std::string type_name() {
  if constexpr (std::is_same_v<T, double>) return "number";
  if constexpr (std::is_same_v<T, int>) return "integer";
  if constexpr (std::is_same_v<T, bool>) return "boolean";
  if constexpr (std::is_same_v<T, std::string>) return "string";
  if constexpr (std::is_same_v<T, std::vector<double>>) return "list of numbers";
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return "list of strings";
}

template <class T>
std::string to_text(const T& value) {
  if constexpr (std::is_same_v<T, double>) return format_number(value);
  if constexpr (std::is_same_v<T, int>) return std::to_string(value);
  if constexpr (std::is_same_v<T, bool>) return value ? "true" : "false";
  if constexpr (std::is_same_v<T, std::string>) return value.empty() ? "\"\"" : value;
  if constexpr (std::is_same_v<T, std::vector<double>>) {
    std::string text = "[";
    for (std::size_t i = 0; i < value.size(); ++i)
      text += (i ? ", " : "") + format_number(value[i]);
    return text + "]";
  }
  if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    std::string text = "[";
    for (std::size_t i = 0; i < value.size(); ++i) text += (i ? ", " : "") + value[i];
    return text + "]";
  }
}

/// Normalises "solids[3].material" to "solids[].material" for the key documentation.
std::string generic_path(const std::string& path) {
  static const std::regex index(R"(\[[0-9]+\])");
  return std::regex_replace(path, index, "[]");
}

/// Parses a scalar as a double the way a user means it ("1e-3", "2", not "abc" or "1,5").
std::optional<double> parse_double(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return value;
}

std::optional<bool> parse_bool(const std::string& text) {
  static const std::set<std::string> yes{"true", "True", "TRUE", "yes", "on"};
  static const std::set<std::string> no{"false", "False", "FALSE", "no", "off"};
  if (yes.count(text)) return true;
  if (no.count(text)) return false;
  return std::nullopt;
}

}  // namespace

bool Bounds::contains(double value) const {
  if (lower_open ? !(value > lower) : !(value >= lower)) return false;
  if (upper_open ? !(value < upper) : !(value <= upper)) return false;
  return true;
}

std::string Bounds::describe() const {
  const bool has_lower = std::isfinite(lower), has_upper = std::isfinite(upper);
  if (has_lower && has_upper)
    return fmt::format("{}{}, {}{}", lower_open ? "(" : "[", format_number(lower),
                       format_number(upper), upper_open ? ")" : "]");
  if (has_lower) return fmt::format("{} {}", lower_open ? ">" : ">=", format_number(lower));
  if (has_upper) return fmt::format("{} {}", upper_open ? "<" : "<=", format_number(upper));
  return "";
}

// ---------------------------------------------------------------------------------------
// Section

std::string Section::child_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

YAML::Node Section::child(std::string_view key) const {
  if (!node_.IsDefined() || node_.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node& node = node_;
  return node[std::string(key)];
}

std::string Section::where(std::string_view key) const {
  if (key.empty()) return document_->where(node_, path_);
  YAML::Node value = child(key);
  if (value.IsDefined()) return document_->where(value, child_path(key));
  return document_->where(node_, path_);
}

std::string Section::located(std::string_view key) const {
  return fmt::format("{}: {}", where(key), key.empty() ? path_ : child_path(key));
}

void Section::fail(std::string_view key, const std::string& message) const {
  const std::string path = key.empty() ? path_ : child_path(key);
  throw InputError(fmt::format("{}: {}: {}", where(key), path.empty() ? "(case)" : path, message));
}

std::string Section::case_directory() const {
  return document_->directory();
}

bool Section::has(std::string_view key) const {
  YAML::Node value = child(key);
  return value.IsDefined() && !value.IsNull();
}

void Section::record(std::string_view key, const std::string& type,
                     const std::string& default_value, const KeyInfo& info) const {
  document_->mark_used(path_, key);
  const std::string path = generic_path(child_path(key));
  auto& records = document_->records_;
  if (std::any_of(records.begin(), records.end(), [&](const auto& r) { return r.path == path; }))
    return;
  records.push_back({path, type, default_value, std::string(info.unit), std::string(info.doc),
                     info.bounds.describe()});
}

template <class T>
T Section::convert(std::string_view key, const YAML::Node& value, const KeyInfo& info) const {
  auto check_number = [&](double number) {
    if (!std::isfinite(number)) fail(key, "must be a finite number");
    if (!info.bounds.contains(number))
      fail(key, fmt::format("value {} is out of range: must be {}{}", format_number(number),
                            info.bounds.describe(),
                            info.unit.empty() ? "" : " " + std::string(info.unit)));
  };
  auto scalar_text = [&](const YAML::Node& node) -> std::string {
    if (!node.IsScalar()) fail(key, "expected a " + type_name<T>());
    return node.Scalar();
  };
  if constexpr (std::is_same_v<T, double>) {
    const auto number = parse_double(scalar_text(value));
    if (!number) fail(key, fmt::format("expected a number, got '{}'", value.Scalar()));
    check_number(*number);
    return *number;
  } else if constexpr (std::is_same_v<T, int>) {
    const std::string text = scalar_text(value);
    const auto number = parse_double(text);
    if (!number || std::floor(*number) != *number || std::abs(*number) > 2e9)
      fail(key, fmt::format("expected an integer, got '{}'", text));
    check_number(*number);
    return static_cast<int>(*number);
  } else if constexpr (std::is_same_v<T, bool>) {
    const auto flag = parse_bool(scalar_text(value));
    if (!flag) fail(key, fmt::format("expected true or false, got '{}'", value.Scalar()));
    return *flag;
  } else if constexpr (std::is_same_v<T, std::string>) {
    return scalar_text(value);
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    if (!value.IsSequence()) fail(key, "expected a list of numbers, e.g. [1, 2, 3]");
    std::vector<double> numbers;
    for (const auto& item : value) {
      const auto number = item.IsScalar() ? parse_double(item.Scalar()) : std::nullopt;
      if (!number) fail(key, "expected a list of numbers, e.g. [1, 2, 3]");
      check_number(*number);
      numbers.push_back(*number);
    }
    return numbers;
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    if (!value.IsSequence()) fail(key, "expected a list of strings, e.g. [a, b]");
    std::vector<std::string> texts;
    for (const auto& item : value) {
      if (!item.IsScalar()) fail(key, "expected a list of strings, e.g. [a, b]");
      texts.push_back(item.Scalar());
    }
    return texts;
  }
}

template <class T>
T Section::get(std::string_view key, const T& default_value, const KeyInfo& info) const {
  record(key, type_name<T>(), to_text(default_value), info);
  YAML::Node value = child(key);
  T result = default_value;
  if (value.IsDefined() && !value.IsNull()) result = convert<T>(key, value, info);
  resolved_[std::string(key)] = result;
  return result;
}

template <class T>
T Section::require(std::string_view key, const KeyInfo& info) const {
  record(key, type_name<T>(), "", info);
  YAML::Node value = child(key);
  if (!value.IsDefined() || value.IsNull())
    fail(key, fmt::format("required key is missing ({}{})", type_name<T>(),
                          info.unit.empty() ? "" : ", in " + std::string(info.unit)));
  T result = convert<T>(key, value, info);
  resolved_[std::string(key)] = result;
  return result;
}

std::string Section::choice(std::string_view key, const std::string& default_value,
                            const std::vector<std::string>& choices, const KeyInfo& info) const {
  std::string options, listed;
  for (const auto& c : choices) {
    options += (options.empty() ? "" : " | ") + c;
    listed += (listed.empty() ? "" : ", ") + c;
  }
  KeyInfo described = info;
  const std::string doc = std::string(info.doc) + " (one of: " + listed + ")";
  described.doc = doc;
  const std::string value = default_value.empty() ? require<std::string>(key, described)
                                                  : get<std::string>(key, default_value, described);
  if (std::find(choices.begin(), choices.end(), value) == choices.end())
    fail(key, fmt::format("'{}' is not one of: {}", value, options));
  return value;
}

Section Section::section(std::string_view key, std::string_view doc) const {
  record(key, "section", "", KeyInfo{"", doc});
  YAML::Node value = child(key);
  if (value.IsDefined() && !value.IsNull() && !value.IsMap())
    fail(key, "expected a section (a mapping of keys to values)");
  const std::string path = child_path(key);
  document_->used_[path];  // registers the section even when it stays empty
  YAML::Node resolved = resolved_[std::string(key)];
  if (!resolved.IsMap()) {
    resolved_[std::string(key)] = YAML::Node(YAML::NodeType::Map);
    resolved = resolved_[std::string(key)];
  }
  return Section(document_, value, resolved, path);
}

std::vector<Section> Section::sections(std::string_view key, std::string_view doc) const {
  record(key, "list of sections", "", KeyInfo{"", doc});
  YAML::Node value = child(key);
  std::vector<Section> result;
  if (!value.IsDefined() || value.IsNull()) return result;
  if (!value.IsSequence()) fail(key, "expected a list of sections (lines starting with '- ')");
  YAML::Node resolved_list(YAML::NodeType::Sequence);
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string path = child_path(key) + "[" + std::to_string(i) + "]";
    if (!value[i].IsMap())
      throw InputError(fmt::format("{}: {}: expected a section (a mapping of keys to values)",
                                   document_->where(value[i], path), path));
    YAML::Node element(YAML::NodeType::Map);
    resolved_list.push_back(element);
    document_->used_[path];
    result.push_back(Section(document_, value[i], resolved_list[i], path));
  }
  resolved_[std::string(key)] = resolved_list;
  return result;
}

#define COAPT_CONFIG_INSTANTIATE(T)                                             \
  template T Section::get<T>(std::string_view, const T&, const KeyInfo&) const; \
  template T Section::require<T>(std::string_view, const KeyInfo&) const;
COAPT_CONFIG_INSTANTIATE(double)
COAPT_CONFIG_INSTANTIATE(int)
COAPT_CONFIG_INSTANTIATE(bool)
COAPT_CONFIG_INSTANTIATE(std::string)
COAPT_CONFIG_INSTANTIATE(std::vector<double>)
COAPT_CONFIG_INSTANTIATE(std::vector<std::string>)
#undef COAPT_CONFIG_INSTANTIATE

// ---------------------------------------------------------------------------------------
// Document

Document Document::from_string(const std::string& text, const std::string& name) {
  Document document;
  document.name_ = name;
  try {
    document.tree_ = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}:{}: malformed YAML: {}", name, e.mark.line + 1, e.msg));
  }
  if (!document.tree_.IsDefined() || document.tree_.IsNull())
    document.tree_ = YAML::Node(YAML::NodeType::Map);
  if (!document.tree_.IsMap())
    throw InputError(name + ":1: the case must be a mapping of keys to values");
  document.resolved_ = YAML::Node(YAML::NodeType::Map);
  return document;
}

Document Document::from_file(const std::string& path) {
  std::ifstream file(path);
  if (!file)
    throw InputError(path + ": cannot open the case file (" +
                     (std::filesystem::exists(path) ? "not readable" : "no such file") + ")");
  std::stringstream text;
  text << file.rdbuf();
  return from_string(text.str(), path);
}

std::string Document::directory() const {
  const auto parent = std::filesystem::path(name_).parent_path();
  return parent.empty() ? "." : parent.string();
}

Section Document::root() {
  return Section(this, tree_, resolved_, "");
}

std::string Document::where(const YAML::Node& node, const std::string& path) const {
  for (const auto& [override_path, text] : overrides_)
    if (path == override_path || path.rfind(override_path + ".", 0) == 0) return "--set " + text;
  if (node.IsDefined() && node.Mark().line >= 0)
    return fmt::format("{}:{}", name_, node.Mark().line + 1);
  return name_;
}

void Document::mark_used(const std::string& path, std::string_view key) {
  auto& keys = used_[path];
  if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.emplace_back(key);
}

void Document::set(const std::string& assignment) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0)
    throw InputError("--set " + assignment + ": expected key.path=value");
  const std::string path = assignment.substr(0, equals);
  const std::string text = assignment.substr(equals + 1);
  YAML::Node value;
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError("--set " + assignment + ": malformed value: " + e.msg);
  }
  static const std::regex component(R"(^([A-Za-z_][A-Za-z0-9_]*)(\[([0-9]+)\])?$)");
  std::vector<std::string> parts;
  std::stringstream stream(path);
  for (std::string part; std::getline(stream, part, '.');) parts.push_back(part);
  YAML::Node node = tree_;
  std::string walked;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    std::smatch match;
    if (!std::regex_match(parts[i], match, component))
      throw InputError("--set " + assignment + ": malformed key '" + parts[i] + "'");
    const std::string key = match[1];
    walked += (walked.empty() ? "" : ".") + parts[i];
    const bool last = i + 1 == parts.size();
    if (!node.IsMap())
      throw InputError("--set " + assignment + ": '" + walked +
                       "' is inside a value, not a section");
    if (match[2].matched) {
      const std::size_t index = std::stoul(match[3]);
      YAML::Node list = node[key];
      if (!list.IsSequence() || index >= list.size())
        throw InputError("--set " + assignment + ": the case has no element " + parts[i]);
      if (last) {
        list[index] = value;
      } else {
        YAML::Node next = list[index];
        node.reset(next);
      }
    } else if (last) {
      node[key] = value;
    } else {
      if (!node[key].IsDefined() || node[key].IsNull()) node[key] = YAML::Node(YAML::NodeType::Map);
      YAML::Node next = node[key];
      node.reset(next);
    }
  }
  overrides_[path] = assignment;
}

void Document::reject_unknown_keys() const {
  // Walk the user's tree; any key that no module read is unknown (a typo or misplaced key).
  auto walk = [&](auto& self, const YAML::Node& node, const std::string& path) -> void {
    const auto used = used_.find(path);
    for (const auto& entry : node) {
      const std::string key = entry.first.Scalar();
      const std::string child = path.empty() ? key : path + "." + key;
      const bool known = used != used_.end() && std::find(used->second.begin(), used->second.end(),
                                                          key) != used->second.end();
      if (!known) {
        std::string hint;
        if (used != used_.end() && !used->second.empty()) {
          for (const auto& k : used->second) hint += (hint.empty() ? "" : ", ") + k;
          hint = " (keys here: " + hint + ")";
        }
        throw InputError(
            fmt::format("{}: {}: unknown key{}", where(entry.first, child), child, hint));
      }
      if (entry.second.IsMap() && used_.count(child)) self(self, entry.second, child);
      if (entry.second.IsSequence())
        for (std::size_t i = 0; i < entry.second.size(); ++i) {
          const std::string element = child + "[" + std::to_string(i) + "]";
          if (entry.second[i].IsMap() && used_.count(element)) self(self, entry.second[i], element);
        }
    }
  };
  walk(walk, tree_, "");
}

std::string Document::resolved_yaml() const {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << resolved_;
  return std::string(out.c_str()) + "\n";
}

}  // namespace coapt::config
