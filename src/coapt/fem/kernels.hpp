#pragma once
/// @file kernels.hpp
/// P1 element kernels on simplices, header-only and in closed form (no quadrature: they are
/// the hot path of assembly), plus the quadrature-based load vector.
///
/// Two entry points per operator:
///  - from a P1Geometry (element_mass, element_laplacian, element_elasticity, ...);
///  - fast paths from Dim+1 raw vertex pointers writing a row-major (= column-major, the
///    matrices are symmetric) array ready for MatSetValues: element_laplacian<Dim>(p, K),
///    element_elasticity<Dim>(p, lambda, mu, K). They build no struct, divide once, and
///    return the signed measure WITHOUT checking it: a degenerate simplex (0 returned) gives
///    non-finite entries, so the caller checks `signed_measure != 0` (or its sign) itself.
/// Vector (elasticity) dofs are node-major: dof a*Dim + i is component i at vertex a.

#include <Eigen/Core>
#include <cmath>

#include "coapt/core/error.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fem/quadrature.hpp"

namespace coapt::fem {

namespace detail {

/// K_{(a,i),(b,j)} = |T| (λ ∂_iλ_a ∂_jλ_b + μ ∂_jλ_a ∂_iλ_b + μ δ_ij ∇λ_a·∇λ_b), into the
/// ((Dim+1)Dim)² array K (symmetric, so storage order does not matter).
template <int Dim>
inline void elasticity_from_gradients(const double (&g)[Dim + 1][Dim], double measure,
                                      double lambda, double mu, double* K) {
  constexpr int n = (Dim + 1) * Dim;
  double gl[Dim + 1][Dim], gm[Dim + 1][Dim];  // |T| λ ∇λ_a and |T| μ ∇λ_a
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i) {
      gl[a][i] = lambda * measure * g[a][i];
      gm[a][i] = mu * measure * g[a][i];
    }
  for (int a = 0; a <= Dim; ++a)
    for (int b = a; b <= Dim; ++b) {
      double dot = 0;
      for (int i = 0; i < Dim; ++i) dot += gm[a][i] * g[b][i];
      for (int i = 0; i < Dim; ++i)
        for (int j = 0; j < Dim; ++j) {
          const double value = gl[a][i] * g[b][j] + gm[a][j] * g[b][i] + (i == j ? dot : 0.0);
          K[(a * Dim + i) * n + b * Dim + j] = value;
          K[(b * Dim + j) * n + a * Dim + i] = value;
        }
    }
}

template <int Dim>
inline void gradients_of(const P1Geometry<Dim>& geometry, double (&g)[Dim + 1][Dim]) {
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i) g[a][i] = geometry.gradients(a, i);
}

}  // namespace detail

/// Consistent mass ∫_T λ_a λ_b = |T|(1+δ_ab)/((d+1)(d+2)).
template <int Dim>
inline Eigen::Matrix<double, Dim + 1, Dim + 1> element_mass(const P1Geometry<Dim>& geometry) {
  const double c = geometry.measure / ((Dim + 1) * (Dim + 2));
  Eigen::Matrix<double, Dim + 1, Dim + 1> M;
  M.setConstant(c);
  M.diagonal().array() += c;
  return M;
}

/// Lumped (row-sum) mass ∫_T λ_a = |T|/(d+1).
template <int Dim>
inline Eigen::Matrix<double, Dim + 1, 1> element_lumped_mass(const P1Geometry<Dim>& geometry) {
  return Eigen::Matrix<double, Dim + 1, 1>::Constant(geometry.measure / (Dim + 1));
}

/// Stiffness of the Laplacian ∫_T ∇λ_a·∇λ_b = |T| ∇λ_a·∇λ_b (exactly symmetric).
template <int Dim>
inline Eigen::Matrix<double, Dim + 1, Dim + 1> element_laplacian(const P1Geometry<Dim>& geometry) {
  Eigen::Matrix<double, Dim + 1, Dim + 1> K;
  for (int a = 0; a <= Dim; ++a)
    for (int b = a; b <= Dim; ++b) {
      double dot = 0;
      for (int i = 0; i < Dim; ++i) dot += geometry.gradients(a, i) * geometry.gradients(b, i);
      K(a, b) = K(b, a) = geometry.measure * dot;
    }
  return K;
}

