#pragma once
/// @file quadrature.hpp
/// Quadrature rules on the reference simplex {x_i >= 0, sum x_i <= 1} of dimension 1, 2, 3.
///
/// Two families, every rule with positive weights and points strictly inside the simplex:
///  - tabulated fully symmetric rules (centroid; 3-point degree 2 and Strang-Fix/Dunavant
///    6-, 12-, 16-, 19-, 25-point degree 4, 6, 8, 9, 10 and Radon's 7-point degree 5 in 2D;
///    Gatermann's 12-point degree 7 in 2D (rotationally symmetric); 4-point degree 2,
///    the 14-point degree 5 and Keast's 24-point degree 6 in 3D). The tabulated coefficients
///    were polished to 20 digits by Newton's method on the moment equations in 50-digit
///    arithmetic and are re-verified by tests/unit/fem/test_quadrature.cpp;
///  - collapsed (Duffy / Stroud conical product) rules, built at run time from Gauss-Jacobi
///    points (Golub-Welsch eigenvalues, then Newton on the orthonormal Jacobi polynomials
///    and Christoffel weights), exact to any degree with (degree/2 + 1)^dim points.
/// simplex_quadrature() returns the cheapest of these for a degree.

#include <cstddef>
#include <vector>

namespace coapt::fem {

/// A quadrature rule on the reference simplex {x_i >= 0, sum x_i <= 1} of dimension dim (1, 2 or
/// 3).
struct QuadratureRule {
  int dim = 0;
  int degree = 0;               ///< exact for polynomials of total degree <= degree
  std::vector<double> points;   ///< n_points × dim reference coordinates
  std::vector<double> weights;  ///< n_points; sum = reference measure (1, 1/2, 1/6)
  int size() const { return static_cast<int>(weights.size()); }
  /// Reference coordinates of point q (dim entries).
  const double* point(int q) const { return points.data() + static_cast<std::size_t>(q) * dim; }
};

/// Largest degree simplex_quadrature() and collapsed_simplex_quadrature() accept.
inline constexpr int max_quadrature_degree = 100;

/// The cheapest rule this library has that is exact to `degree` on the reference `dim`-simplex
/// (cached; thread-safe after first use is not required). Degrees 0..10 at least, dims 1..3.
/// Throws InputError for dim outside 1..3 or degree outside 0..max_quadrature_degree.
/// The returned reference stays valid for the life of the program.
const QuadratureRule& simplex_quadrature(int dim, int degree);

/// The collapsed (Stroud conical product) rule exact to `degree`: m = degree/2 + 1 Gauss-Jacobi
/// points per direction, m^dim points in all; in 1D this is the m-point Gauss-Legendre rule.
QuadratureRule collapsed_simplex_quadrature(int dim, int degree);

/// The tabulated (symmetric) rules of dimension `dim`, lowest degree first (for tests and
/// for callers that want a symmetric rule). Empty for dim 1 (Gauss-Legendre is collapsed).
const std::vector<QuadratureRule>& tabulated_simplex_quadratures(int dim);

/// The n-point Gauss-Jacobi rule on [0, 1] for the weight (1 - u)^alpha, alpha > -1:
/// nodes ascending, weights summing to 1/(alpha + 1); exact for polynomials of degree 2n-1.
void gauss_jacobi(int n, double alpha, std::vector<double>& nodes, std::vector<double>& weights);

/// Measure of the reference simplex of dimension dim: 1/dim!.
double reference_simplex_measure(int dim);

}  // namespace coapt::fem
