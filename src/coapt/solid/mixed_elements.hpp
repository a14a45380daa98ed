#pragma once
/// @file mixed_elements.hpp
/// The mixed displacement–pressure P1–P1 element for nearly incompressible solids (the
/// case key `formulation: mixed`), header-only, 2D (plane strain) and 3D.
///
/// Why this remedy. On P1 simplices the displacement formulation locks: a mesh has about as
/// many cells (each with its own J) as displacement dofs, so J ≈ 1 everywhere leaves almost no
/// admissible motion. Of the usual remedies, F-bar patches and nodal-averaged J/pressure
/// (average nodal pressure) have a consistent tangent that couples every vertex to the
/// vertices of all cells around its neighbours (a two-ring stencil), which the vertex-neighbour
/// CSR pattern of fem::P1Matrix does not hold; an inexact tangent would lose Newton's quadratic
/// convergence. A P1 pressure per vertex keeps the one-ring pattern (fem::P1Matrix with Dim + 1
/// components per vertex), gives an exact symmetric tangent and stays on the same mesh. Equal
/// order P1–P1 violates the inf-sup condition, so the pressure equation gets the
/// Brezzi–Pitkäranta term −τ ∫ ∇p·∇q with τ = α h²/(2μ) (h: the cell's longest edge,
/// α = 0.2, μ: the shear modulus), which is consistent to O(h) in the pressure.
///
/// Stationary points of (reference configuration, per cell)
///
///   Π(u, p) = ∫ ψ_iso(F) + p (J − 1) − p²/(2κ) − τ/2 |∇p|² dX,
///
/// where ψ_iso = ψ − κ U(J) is the law without its volumetric part U (materials.hpp;
/// nearly_incompressible_neo_hookean and fibre_reinforced). Eliminating p gives the
/// volumetric energy κ/2 (J − 1)², which agrees with κ U(J) to second order in J − 1 (and both
/// give the same incompressible limit). Residuals per vertex a (dofs a·(Dim+1) + i for
/// displacement component i, a·(Dim+1) + Dim for p), with p̄ the mean nodal pressure of the cell
/// (the coupling term is linear in p and constant otherwise, so p̄ integrates it exactly):
///
///   r_ai = |T| (P_iso + p̄ J F⁻ᵀ)_iJ N_a,J
///   r_a  = |T| (J − 1)/(Dim+1) − Σ_b M_ab p_b/κ − τ |T| ∇N_a·∇p
///
/// and the tangent (symmetric):
///   K_ai,bk = |T| N_a,J (A_iso + p̄ J (F⁻ᵀ ⊗ F⁻ᵀ − F⁻ᵀ_iL F⁻ᵀ_kJ))_iJkL N_b,L
///   K_ai,b  = K_b,ai = |T|/(Dim+1) (J F⁻ᵀ ∇N_a)_i
///   K_a,b   = −M_ab/κ − τ |T| ∇N_a·∇N_b.
/// In plane strain every 3D quantity is taken at diag(F, 1) and restricted to the plane.

#include <Eigen/Core>
#include <Eigen/LU>

#include "coapt/fem/kernels.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/solid/elements.hpp"

