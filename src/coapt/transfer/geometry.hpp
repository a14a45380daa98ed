#pragma once
/// @file geometry.hpp
/// Small fixed-size geometry for the transfer kernels: points, P1 simplices with their
/// barycentric map, moments of a region up to order two, and quadrature points.
///
/// Everything here is header-only, allocation-free and works on std::array so the
/// intersection kernels (intersection.hpp, clipping.hpp) stay self-contained.

#include <array>
#include <cmath>

namespace coapt::transfer {

/// A point or vector of R^dim [m].
template <int dim>
using Point = std::array<double, dim>;

/// One value per vertex of a dim-simplex (dim + 1 entries).
template <int dim>
using NodalVector = std::array<double, dim + 1>;

/// One value per pair of vertices of two dim-simplices, [i][j] (row i: first simplex).
template <int dim>
using NodalMatrix = std::array<std::array<double, dim + 1>, dim + 1>;

/// Moments of a region Ω up to order two.
template <int dim>
struct Moments {
  double measure = 0.0;                  ///< |Ω| [m^dim]
  Point<dim> centroid{};                 ///< x̄ = ∫_Ω x / |Ω| [m] (0 when |Ω| = 0)
  std::array<Point<dim>, dim> second{};  ///< ∫_Ω (x − x̄)(x − x̄)ᵀ [m^(dim+2)], symmetric
};

/// A quadrature point in physical coordinates and its weight [m^dim].
template <int dim>
struct QuadraturePoint {
  Point<dim> point{};
  double weight = 0.0;
};

/// A P1 simplex prepared once per element for the intersection kernels: its vertices, the
/// gradients of its barycentric coordinates, its measure and its bounding box.
///
/// λ_i(x) = ∇λ_i · (x − v_anchor(i)), with anchor(i) a vertex on the face opposite v_i
/// (v_1 for i = 0, v_0 otherwise): each λ_i is evaluated relative to a point of its own
/// zero plane, so a point on a face gives λ_i at round-off of the local size, not of the
/// coordinates' magnitude. Either vertex orientation is accepted.
template <int dim>
struct Simplex {
  std::array<Point<dim>, dim + 1> vertices{};   ///< [m]
  std::array<Point<dim>, dim + 1> gradients{};  ///< ∇λ_i [1/m]
  double measure = 0.0;    ///< |T| [m^dim]; 0 marks a degenerate simplex (intersects nothing)
  Point<dim> box_lower{};  ///< bounding box [m]
  Point<dim> box_upper{};

