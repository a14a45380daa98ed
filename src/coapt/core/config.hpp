#pragma once
/// @file config.hpp
/// Case files: one YAML document per case, read once into each module's `const` parameter
/// struct. Every key is read through a Section with its unit, default and documentation, so
///  - a wrong type or a non-physical value is rejected as `file:line: key.path: message`;
///  - keys nobody read (typos, misplaced keys) are rejected by Document::reject_unknown_keys();
///  - the case as resolved (defaults and --set overrides applied) can be written back;
///  - the keys a case understands can be listed with their units and defaults (`coapt keys`).

#include <yaml-cpp/yaml.h>

#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace coapt::config {

/// Admissible range of a numeric key.
struct Bounds {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  bool lower_open = false;
  bool upper_open = false;

  static Bounds any() { return {}; }
  static Bounds positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Bounds non_negative() {
    return {0.0, std::numeric_limits<double>::infinity(), false, false};
  }
  static Bounds closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Bounds open(double lo, double hi) { return {lo, hi, true, true}; }
  bool contains(double value) const;
  std::string describe() const;
};

/// What a key means: its unit (SI; "" if dimensionless), one line of documentation, its range.
struct KeyInfo {
  std::string_view unit;
  std::string_view doc;
  Bounds bounds = Bounds::any();
};

/// One documented key as read by some module (for `coapt keys` and the user guide).
struct KeyRecord {
  std::string path;
  std::string type;
  std::string default_value;  ///< "" when required
  std::string unit;
  std::string doc;
  std::string range;
};

class Document;

/// A view of one mapping in the case (the root or a nested section). Cheap to copy.
class Section {
 public:
  /// Value of `key`, or `default_value` when absent. T: double, int, bool, std::string,
  /// std::vector<double>, std::vector<std::string>. Throws InputError on a wrong type or range.
  template <class T>
  T get(std::string_view key, const T& default_value, const KeyInfo& info) const;
  /// Value of a key that must be given. Throws InputError naming the section when absent.
  template <class T>
  T require(std::string_view key, const KeyInfo& info) const;
  /// One of `choices`, or `default_value` when absent.
  std::string choice(std::string_view key, const std::string& default_value,
                     const std::vector<std::string>& choices, const KeyInfo& info) const;
  /// Whether `key` is present.
  bool has(std::string_view key) const;
  /// The nested section `key` (an empty one when absent: its keys take their defaults).
  Section section(std::string_view key, std::string_view doc = "") const;
  /// The elements of the sequence of sections `key` (empty when absent).
  std::vector<Section> sections(std::string_view key, std::string_view doc = "") const;
  /// Throws InputError located at this section (or at `key` inside it when given).
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;
  /// Dotted path of this section ("" for the root).
  const std::string& path() const { return path_; }
  /// Location "file:line" of `key` (or of this section when key is empty).
  std::string where(std::string_view key = "") const;
  /// "file:line: path" of `key` (or of this section): the prefix of a message about it.
  std::string located(std::string_view key = "") const;
  /// Folder of the case file: relative paths in the case are relative to it.
  std::string case_directory() const;

 private:
  friend class Document;
  Section(Document* document, YAML::Node node, YAML::Node resolved, std::string path)
      : document_(document),
        node_(std::move(node)),
        resolved_(std::move(resolved)),
        path_(std::move(path)) {}
  std::string child_path(std::string_view key) const;
  YAML::Node child(std::string_view key) const;
  template <class T>
  T convert(std::string_view key, const YAML::Node& value, const KeyInfo& info) const;
  void record(std::string_view key, const std::string& type, const std::string& default_value,
              const KeyInfo& info) const;

  Document* document_;
  YAML::Node node_;              ///< the user's mapping (may be undefined)
  mutable YAML::Node resolved_;  ///< the resolved mapping being built (a shared view)
  std::string path_;
};

/// A case file with its overrides; owns the YAML tree and the record of what was read.
class Document {
 public:
  /// Parses `path`; throws InputError "file:line: message" on unreadable or malformed YAML.
  static Document from_file(const std::string& path);
  /// Parses YAML text; `name` stands for the file in messages.
  static Document from_string(const std::string& text, const std::string& name);

  /// Applies `key.path=value` (value in YAML syntax); throws InputError on a malformed one.
  void set(const std::string& assignment);
  /// The root section.
  Section root();
  /// Throws InputError at the first key that no module read: "file:line: key: unknown key".
  void reject_unknown_keys() const;
  /// The case as resolved (every key read, with defaults and overrides) as YAML text.
  std::string resolved_yaml() const;
  /// Every key read so far, with unit, default and documentation.
  const std::vector<KeyRecord>& keys() const { return records_; }
  /// The file name used in messages.
  const std::string& name() const { return name_; }
  /// The directory of the case file (relative paths in the case are relative to it).
  std::string directory() const;

 private:
  friend class Section;
  Document() = default;
  std::string where(const YAML::Node& node, const std::string& path) const;
  void mark_used(const std::string& path, std::string_view key);

  std::string name_;
  YAML::Node tree_;
  YAML::Node resolved_;
  std::map<std::string, std::string> overrides_;          ///< path -> "--set ..." text
  std::map<std::string, std::vector<std::string>> used_;  ///< section path -> keys read
  std::vector<KeyRecord> records_;
};

}  // namespace coapt::config