namespace coapt::solid {

/// Stabilisation factor α of τ = α h²/(2μ).
inline constexpr double kPressureStabilisation = 0.2;

/// Nodal values of one cell in the mixed layout: row a = (u_a, p_a).
template <int Dim>
using MixedNodalValues = Eigen::Matrix<double, Dim + 1, Dim + 1>;
template <int Dim>
using MixedElementVector = Eigen::Matrix<double, (Dim + 1) * (Dim + 1), 1>;
template <int Dim>
using MixedElementMatrix =
    Eigen::Matrix<double, (Dim + 1) * (Dim + 1), (Dim + 1) * (Dim + 1), Eigen::RowMajor>;

/// The volumetric part split off for the mixed form: κ and the shear modulus μ of the laws
/// that have a volumetric energy κ U(J); false for the others.
inline bool volumetric_split(const Material& material, double& bulk, double& shear) {
  if (const auto* law = std::get_if<NearlyIncompressibleNeoHookean>(&material)) {
    bulk = law->bulk_modulus;
    shear = law->shear_modulus;
    return true;
  }
  if (const auto* law = std::get_if<FibreReinforced>(&material)) {
    bulk = law->bulk_modulus;
    shear = law->shear_modulus;
    return true;
  }
  return false;
}

/// P_vol = κ U'(J) J F⁻ᵀ = κ (J² − 1)/2 F⁻ᵀ and its tangent
/// A_vol = κ J² F⁻ᵀ ⊗ F⁻ᵀ − κ (J² − 1)/2 F⁻ᵀ_iL F⁻ᵀ_kJ (U of materials.hpp).
inline void volumetric_part(double bulk, const Matrix3& F, Matrix3& P, Tangent3& A) {
  const double J = F.determinant();
  const Matrix3 Finv_T = F.inverse().transpose();
  const double pressure_factor = 0.5 * bulk * (J * J - 1.0);
  P = pressure_factor * Finv_T;
  A.setZero();
  add_dyadic(A, bulk * J * J, Finv_T, Finv_T);
  add_crossed_dyadic(A, -pressure_factor, Finv_T, Finv_T);
}

/// Longest edge of a cell [m].
template <int Dim>
inline double longest_edge(const NodalValues<Dim>& points) {
  double h = 0;
  for (int a = 0; a <= Dim; ++a)
    for (int b = a + 1; b <= Dim; ++b) h = std::max(h, (points.row(a) - points.row(b)).norm());
  return h;
}

/// Residual and (if `K` is not null) tangent of one cell in the mixed layout. `h` is the
/// cell's longest edge. Returns J (the caller rejects J ≤ 0).
template <int Dim>
inline double mixed_element(const fem::P1Geometry<Dim>& geometry, double h,
                            const Material& material, const FibreDirections& fibres,
                            const MixedNodalValues<Dim>& values, MixedElementVector<Dim>& r,
                            MixedElementMatrix<Dim>* K) {
  constexpr int m = Dim + 1;  // dofs per vertex
  double bulk = 0, shear = 0;
  volumetric_split(material, bulk, shear);
  const NodalValues<Dim> displacement = values.template leftCols<Dim>();
  const Eigen::Matrix<double, Dim + 1, 1> p = values.col(Dim);
  const double p_mean = p.mean();
  const auto& g = geometry.gradients;
  const double V = geometry.measure;
  const MatrixD<Dim> F = deformation_gradient<Dim>(g, displacement);
  Matrix3 F3 = Matrix3::Identity();
  F3.template topLeftCorner<Dim, Dim>() = F;
  const double J = F3.determinant();
  if (!(J > 0.0)) return J;
  Matrix3 P_vol;
  Tangent3 A_vol;
  volumetric_part(bulk, F3, P_vol, A_vol);
  const Matrix3 Finv_T = F3.inverse().transpose();
  // P_iso + p̄ J F⁻ᵀ (3D), restricted to the plane in 2D.
  const Matrix3 P3 = first_piola(material, F3, fibres) - P_vol + p_mean * J * Finv_T;
  const MatrixD<Dim> P = P3.template topLeftCorner<Dim, Dim>();
  const MatrixD<Dim> JFinv_T = (J * Finv_T).template topLeftCorner<Dim, Dim>();
  const double tau = kPressureStabilisation * h * h / (2.0 * shear);
  const auto mass = fem::element_mass<Dim>(geometry);
  const Eigen::Matrix<double, Dim + 1, 1> stabilised = V * tau * (g * g.transpose()) * p;
  const NodalValues<Dim> forces = V * g * P.transpose();
  for (int a = 0; a <= Dim; ++a) {
    for (int i = 0; i < Dim; ++i) r(a * m + i) = forces(a, i);
    r(a * m + Dim) = V * (J - 1.0) / (Dim + 1) - mass.row(a).dot(p) / bulk - stabilised(a);
  }
  if (!K) return J;
  Tangent3 A3 = tangent(material, F3, fibres) - A_vol;
  add_dyadic(A3, p_mean * J, Finv_T, Finv_T);
  add_crossed_dyadic(A3, -p_mean * J, Finv_T, Finv_T);
  const NodalValues<Dim> coupling = g * JFinv_T.transpose();  // row a = J F⁻ᵀ ∇N_a
  for (int a = 0; a <= Dim; ++a)
    for (int b = 0; b <= Dim; ++b) {
      for (int i = 0; i < Dim; ++i)
        for (int k = 0; k < Dim; ++k) {
          double sum = 0.0;
          for (int I = 0; I < Dim; ++I)
            for (int L = 0; L < Dim; ++L) sum += g(a, I) * A3(3 * i + I, 3 * k + L) * g(b, L);
          (*K)(a * m + i, b * m + k) = V * sum;
        }
      for (int i = 0; i < Dim; ++i) {
        (*K)(a * m + i, b * m + Dim) = V / (Dim + 1) * coupling(a, i);
        (*K)(b * m + Dim, a * m + i) = V / (Dim + 1) * coupling(a, i);
      }
      (*K)(a * m + Dim, b * m + Dim) = -mass(a, b) / bulk - V * tau * g.row(a).dot(g.row(b));
    }
  return J;
}

}  // namespace coapt::solid