/// Linear elasticity stiffness, dof order node-major (a*Dim + i), Lamé λ, μ [Pa]:
/// ∫_T λ div u div v + 2μ ε(u):ε(v).
template <int Dim>
inline Eigen::Matrix<double, (Dim + 1) * Dim, (Dim + 1) * Dim> element_elasticity(
    const P1Geometry<Dim>& geometry, double lambda, double mu) {
  double g[Dim + 1][Dim];
  detail::gradients_of<Dim>(geometry, g);
  Eigen::Matrix<double, (Dim + 1) * Dim, (Dim + 1) * Dim> K;
  detail::elasticity_from_gradients<Dim>(g, geometry.measure, lambda, mu, K.data());
  return K;
}

/// Fast path: the Laplacian stiffness from Dim+1 vertex pointers into K ((Dim+1)² doubles,
/// symmetric). Uses the Gram matrix of the adjugate rows, K_ab = c_a·c_b / (Dim! |det J|),
/// and the zero row sums for vertex 0. Returns det J / Dim! (unchecked; see the file comment).
template <int Dim>
inline double element_laplacian(const double* const* vertices, double* K) {
  constexpr int n = Dim + 1;
  double e[Dim][Dim], c[Dim][Dim];
  detail::edges_from_pointers<Dim>(vertices, e);
  const double det = detail::edge_cofactors<Dim>(e, c);
  const double scale = 1.0 / (detail::factorial(Dim) * std::abs(det));
  for (int k = 0; k < Dim; ++k)
    for (int l = k; l < Dim; ++l) {
      double dot = 0;
      for (int i = 0; i < Dim; ++i) dot += c[k][i] * c[l][i];
      K[(k + 1) * n + l + 1] = K[(l + 1) * n + k + 1] = scale * dot;
    }
  double corner = 0;
  for (int l = 1; l <= Dim; ++l) {
    double row = 0;
    for (int k = 1; k <= Dim; ++k) row += K[k * n + l];
    K[l] = K[l * n] = -row;
    corner += row;
  }
  K[0] = corner;
  return det / detail::factorial(Dim);
}

/// Fast path: the elasticity stiffness from Dim+1 vertex pointers into K (((Dim+1)Dim)²
/// doubles, symmetric, node-major dofs). Returns det J / Dim! (unchecked).
template <int Dim>
inline double element_elasticity(const double* const* vertices, double lambda, double mu,
                                 double* K) {
  double e[Dim][Dim], g[Dim + 1][Dim];
  detail::edges_from_pointers<Dim>(vertices, e);
  const double det = detail::gradients_from_edges<Dim>(e, g);
  const double signed_measure = det / detail::factorial(Dim);
  detail::elasticity_from_gradients<Dim>(g, std::abs(signed_measure), lambda, mu, K);
  return signed_measure;
}

/// Physical coordinates (n_points × Dim) of the points of `rule` in the simplex `vertices`,
/// where to evaluate the f given to element_load.
template <int Dim>
inline Eigen::Matrix<double, Eigen::Dynamic, Dim> quadrature_points(
    const Eigen::Matrix<double, Dim + 1, Dim>& vertices, const QuadratureRule& rule) {
  COAPT_ASSERT(rule.dim == Dim, "quadrature rule of the wrong dimension");
  Eigen::Matrix<double, Eigen::Dynamic, Dim> x(rule.size(), Dim);
  for (int q = 0; q < rule.size(); ++q) {
    const Eigen::Map<const Eigen::Matrix<double, Dim, 1>> xi(rule.point(q));
    x.row(q) = map_to_physical<Dim>(vertices, xi).transpose();
  }
  return x;
}

/// Load vector ∫_T f λ_a for f given at the rule's points (values n_points × n_components,
/// e.g. f evaluated at quadrature_points()) -> (Dim+1) × n_components.
template <int Dim>
inline Eigen::Matrix<double, Dim + 1, Eigen::Dynamic> element_load(
    const P1Geometry<Dim>& geometry, const QuadratureRule& rule,
    const Eigen::Ref<const Eigen::MatrixXd>& values) {
  COAPT_ASSERT(rule.dim == Dim, "quadrature rule of the wrong dimension");
  COAPT_ASSERT(values.rows() == rule.size(), "load values: one row per quadrature point needed");
  // Physical weights: reference weights × |det J| = Dim! |T|.
  const double scale = detail::factorial(Dim) * geometry.measure;
  Eigen::Matrix<double, Dim + 1, Eigen::Dynamic> load =
      Eigen::Matrix<double, Dim + 1, Eigen::Dynamic>::Zero(Dim + 1, values.cols());
  for (int q = 0; q < rule.size(); ++q) {
    const Eigen::Map<const Eigen::Matrix<double, Dim, 1>> xi(rule.point(q));
    load.noalias() += (scale * rule.weights[q]) * p1_values<Dim>(xi) * values.row(q);
  }
  return load;
}

}  // namespace coapt::fem
