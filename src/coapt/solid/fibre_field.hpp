#pragma once
/// @file fibre_field.hpp
/// Fibre directions per cell for the fibre-reinforced law. A body's `fibres:` section gives
/// them in one of three ways:
///
///   fibres: {rule: constant, direction: [1, 0, 0], second_direction: [0, 1, 0]}
///   fibres: {rule: circumferential, axis: [0, 0, 1], point: [0, 0, 0], angle: 30}
///   fibres: {rule: file, file: fibres.csv}
///
///  - constant: the same unit directions in every cell (the body keys fibre_direction and
///    second_fibre_direction are the short form of it);
///  - circumferential: c = axis × (X_c − point) / |…| at the cell centroid X_c, tilted by
///    ±angle towards the axis: family 1 is cos θ c + sin θ e_axis, family 2 cos θ c − sin θ
///    e_axis (θ = angle in degrees; one family takes the + sign). A centroid on the axis has
///    no circumferential direction and is an error naming the element;
///  - file: a CSV file (relative to the case file) with one row per element of the body,
///    `element, a1x, a1y, a1z` or, for two families, `element, a1x, a1y, a1z, a2x, a2y, a2z`,
///    where `element` is the element number in the mesh source (the Gmsh element tag,
///    Mesh::original_cell; 1, 2, ... for the built-in generators). Blank lines and lines
///    starting with `#` are skipped; a first line that does not start with a number is a
///    header. The directions are normalised; a zero or non-finite vector, a wrong number of
///    columns, a repeated element, an element of the body missing from the file or a row
///    naming no element of the body is an InputError naming the file and line (or element).
///
/// In 2D (plane strain) every direction must lie in the x–y plane.

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/solid/materials.hpp"

namespace coapt::solid {

/// How a body's fibre directions are given (see the file comment).
struct FibreFieldParameters {
  enum class Rule { constant, circumferential, file };
  Rule rule = Rule::constant;
  FibreDirections constant;         ///< rule constant: unit directions
  Vector3 axis = Vector3::UnitZ();  ///< rule circumferential: unit axis direction
  Vector3 point = Vector3::Zero();  ///< a point on the axis [m]
  double angle = 0;                 ///< tilt towards the axis [rad]
  std::string file;                 ///< rule file: path of the CSV file
  std::string where;                ///< location in the case file, for messages

  /// Reads `fibres:` of a body (or the short form fibre_direction / second_fibre_direction
  /// of the body section) for a material with `families` fibre families. InputError naming
  /// the key on bad input.
  static FibreFieldParameters read(const config::Section& body, int families);
  /// "constant (1, 0, 0)", "circumferential about (0, 0, 1) through (0, 0, 0), ±30°", ...
  std::string describe(int families) const;
};

/// The circumferential fibre directions at point X (rule circumferential): families 1 and 2.
/// Throws InputError (naming `where`) when X lies on the axis.
FibreDirections circumferential_fibres(const FibreFieldParameters& field, const Vector3& X,
                                       const std::string& where);

/// Fibre directions from CSV text (rule file): for each element number in `elements` (the
/// local cells of a body, the first `n_owned` of them owned), its directions, in that order.
/// `name` is the file name for messages. Collective on comm: every rank gets the same
/// InputError, including for a row that names no owned element on any rank.
std::vector<FibreDirections> fibres_from_csv(const std::string& text, const std::string& name,
                                             const std::vector<std::int64_t>& elements,
                                             std::size_t n_owned, int families, MPI_Comm comm);

}  // namespace coapt::solid