  static constexpr int anchor(int i) { return i == 0 ? 1 : 0; }
  /// λ_i(x), the i-th barycentric coordinate extended affinely to R^dim.
  double barycentric(int i, const Point<dim>& x) const {
    const Point<dim>& a = vertices[anchor(i)];
    double value = 0.0;
    for (int k = 0; k < dim; ++k) value += gradients[i][k] * (x[k] - a[k]);
    return value;
  }
  bool degenerate() const { return !(measure > 0.0); }
};

/// Relative flatness below which a simplex counts as degenerate: |det J| ≤ this · L^dim,
/// L the longest edge. Such an element has no volume at round-off level of its own size.
inline constexpr double kDegenerateSimplex = 1e-14;

/// Prepares a simplex (triangle for dim = 2, tetrahedron for dim = 3) from its vertices [m].
/// A flat or non-finite simplex gets measure 0 and zero gradients.
template <int dim>
Simplex<dim> make_simplex(const std::array<Point<dim>, dim + 1>& vertices) {
  static_assert(dim == 2 || dim == 3, "simplices of dimension 2 or 3");
  Simplex<dim> s;
  s.vertices = vertices;
  s.box_lower = vertices[0];
  s.box_upper = vertices[0];
  for (int v = 1; v <= dim; ++v)
    for (int k = 0; k < dim; ++k) {
      s.box_lower[k] = std::fmin(s.box_lower[k], vertices[v][k]);
      s.box_upper[k] = std::fmax(s.box_upper[k], vertices[v][k]);
    }
  std::array<Point<dim>, dim> e;  // edges from v_0
  double longest = 0.0;
  for (int v = 0; v <= dim; ++v)
    for (int w = v + 1; w <= dim; ++w) {
      double length2 = 0.0;
      for (int k = 0; k < dim; ++k) {
        const double d = vertices[w][k] - vertices[v][k];
        length2 += d * d;
      }
      longest = std::fmax(longest, length2);
    }
  longest = std::sqrt(longest);
  for (int v = 0; v < dim; ++v)
    for (int k = 0; k < dim; ++k) e[v][k] = vertices[v + 1][k] - vertices[0][k];
  // Rows of J⁻¹ (J = [e_1 .. e_dim]) are ∇λ_1..∇λ_dim: cofactors over det J.
  std::array<Point<dim>, dim> cofactor;
  double det;
  if constexpr (dim == 2) {
    cofactor[0] = {e[1][1], -e[1][0]};
    cofactor[1] = {-e[0][1], e[0][0]};
    det = e[0][0] * e[1][1] - e[0][1] * e[1][0];
  } else {
    const auto cross = [](const Point<3>& a, const Point<3>& b) {
      return Point<3>{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                      a[0] * b[1] - a[1] * b[0]};
    };
    cofactor[0] = cross(e[1], e[2]);
    cofactor[1] = cross(e[2], e[0]);
    cofactor[2] = cross(e[0], e[1]);
    det = e[0][0] * cofactor[0][0] + e[0][1] * cofactor[0][1] + e[0][2] * cofactor[0][2];
  }
  const double scale = std::pow(longest, dim);
  if (!(std::fabs(det) > kDegenerateSimplex * scale) || !std::isfinite(det) ||
      !std::isfinite(scale))
    return s;  // measure 0, gradients 0
  s.measure = std::fabs(det) / (dim == 2 ? 2.0 : 6.0);
  s.gradients[0] = {};
  for (int v = 0; v < dim; ++v)
    for (int k = 0; k < dim; ++k) {
      s.gradients[v + 1][k] = cofactor[v][k] / det;
      s.gradients[0][k] -= s.gradients[v + 1][k];
    }
  return s;
}

/// Moments of a simplex: |T|, its vertex centroid, and
/// ∫_T (x − x̄)(x − x̄)ᵀ = |T| / ((d+1)(d+2)) Σ_k (v_k − x̄)(v_k − x̄)ᵀ
/// (from ∫_T λ_k λ_l = |T| (1 + δ_kl) / ((d+1)(d+2))).
template <int dim>
Moments<dim> simplex_moments(const Simplex<dim>& s) {
  Moments<dim> m;
  m.measure = s.measure;
  for (const auto& v : s.vertices)
    for (int k = 0; k < dim; ++k) m.centroid[k] += v[k] / (dim + 1);
  const double factor = s.measure / ((dim + 1) * (dim + 2));
  for (const auto& v : s.vertices) {
    Point<dim> q;
    for (int k = 0; k < dim; ++k) q[k] = v[k] - m.centroid[k];
    for (int r = 0; r < dim; ++r)
      for (int c = 0; c < dim; ++c) m.second[r][c] += factor * q[r] * q[c];
  }
  return m;
}

/// Degree-2 rules with positive weights and interior points (Hammer, Marlowe & Stroud 1956):
/// triangle: barycentric (2/3, 1/6, 1/6) and permutations, weights |T|/3;
/// tetrahedron: (α, β, β, β) and permutations, α = (5 + 3√5)/20, β = (5 − √5)/20, weights |T|/4.
namespace detail {
inline constexpr double kTriangleRuleOwn = 2.0 / 3.0;
inline constexpr double kTriangleRuleOther = 1.0 / 6.0;
inline constexpr double kTetrahedronRuleOwn = 0.58541019662496845446;
inline constexpr double kTetrahedronRuleOther = 0.13819660112501051518;
}  // namespace detail

/// Writes the degree-2 rule of simplex `s` (dim + 1 points) to `points`; returns dim + 1.
template <int dim>
int simplex_quadrature(const Simplex<dim>& s, QuadraturePoint<dim>* points) {
  constexpr double own = dim == 2 ? detail::kTriangleRuleOwn : detail::kTetrahedronRuleOwn;
  constexpr double other = dim == 2 ? detail::kTriangleRuleOther : detail::kTetrahedronRuleOther;
  Point<dim> sum{};
  for (const auto& v : s.vertices)
    for (int k = 0; k < dim; ++k) sum[k] += v[k];
  for (int v = 0; v <= dim; ++v) {
    for (int k = 0; k < dim; ++k)
      points[v].point[k] = other * sum[k] + (own - other) * s.vertices[v][k];
    points[v].weight = s.measure / (dim + 1);
  }
  return dim + 1;
}

/// ∫_Ω λ^P_i λ^Q_j from the moments of Ω, for affine λ^P, λ^Q (exact in exact arithmetic):
/// ∫_Ω λ^P_i λ^Q_j = |Ω| λ^P_i(x̄) λ^Q_j(x̄) + ∇λ^P_iᵀ [∫_Ω (x − x̄)(x − x̄)ᵀ] ∇λ^Q_j.
/// Round-off grows like ε (ℓ/h_P)(ℓ/h_Q), ℓ the size of Ω and h the heights of P and Q:
/// fine for shape-regular elements (e.g. ∫_{A∩B} λ^A_i λ^A_j for a consistent mass on cut
/// cells), not for slivers; local_integrals() does not use it.
template <int dim>
NodalMatrix<dim> mass_matrix(const Moments<dim>& moments, const Simplex<dim>& p,
                             const Simplex<dim>& q) {
  NodalVector<dim> p_at_centroid, q_at_centroid;
  std::array<Point<dim>, dim + 1> second_q;  // [∫(x − x̄)(x − x̄)ᵀ] ∇λ^Q_j
  for (int i = 0; i <= dim; ++i) {
    p_at_centroid[i] = p.barycentric(i, moments.centroid);
    q_at_centroid[i] = q.barycentric(i, moments.centroid);
    for (int r = 0; r < dim; ++r) {
      double value = 0.0;
      for (int c = 0; c < dim; ++c) value += moments.second[r][c] * q.gradients[i][c];
      second_q[i][r] = value;
    }
  }
  NodalMatrix<dim> mass;
  for (int i = 0; i <= dim; ++i)
    for (int j = 0; j <= dim; ++j) {
      double value = moments.measure * p_at_centroid[i] * q_at_centroid[j];
      for (int r = 0; r < dim; ++r) value += p.gradients[i][r] * second_q[j][r];
      mass[i][j] = value;
    }
  return mass;
}

/// ∫_Ω λ^P_i = |Ω| λ^P_i(x̄) from the moments of Ω.
template <int dim>
NodalVector<dim> basis_integrals(const Moments<dim>& moments, const Simplex<dim>& p) {
  NodalVector<dim> integrals;
  for (int i = 0; i <= dim; ++i)
    integrals[i] = moments.measure * p.barycentric(i, moments.centroid);
  return integrals;
}

}  // namespace coapt::transfer
