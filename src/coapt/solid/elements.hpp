#pragma once
/// @file elements.hpp
/// Total-Lagrangian P1 element kernels for the solid, header-only, in 2D (plane strain) and
/// 3D. On a P1 simplex the basis gradients ∇_X N_a are constant, so F is constant per cell
/// and one point integrates the internal force and its tangent exactly:
///
///   F = I + Σ_a u_a ⊗ ∇_X N_a                               (F_iJ = δ_iJ + Σ_a u_ai N_a,J)
///   r_ai  = |T| P_iJ(F) N_a,J                                (internal force, [N] or [N/m])
///   K_aibk = |T| N_a,J A_iJkL(F) N_b,L                       (∂r_ai/∂u_bk)
///
/// with |T| the reference measure, P the first Piola–Kirchhoff stress and A = ∂P/∂F of the
/// material (materials.hpp; the plane_strain wrapper in 2D). Element vectors and matrices
/// are node-major: dof a·Dim + i (vertex a, component i), as fem::P1Matrix expects.
/// Pure functions, no MPI, no allocation.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "coapt/fem/p1.hpp"
#include "coapt/solid/materials.hpp"

namespace coapt::solid {

/// Dim×Dim matrix.
template <int Dim>
using MatrixD = Eigen::Matrix<double, Dim, Dim>;
/// Nodal values of one P1 cell: row a = vertex a's Dim components.
template <int Dim>
using NodalValues = Eigen::Matrix<double, Dim + 1, Dim>;
/// Element vector (node-major, (Dim+1)·Dim entries).
template <int Dim>
using ElementVector = Eigen::Matrix<double, (Dim + 1) * Dim, 1>;
/// Element matrix (node-major, row-major storage as fem::P1Matrix expects).
template <int Dim>
using ElementMatrix = Eigen::Matrix<double, (Dim + 1) * Dim, (Dim + 1) * Dim, Eigen::RowMajor>;
/// ∂P/∂F in Dim dimensions, A(Dim·i + J, Dim·k + L).
template <int Dim>
using TangentD = Eigen::Matrix<double, Dim * Dim, Dim * Dim>;

/// F = I + Σ_a u_a ⊗ ∇N_a from the basis gradients (row a = ∇_X N_a) and nodal displacements.
template <int Dim>
inline MatrixD<Dim> deformation_gradient(const NodalValues<Dim>& gradients,
                                         const NodalValues<Dim>& displacement) {
  return MatrixD<Dim>::Identity() + displacement.transpose() * gradients;
}

/// P(F) [Pa] of the material: the 3D law, or its plane-strain part in 2D.
template <int Dim>
inline MatrixD<Dim> piola_stress(const Material& material, const MatrixD<Dim>& F,
                                 const FibreDirections& fibres) {
  if constexpr (Dim == 2)
    return plane_strain::first_piola(material, F, fibres);
  else
    return first_piola(material, F, fibres);
}

/// A(F) = ∂P/∂F [Pa] of the material (plane-strain part in 2D).
template <int Dim>
inline TangentD<Dim> piola_tangent(const Material& material, const MatrixD<Dim>& F,
                                   const FibreDirections& fibres) {
  if constexpr (Dim == 2)
    return plane_strain::tangent(material, F, fibres);
  else
    return tangent(material, F, fibres);
}

/// Cauchy stress σ [Pa], 3×3 (with σ₃₃ in plane strain).
template <int Dim>
inline Matrix3 cauchy_stress(const Material& material, const MatrixD<Dim>& F,
                             const FibreDirections& fibres) {
  if constexpr (Dim == 2)
    return plane_strain::cauchy(material, F, fibres);
  else
    return cauchy(material, F, fibres);
}

/// det F of a Dim×Dim deformation gradient (plane strain: F₃₃ = 1).
template <int Dim>
inline double volume_ratio_of(const MatrixD<Dim>& F) {
  return F.determinant();
}

/// Internal force r_ai = |T| P_iJ N_a,J of one cell [N (3D), N/m (2D)].
/// `geometry` is the reference cell's P1 geometry.
template <int Dim>
inline ElementVector<Dim> element_residual(const fem::P1Geometry<Dim>& geometry,
                                           const Material& material, const FibreDirections& fibres,
                                           const NodalValues<Dim>& displacement) {
  const MatrixD<Dim> F = deformation_gradient<Dim>(geometry.gradients, displacement);
  const MatrixD<Dim> P = piola_stress<Dim>(material, F, fibres);
  // Row a of (∇N) Pᵀ is Σ_J P_iJ N_a,J over i.
  const NodalValues<Dim> forces = geometry.measure * geometry.gradients * P.transpose();
  ElementVector<Dim> r;
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i) r(a * Dim + i) = forces(a, i);
  return r;
}

