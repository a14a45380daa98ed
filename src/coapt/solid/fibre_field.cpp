// Fibre directions per cell: the constant, circumferential and file rules (fibre_field.hpp).
#include "coapt/solid/fibre_field.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <unordered_map>

#include "coapt/core/collective.hpp"
#include "coapt/core/error.hpp"

namespace coapt::solid {

using config::Bounds;

namespace {

/// A 2- or 3-component vector key (a 2D vector gets z = 0).
Vector3 read_vector(const config::Section& section, std::string_view key, std::string_view unit,
                    std::string_view doc) {
  const auto values = section.get<std::vector<double>>(key, {}, {unit, doc});
  if (values.size() < 2 || values.size() > 3)
    section.fail(key, "expected 2 or 3 components (a 2D vector gets z = 0)");
  Vector3 vector = Vector3::Zero();
  for (std::size_t i = 0; i < values.size(); ++i) vector(static_cast<int>(i)) = values[i];
  return vector;
}

/// `vector` / |vector|, or InputError at `key` when it is zero or not finite.
Vector3 normalised(const config::Section& section, std::string_view key, const Vector3& vector) {
  const double norm = vector.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) section.fail(key, "must be a non-zero finite vector");
  return vector / norm;
}

/// Splits a CSV line at commas (spaces around entries allowed).
std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    std::string_view field = line.substr(
        start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    while (!field.empty() && std::isspace(static_cast<unsigned char>(field.front())))
      field.remove_prefix(1);
    while (!field.empty() && std::isspace(static_cast<unsigned char>(field.back())))
      field.remove_suffix(1);
    fields.push_back(field);
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

template <class T>
bool parse_number(std::string_view text, T& value) {
  if (text.empty()) return false;
  if constexpr (std::is_floating_point_v<T>) {
    // std::from_chars for double is in libstdc++ 11+; strtod is the portable fallback.
    std::string copy(text);
    char* end = nullptr;
    value = std::strtod(copy.c_str(), &end);
    return end == copy.c_str() + copy.size();
  } else {
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    return error == std::errc() && end == text.data() + text.size();
  }
}

struct CsvRow {
  int line = 0;
  FibreDirections fibres;
};

}  // namespace

FibreFieldParameters FibreFieldParameters::read(const config::Section& body, int families) {
  FibreFieldParameters p;
  const bool short_form = body.has("fibre_direction") || body.has("second_fibre_direction");
  if (short_form) {
    if (body.has("fibres"))
      body.fail("fibres", "give either fibres or fibre_direction (the short form), not both");
    p.where = body.located();
    p.rule = Rule::constant;
    p.constant.a0[0] = read_vector(body, "fibre_direction", "", "unit fibre direction (reference)");
    if (families > 1)
      p.constant.a0[1] = read_vector(body, "second_fibre_direction", "",
                                     "unit direction of the second fibre family (reference)");
    return p;
  }
  const auto section = body.section("fibres", "fibre directions (fibre_reinforced only)");
  p.where = section.located();
  const std::string rule = section.choice(
      "rule", "", {"constant", "circumferential", "file"},
      {"",
       "constant: given directions; circumferential: axis x (X - point); file: CSV per element"});
  if (rule == "constant") {
    p.rule = Rule::constant;
    p.constant.a0[0] = normalised(
        section, "direction",
        read_vector(section, "direction", "", "fibre direction, normalised (rule constant)"));
    if (families > 1)
      p.constant.a0[1] =
          normalised(section, "second_direction",
                     read_vector(section, "second_direction", "",
                                 "direction of the second family, normalised (rule constant)"));
  } else if (rule == "circumferential") {
    p.rule = Rule::circumferential;
    p.axis = normalised(section, "axis",
                        read_vector(section, "axis", "", "axis direction (rule circumferential)"));
    p.point = section.has("point")
                  ? read_vector(section, "point", "m", "a point on the axis (rule circumferential)")
                  : Vector3::Zero();
    p.angle = section.get<double>("angle", 0.0,
                                  {"degree", "tilt of the families towards the axis (+/- angle)",
                                   Bounds::closed(-90.0, 90.0)}) *
              std::numbers::pi / 180.0;
  } else {
    p.rule = Rule::file;
    const auto file = section.require<std::string>(
        "file", {"", "CSV: element, a1x, a1y, a1z[, a2x, a2y, a2z] (relative to the case)"});
    const std::filesystem::path path(file);
    p.file =
        path.is_absolute()
            ? file
            : (std::filesystem::path(section.case_directory()) / path).lexically_normal().string();
  }
  return p;
}

std::string FibreFieldParameters::describe(int families) const {
  const auto vector = [](const Vector3& v) {
    return fmt::format("({:.4g}, {:.4g}, {:.4g})", v.x(), v.y(), v.z());
  };
  switch (rule) {
    case Rule::constant:
      return families > 1
                 ? fmt::format("constant {} and {}", vector(constant.a0[0]), vector(constant.a0[1]))
                 : fmt::format("constant {}", vector(constant.a0[0]));
    case Rule::circumferential:
      return fmt::format("circumferential about {} through {}, {}{:g} degrees", vector(axis),
                         vector(point), families > 1 ? "+/-" : "",
                         angle * 180.0 / std::numbers::pi);
    case Rule::file:
      return "from " + file;
  }
  return "";
}

FibreDirections circumferential_fibres(const FibreFieldParameters& field, const Vector3& X,
                                       const std::string& where) {
  const Vector3 tangential = field.axis.cross(X - field.point);
  const double norm = tangential.norm();
  // The centroid is on the axis when its distance is below round-off of the coordinates.
  const double scale = std::max(X.norm(), field.point.norm());
  if (!(norm > 1e-12 * std::max(scale, 1e-300)))
    throw InputError(fmt::format(
        "{}: lies on the axis of the circumferential fibre rule, which gives it no direction",
        where));
  const Vector3 c = tangential / norm;
  FibreDirections fibres;
  fibres.a0[0] = std::cos(field.angle) * c + std::sin(field.angle) * field.axis;
  fibres.a0[1] = std::cos(field.angle) * c - std::sin(field.angle) * field.axis;
  return fibres;
}

std::vector<FibreDirections> fibres_from_csv(const std::string& text, const std::string& name,
                                             const std::vector<std::int64_t>& elements,
                                             std::size_t n_owned, int families, MPI_Comm comm) {
  const std::size_t columns = 1 + 3 * static_cast<std::size_t>(families);
  std::unordered_map<std::int64_t, std::size_t> row_of_element;
  std::vector<CsvRow> rows;
  std::vector<FibreDirections> result;
  std::string message;
  try {
    std::istringstream stream(text);
    std::string line;
    int number = 0;
    bool first_data = true;
    while (std::getline(stream, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto fields = split(line);
      if (fields.size() == 1 && fields[0].empty()) continue;
      if (!fields[0].empty() && fields[0].front() == '#') continue;
      std::int64_t element = 0;
      if (!parse_number(fields[0], element)) {
        if (first_data) {  // a header
          first_data = false;
          continue;
        }
        throw InputError(fmt::format("{}:{}: '{}' is not an element number", name, number,
                                     std::string(fields[0])));
      }
      first_data = false;
      if (fields.size() != columns)
        throw InputError(fmt::format(
            "{}:{}: {} columns, expected {} (element and {} direction(s) of 3 components)", name,
            number, fields.size(), columns, families));
      CsvRow row;
      row.line = number;
      for (int f = 0; f < families; ++f) {
        Vector3 a = Vector3::Zero();
        for (int i = 0; i < 3; ++i) {
          const auto field = fields[1 + 3 * static_cast<std::size_t>(f) + i];
          if (!parse_number(field, a(i)))
            throw InputError(
                fmt::format("{}:{}: '{}' is not a number", name, number, std::string(field)));
        }
        const double norm = a.norm();
        if (!(norm > 0.0) || !std::isfinite(norm))
          throw InputError(
              fmt::format("{}:{}: element {}: fibre direction {} is zero or not finite", name,
                          number, element, f + 1));
        row.fibres.a0[f] = a / norm;
      }
      const auto [it, inserted] = row_of_element.emplace(element, rows.size());
      if (!inserted)
        throw InputError(fmt::format("{}:{}: element {} is given again (first on line {})", name,
                                     number, element, rows[it->second].line));
      rows.push_back(row);
    }
    result.reserve(elements.size());
    for (std::int64_t element : elements) {
      const auto it = row_of_element.find(element);
      if (it == row_of_element.end())
        throw InputError(fmt::format("{}: element {} of the body has no row ({} rows)", name,
                                     element, rows.size()));
      result.push_back(rows[it->second].fibres);
    }
  } catch (const InputError& e) {
    message = e.what();
  }
  rethrow_collectively(comm, message, true);

  // Every row must name an owned element of the body on some rank.
  std::vector<unsigned char> used(rows.size(), 0);
  for (std::size_t k = 0; k < n_owned; ++k) used[row_of_element.at(elements[k])] = 1;
  if (!used.empty())
    MPI_Allreduce(MPI_IN_PLACE, used.data(), static_cast<int>(used.size()), MPI_UNSIGNED_CHAR,
                  MPI_MAX, comm);
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (!used[r]) {
      std::int64_t element = 0;
      for (const auto& [e, row] : row_of_element)
        if (row == r) element = e;
      throw InputError(fmt::format("{}:{}: element {} is not an element of the body", name,
                                   rows[r].line, element));
    }
  return result;
}

}  // namespace coapt::solid
