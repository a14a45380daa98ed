#pragma once
/// @file p1.hpp
/// P1 (linear) Lagrange elements on simplices, header-only: the affine geometry of a
/// segment, triangle or tetrahedron (Jacobian, constant basis gradients, measure), the
/// barycentric basis λ_a, its dual (biorthogonal) basis ψ_a, and the reference-to-physical map.
///
/// Conventions: a simplex has Dim+1 vertices x_0..x_Dim (rows of a (Dim+1)×Dim matrix, or
/// Dim+1 pointers to Dim coordinates); the reference simplex is {xi_i >= 0, sum xi_i <= 1}
/// with x(xi) = x_0 + J xi, J = [x_1 - x_0, ..., x_Dim - x_0] (columns);
/// λ_0 = 1 - sum xi, λ_a = xi_{a-1}. Inverses use the closed-form adjugate (no pivoting).

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <string>

#include "coapt/core/error.hpp"

namespace coapt::fem {

template <int Dim>
struct P1Geometry {
  static_assert(Dim >= 1 && Dim <= 3, "P1 simplices of dimension 1, 2, 3");
  Eigen::Matrix<double, Dim, Dim> jacobian;       ///< J = [x1-x0, x2-x0, ...] (columns)
  Eigen::Matrix<double, Dim + 1, Dim> gradients;  ///< row a = ∇λ_a (constant)
  double measure = 0;                             ///< |T| > 0 (absolute)
  double signed_measure = 0;                      ///< det J / Dim!
};

namespace detail {

/// Dim! as a double.
constexpr double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}

/// Given the edges e[k] = x_{k+1} - x_0 (the columns of J), writes the cofactor rows
/// c[k] = det(J) ∇λ_{k+1} (the rows of adj J) and returns det J. No division, no pivoting.
template <int Dim>
inline double edge_cofactors(const double (&e)[Dim][Dim], double (&c)[Dim][Dim]) {
  if constexpr (Dim == 1) {
    c[0][0] = 1.0;
    return e[0][0];
  } else if constexpr (Dim == 2) {
    c[0][0] = e[1][1];
    c[0][1] = -e[1][0];
    c[1][0] = -e[0][1];
    c[1][1] = e[0][0];
    return e[0][0] * e[1][1] - e[0][1] * e[1][0];
  } else {
    // Row k of J^{-1} is orthogonal to the other two edges: cross products.
    c[0][0] = e[1][1] * e[2][2] - e[1][2] * e[2][1];
    c[0][1] = e[1][2] * e[2][0] - e[1][0] * e[2][2];
    c[0][2] = e[1][0] * e[2][1] - e[1][1] * e[2][0];
    c[1][0] = e[2][1] * e[0][2] - e[2][2] * e[0][1];
    c[1][1] = e[2][2] * e[0][0] - e[2][0] * e[0][2];
    c[1][2] = e[2][0] * e[0][1] - e[2][1] * e[0][0];
    c[2][0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
    c[2][1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
    c[2][2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    return e[0][0] * c[0][0] + e[0][1] * c[0][1] + e[0][2] * c[0][2];
  }
}

/// Edges e[k] = x_{k+1} - x_0 from vertex pointers.
template <int Dim>
inline void edges_from_pointers(const double* const* vertices, double (&e)[Dim][Dim]) {
  for (int k = 0; k < Dim; ++k)
    for (int i = 0; i < Dim; ++i) e[k][i] = vertices[k + 1][i] - vertices[0][i];
}

/// Gradients g[a] = ∇λ_a of all Dim+1 barycentric functions; returns det J (not checked).
template <int Dim>
inline double gradients_from_edges(const double (&e)[Dim][Dim], double (&g)[Dim + 1][Dim]) {
  double c[Dim][Dim];
  const double det = edge_cofactors<Dim>(e, c);
  const double inverse = 1.0 / det;
  for (int i = 0; i < Dim; ++i) g[0][i] = 0.0;
  for (int k = 0; k < Dim; ++k)
    for (int i = 0; i < Dim; ++i) {
      g[k + 1][i] = c[k][i] * inverse;
      g[0][i] -= g[k + 1][i];
    }
  return det;
}

/// Throws the InputError for a degenerate simplex, listing its edge vectors.
[[noreturn]] [[gnu::cold]] [[gnu::noinline]] inline void throw_degenerate_simplex(
    int dim, const double (&e)[3][3], double det) {
  static const char* const names[4] = {"", "segment", "triangle", "tetrahedron"};
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", det);
  std::string message =
      std::string("degenerate P1 ") + names[dim] + " (det J = " + buffer + "), edges x_k - x_0:";
  for (int k = 0; k < dim; ++k) {
    message += " (";
    for (int i = 0; i < dim; ++i) {
      std::snprintf(buffer, sizeof buffer, "%s%.17g", i == 0 ? "" : ", ", e[k][i]);
      message += buffer;
    }
    message += ")";
  }
  throw InputError(message);
}

template <int Dim>
inline P1Geometry<Dim> geometry_from_edges(const double (&e)[Dim][Dim]) {
  P1Geometry<Dim> geometry;
  double g[Dim + 1][Dim];
  const double det = gradients_from_edges<Dim>(e, g);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) [[unlikely]] {
    double e3[3][3] = {};
    for (int k = 0; k < Dim; ++k)
      for (int i = 0; i < Dim; ++i) e3[k][i] = e[k][i];
    throw_degenerate_simplex(Dim, e3, det);
  }
  for (int k = 0; k < Dim; ++k)
    for (int i = 0; i < Dim; ++i) geometry.jacobian(i, k) = e[k][i];
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i) geometry.gradients(a, i) = g[a][i];
  geometry.signed_measure = det / factorial(Dim);
  geometry.measure = std::abs(geometry.signed_measure);
  return geometry;
}

}  // namespace detail

/// Geometry of a simplex from its Dim+1 vertices given as rows of `vertices`.
/// Throws InputError if the simplex is degenerate (det J == 0) or not finite.
template <int Dim>
inline P1Geometry<Dim> p1_geometry(const Eigen::Matrix<double, Dim + 1, Dim>& vertices) {
  double e[Dim][Dim];
  for (int k = 0; k < Dim; ++k)
    for (int i = 0; i < Dim; ++i) e[k][i] = vertices(k + 1, i) - vertices(0, i);
  return detail::geometry_from_edges<Dim>(e);
}

/// Same from Dim+1 pointers to the vertices' Dim coordinates (e.g. into Mesh::coordinates):
/// call as p1_geometry<3>(p) with const double* p[4].
template <int Dim>
inline P1Geometry<Dim> p1_geometry(const double* const* vertices) {
  double e[Dim][Dim];
  detail::edges_from_pointers<Dim>(vertices, e);
  return detail::geometry_from_edges<Dim>(e);
}

/// Signed measure det J / Dim! from vertex pointers (no check).
template <int Dim>
inline double p1_signed_measure(const double* const* vertices) {
  double e[Dim][Dim], c[Dim][Dim];
  detail::edges_from_pointers<Dim>(vertices, e);
  return detail::edge_cofactors<Dim>(e, c) / detail::factorial(Dim);
}

/// Barycentric coordinates λ (Dim+1) at reference point xi (Dim): λ_0 = 1 - sum xi, λ_a = xi_{a-1}.
template <int Dim>
inline Eigen::Matrix<double, Dim + 1, 1> p1_values(const Eigen::Matrix<double, Dim, 1>& xi) {
  Eigen::Matrix<double, Dim + 1, 1> lambda;
  lambda(0) = 1.0 - xi.sum();
  lambda.template tail<Dim>() = xi;
  return lambda;
}

/// Dual (biorthogonal) basis ψ_a = (Dim+2)λ_a − 1 at xi: ∫_T ψ_a λ_b = δ_ab ∫_T λ_b.
template <int Dim>
inline Eigen::Matrix<double, Dim + 1, 1> p1_dual_values(const Eigen::Matrix<double, Dim, 1>& xi) {
  return ((Dim + 2.0) * p1_values<Dim>(xi).array() - 1.0).matrix();
}

/// Physical point of reference point xi.
template <int Dim>
inline Eigen::Matrix<double, Dim, 1> map_to_physical(
    const Eigen::Matrix<double, Dim + 1, Dim>& vertices, const Eigen::Matrix<double, Dim, 1>& xi) {
  return (p1_values<Dim>(xi).transpose() * vertices).transpose();
}

}  // namespace coapt::fem
