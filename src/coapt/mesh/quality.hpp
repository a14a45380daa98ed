#pragma once
/// @file quality.hpp
/// Element quality checks: orientation, degeneracy and shape of the cells of a mesh.
///
/// Typical use after reading or generating a mesh:
///     orient_cells(mesh);                      // fixes a consistently flipped mesh
///     const auto report = check_quality(mesh);
///     require_valid(mesh, report);             // InputError on inverted/degenerate cells
///
/// All functions look at the local cells of the calling rank (the whole mesh before
/// distribution) and are not collective.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "coapt/mesh/mesh.hpp"

namespace coapt::mesh {

/// A cell the quality check flags.
struct CellIssue {
  int cell = -1;                     ///< local cell index
  std::int64_t original = 0;         ///< its number in the source (Mesh::original_cell)
  std::array<double, 3> centroid{};  ///< z = 0 in 2D
  double measure = 0;                ///< signed area / volume
};

/// Summary of the cells' measures and shapes.
///
/// The shape measure is the mean-ratio quality, normalised to 1 for the regular (equilateral)
/// simplex and 0 for a flat one, computed from the absolute measure:
///     2D: q = 4 √3 |A| / Σ l_i²         (3 edges)
///     3D: q = 12 (3 |V|)^(2/3) / Σ l_i²  (6 edges)
/// It is small for every badly shaped simplex, slivers included (unlike the edge ratio).
///
/// A cell is degenerate if |measure| < kDegenerateFraction × (mean |measure| of the mesh);
/// it is inverted if it is not degenerate and its signed measure is negative.
struct QualityReport {
  std::string source;
  int dim = 0;
  std::int64_t n_cells = 0;
  double min_measure = 0;           ///< smallest signed measure (negative if some cell is inverted)
  double max_measure = 0;           ///< largest signed measure
  double total_measure = 0;         ///< sum of |measure|
  double min_shape = 0;             ///< smallest mean-ratio quality (1 = regular simplex)
  double max_shape = 0;             ///< largest mean-ratio quality
  std::vector<CellIssue> inverted;  ///< every inverted cell, in cell order
  std::vector<CellIssue> degenerate;  ///< every degenerate cell, in cell order

  bool valid() const { return inverted.empty() && degenerate.empty(); }
};

/// Relative threshold below which a cell's |measure| counts as degenerate.
inline constexpr double kDegenerateFraction = 1e-12;

/// Mean-ratio shape quality of a simplex from `dim + 1` points (see QualityReport).
double shape_quality(int dim, const double* const* points);
/// Mean-ratio shape quality of local cell c.
double cell_shape_quality(const Mesh& mesh, int c);

/// Measures every local cell of the mesh.
QualityReport check_quality(const Mesh& mesh);

/// If every non-degenerate cell has a negative signed measure (a consistently flipped mesh,
/// e.g. a 2D surface meshed with normal −z), swaps the last two vertices of every cell so
/// that all become positive, and returns true. Otherwise changes nothing and returns false:
/// a mesh with some (not all) negative cells keeps them, and check_quality reports them as
/// inverted. Facets are not touched (their orientation is geometric, see topology.hpp).
bool orient_cells(Mesh& mesh);

/// Throws InputError if the report lists inverted or degenerate cells:
/// "<source>: inverted element 17 at (x, y, z), element 23 at (...), ... (N inverted
/// elements in total)", naming the cells by their original numbers (first few only).
void require_valid(const Mesh& mesh, const QualityReport& report);

}  // namespace coapt::mesh
