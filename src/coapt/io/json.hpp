#pragma once
/// @file json.hpp
/// A small JSON value for writing results (summary.json): null, bool, integer, number,
/// string, array, object (keys kept in insertion order), its text, and a small parser for
/// reading results back.
///
///   Json summary;                        // null; becomes an object on first operator[]
///   summary["case"] = "cylinder";
///   summary["steps"] = 120;
///   summary["drag"] = Json::array({1.5, 1.25});
///   summary["fluid"]["iterations"].push_back(3);
///   std::string text = summary.dump(2);  // like Python's json.dumps(value, indent=2)
///
/// Numbers that are not finite (NaN, ±inf) cannot be written in JSON: dump() writes them
/// as null, and has_non_finite() tells whether a value holds any, so callers can refuse or
/// warn (the project never hides a NaN silently).

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace coapt::io {

class Json {
 public:
  enum class Type { null, boolean, integer, number, string, array, object };
  using Array = std::vector<Json>;
  using Object = std::vector<std::pair<std::string, Json>>;  ///< insertion order

  Json() = default;
  Json(std::nullptr_t) {}
  Json(bool value) : value_(value) {}
  template <class T>
  requires(std::is_integral_v<T> && !std::is_same_v<T, bool>) Json(T value)
      : value_(static_cast<std::int64_t>(value)) {}
  Json(double value) : value_(value) {}
  Json(float value) : value_(static_cast<double>(value)) {}
  Json(const char* value) : value_(std::string(value)) {}
  Json(std::string value) : value_(std::move(value)) {}
  Json(std::string_view value) : value_(std::string(value)) {}

  /// An array of the given elements (empty by default).
  static Json array(std::initializer_list<Json> elements = {});
  /// An array of the values of a range (e.g. a std::vector<double>).
  template <class Range>
  static Json array_of(const Range& range) {
    Json out = array();
    for (const auto& element : range) out.push_back(Json(element));
    return out;
  }
  /// An object of the given members, in this order (empty by default). A repeated key
  /// keeps its first position and the last value.
  static Json object(std::initializer_list<std::pair<std::string, Json>> members = {});

  Type type() const { return static_cast<Type>(value_.index()); }
  bool is_null() const { return type() == Type::null; }
  bool is_object() const { return type() == Type::object; }
  bool is_array() const { return type() == Type::array; }

  /// The member `key` of an object, added (null) at the end if missing. A null value
  /// becomes an empty object first; any other non-object throws InternalError.
  Json& operator[](std::string_view key);
  /// The member `key`; throws InternalError if this is not an object or has no such key.
  const Json& at(std::string_view key) const;
  /// Element `index` of an array; throws InternalError if out of range or not an array.
  const Json& at(std::size_t index) const;
  Json& at(std::size_t index);
  /// Whether this is an object with member `key`.
  bool contains(std::string_view key) const;
  /// Appends to an array. A null value becomes an empty array first; any other non-array
  /// throws InternalError.
  void push_back(Json element);
  /// Number of elements (array) or members (object); 0 for anything else.
  std::size_t size() const;

  /// Accessors; each throws InternalError if the value is of another type (as_double also
  /// accepts an integer).
  bool as_bool() const;
  std::int64_t as_int() const;
  double as_double() const;
  const std::string& as_string() const;
  const Array& as_array() const;
  const Object& as_object() const;

  /// Whether this value or anything inside it is a non-finite number.
  bool has_non_finite() const;

  /// The JSON text, no trailing newline. indent < 0: compact, one line, no spaces
  /// ({"a":1,"b":[1,2]}); indent >= 0: one member or element per line, indented by
  /// `indent` spaces a level, members as "key": value, empty containers as [] and {}.
  /// Integers are written as such; other numbers as Python's repr() writes a float (the
  /// shortest digits that read back to the same double; 3.0, 0.0001, 1e-05, 1e+16); NaN
  /// and ±inf as null. Strings are escaped per RFC 8259 (", \, control characters); other
  /// bytes, UTF-8 included, are written as they are. So the text equals Python's
  /// json.dumps(value, indent=indent, ensure_ascii=False) (compact: separators=(",", ":"))
  /// for the same data.
  std::string dump(int indent = 2) const;

  /// Parses JSON text (RFC 8259; numbers without '.', 'e' or 'E' that fit become integers,
  /// others doubles, read exactly). Small and strict, for reading back results and tool
  /// output (tests, checks); throws coapt::InputError with the byte offset on bad input.
  static Json parse(std::string_view text);

  /// Writes dump(indent) and a newline to `path` (through a temporary file renamed into
  /// place). Throws coapt::Error naming the file if it cannot. Not collective: call it on
  /// one rank.
  void write_file(const std::filesystem::path& path, int indent = 2) const;

  friend bool operator==(const Json&, const Json&) = default;

 private:
  void dump_to(std::string& out, int indent, int level) const;
  std::variant<std::nullptr_t, bool, std::int64_t, double, std::string, Array, Object> value_;
};

/// `text` as a JSON string literal, quotes included.
std::string json_quote(std::string_view text);

}  // namespace coapt::io