/// Tangent K_aibk = |T| N_a,J A_iJkL N_b,L of one cell [N/m (3D), N/m² (2D)]: the exact
/// derivative of element_residual with respect to the nodal displacements.
template <int Dim>
inline ElementMatrix<Dim> element_tangent(const fem::P1Geometry<Dim>& geometry,
                                          const Material& material, const FibreDirections& fibres,
                                          const NodalValues<Dim>& displacement) {
  const MatrixD<Dim> F = deformation_gradient<Dim>(geometry.gradients, displacement);
  const TangentD<Dim> A = piola_tangent<Dim>(material, F, fibres);
  const auto& g = geometry.gradients;
  ElementMatrix<Dim> K;
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i)
      for (int b = 0; b <= Dim; ++b)
        for (int k = 0; k < Dim; ++k) {
          double sum = 0.0;
          for (int J = 0; J < Dim; ++J)
            for (int L = 0; L < Dim; ++L) sum += g(a, J) * A(Dim * i + J, Dim * k + L) * g(b, L);
          K(a * Dim + i, b * Dim + k) = geometry.measure * sum;
        }
  return K;
}

/// Consistent load of a uniform force density f over a cell or a facet of measure
/// `measure`: ∫ f N_a = f |T| / (number of vertices) per vertex (P1: ∫ N_a = |T|/n_vertices).
template <int Dim>
inline Eigen::Matrix<double, Dim, 1> uniform_nodal_load(const Eigen::Matrix<double, Dim, 1>& f,
                                                        double measure, int n_vertices) {
  return f * (measure / n_vertices);
}

/// Current positions of the vertices of one boundary facet: row a = x_a (Dim vertices).
template <int Dim>
using FacetPositions = Eigen::Matrix<double, Dim, Dim>;
/// Element vector of a facet (facet-vertex-major, Dim·Dim entries).
template <int Dim>
using FacetVector = Eigen::Matrix<double, Dim * Dim, 1>;
/// Element matrix of a facet (facet-vertex-major, row-major).
template <int Dim>
using FacetMatrix = Eigen::Matrix<double, Dim * Dim, Dim * Dim, Eigen::RowMajor>;

/// Follower pressure p [Pa] on a boundary facet in its current position: the load −p n da,
/// so the residual (internal minus external forces) gets
///
///   r_a = p ∫ n N_a da = p N / Dim  per facet vertex a,
///
/// with N the area-weighted outward normal of the current facet (the facet's vertices are
/// ordered with the normal out of its cell, Mesh::facets): in 3D N = ½ (x₁ − x₀) × (x₂ − x₀)
/// (so r_a = p/6 (x₁ − x₀) × (x₂ − x₀)); in 2D (per unit thickness, the cell on the left of
/// x₀ → x₁) N = Q (x₁ − x₀) with Q = [[0, 1], [−1, 0]].
template <int Dim>
inline FacetVector<Dim> pressure_facet_residual(const FacetPositions<Dim>& x, double pressure) {
  Eigen::Matrix<double, Dim, 1> normal;  // p N / Dim, the force on each vertex
  if constexpr (Dim == 2) {
    const Eigen::Vector2d e = (x.row(1) - x.row(0)).transpose();
    normal << e(1), -e(0);
    normal *= 0.5 * pressure;  // p N / 2
  } else {
    const Eigen::Vector3d e1 = (x.row(1) - x.row(0)).transpose();
    const Eigen::Vector3d e2 = (x.row(2) - x.row(0)).transpose();
    normal = e1.cross(e2) * (pressure / 6.0);  // p (½ e₁ × e₂) / 3
  }
  FacetVector<Dim> r;
  for (int a = 0; a < Dim; ++a) r.template segment<Dim>(a * Dim) = normal;
  return r;
}

/// Its exact derivative ∂r_ai/∂x_bk (= ∂r_ai/∂u_bk): in 3D, with [v]× w = v × w,
/// ∂N/∂x₀ = ½([e₂]× − [e₁]×), ∂N/∂x₁ = −½[e₂]×, ∂N/∂x₂ = ½[e₁]×, e₁ = x₁ − x₀, e₂ = x₂ − x₀;
/// in 2D ∂N/∂x₀ = −Q, ∂N/∂x₁ = Q. Not symmetric: a follower load is not conservative facet
/// by facet.
template <int Dim>
inline FacetMatrix<Dim> pressure_facet_tangent(const FacetPositions<Dim>& x, double pressure) {
  FacetMatrix<Dim> K;
  std::array<Eigen::Matrix<double, Dim, Dim>, Dim> derivative;  // ∂(r_a)/∂x_b, same for all a
  if constexpr (Dim == 2) {
    Eigen::Matrix2d Q;
    Q << 0.0, 1.0, -1.0, 0.0;
    derivative[0] = -0.5 * pressure * Q;
    derivative[1] = 0.5 * pressure * Q;
  } else {
    const auto cross_matrix = [](const Eigen::Vector3d& v) {
      Eigen::Matrix3d m;
      m << 0.0, -v(2), v(1), v(2), 0.0, -v(0), -v(1), v(0), 0.0;
      return m;
    };
    const Eigen::Matrix3d E1 = cross_matrix((x.row(1) - x.row(0)).transpose());
    const Eigen::Matrix3d E2 = cross_matrix((x.row(2) - x.row(0)).transpose());
    const double scale = pressure / 6.0;
    derivative[0] = scale * (E2 - E1);
    derivative[1] = -scale * E2;
    derivative[2] = scale * E1;
  }
  for (int a = 0; a < Dim; ++a)
    for (int b = 0; b < Dim; ++b) K.template block<Dim, Dim>(a * Dim, b * Dim) = derivative[b];
  return K;
}

}  // namespace coapt::solid
