#pragma once
/// @file mixed_solver.hpp
/// The linear solver of the mixed displacement–pressure Newton systems (formulation: mixed,
/// options prefix solid_): a Schur-complement block preconditioner in 3D, LU in 2D.
///
/// The Newton matrix of mixed_elements.hpp, in blocks of displacement u and pressure p, is
///
///   K = [ A   Bᵀ ]      A: the isochoric tangent (shear modulus μ; the bulk modulus κ
///       [ B  −C  ]      lives only in C), C = M_p/κ + τ L_p (pressure mass, Brezzi–Pitkäranta),
///
/// with Schur complement S = −C − B A⁻¹ Bᵀ. Linearised at F = I, A = 2μ ε_dev : ε_dev and, on
/// gradient fields u = ∇φ (the ones B sees), div A u = (4/3) μ ∇Δφ in 3D and in plane strain,
/// so B A⁻¹ Bᵀ ≈ 3/(4μ) M_p (exact for the continuous problem with periodic conditions, and
/// spectrally equivalent on a bounded domain by the inf-sup condition; where P1–P1 violates it,
/// at the pressure's high frequencies, τ L_p takes over). Hence
///
///   S ≈ S_p = −(1/κ + w/μ) M_p − τ L_p,   w = 3/4,
///
/// used as −C (read off K) minus the lumped w M_p/μ. At κ/μ = 5000, −C alone (the "selfp"
/// choice without A⁻¹) is off by about κ/μ on the smooth pressure modes; the w/μ term makes S_p
/// equivalent to S uniformly in h. S_p is a mass matrix plus a Laplacian weighted by h², so its
/// diagonal is equivalent to it and one Jacobi sweep applies S_p⁻¹ at any mesh size. (With that
/// sweep, w changes the iterations little, 119–141 over w = 0–1.5 at 16³·6 tets, since the
/// diagonal of τ L_p is itself of the size of M_p/μ. With S_p applied exactly (LU), w = 0 needs
/// 153 and 313 iterations at 8³·6 and 16³·6 tets, w = 3/4 76 and 93.)
///
/// Defaults in 3D: GMRES (relative tolerance 1e-8) with PCFIELDSPLIT Schur, upper
/// factorisation; the displacement split "u" one GAMG V-cycle with the rigid-body near-null
/// space (block size Dim), the pressure split "p" Jacobi on S_p. Every default gives way to a
/// -solid_ option (-solid_pc_type lu for the direct solver; -solid_schur_mass_scale for w).

#include <mpi.h>
#include <petscksp.h>

#include <string>

#include "coapt/core/petsc.hpp"
#include "coapt/fem/linear_solver.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::solid {

class MixedLinearSolver {
 public:
  /// `pressure_mass`: the lumped M_p/μ (Σ over the cells at a vertex of |T|/((Dim+1) μ_T),
  /// in the units of the pressure unknown) at the pressure dofs of the (Dim+1)-component
  /// vertex layout, zero elsewhere; kept. Collective.
  MixedLinearSolver(const mesh::Mesh& mesh, Vec pressure_mass);
  /// Sets the Newton matrix (after assembly and Dirichlet elimination); builds S_p. Collective.
  void set_operator(Mat matrix);
  /// Solves K x = b; throws ConvergenceError if the Krylov method fails. Collective.
  fem::SolveStats solve(Vec rhs, Vec solution);
  /// One line: "gmres + fieldsplit (Schur: u gamg, p jacobi) (options prefix -solid_)".
  std::string describe() const;
  /// Whether the block preconditioner (rather than a factorisation) is in use.
  bool block_preconditioner() const { return fieldsplit_; }

 private:
  void configure(const mesh::Mesh& mesh);

  fem::LinearSolver solver_;
  OwnedVec pressure_mass_;  ///< the pressure_mass argument (own copy)
  OwnedIS displacement_dofs_, pressure_dofs_;
  OwnedMat schur_preconditioner_;  ///< S_p
  bool fieldsplit_ = false;
  bool user_schur_ = false;  ///< S_p is ours (no -solid_pc_fieldsplit_schur_precondition)
  double mass_scale_ = 0.75;
};

/// The solver defaults of the mixed form: GMRES + fieldsplit in 3D, MUMPS LU in 2D.
fem::LinearSolverDefaults mixed_solver_defaults(int dim);

}  // namespace coapt::solid
