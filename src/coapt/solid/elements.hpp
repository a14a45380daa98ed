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

}  // namespace coapt::solid
