#pragma once
/// @file navier_stokes.hpp
/// The fluid operator: P1-P1 SUPG/PSPG/LSIC Navier–Stokes (kernels.hpp) on a distributed
/// mesh, solved by Newton's method for one steady problem or one BDF step. It is the only
/// fluid file that touches PETSc solvers (options prefix -fluid_).
///
/// State: one ghosted vector with (u_1, .., u_Dim, p) per vertex (fem::create_vertex_vector
/// with n = dim + 1). Dirichlet dofs take the values the caller wrote into the state before
/// solve(); Newton corrections are zero there. Constrained vertices (the immersed coupling's
/// velocity constraint) are Dirichlet velocity dofs whose reaction forces can be read back.

#include <mpi.h>
#include <petscvec.h>

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "coapt/core/petsc.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/linear_solver.hpp"
#include "coapt/fluid/kernels.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::fluid {

/// Material, stabilisation and Newton settings (read once by the driver).
struct FluidParameters {
  double density = 1.0;                             ///< ρ [kg/m³]
  double viscosity = 1.0;                           ///< dynamic viscosity μ [Pa s]
  bool convection = true;                           ///< false: Stokes
  ViscousForm viscous_form = ViscousForm::laplace;  ///< the viscous term (kernels.hpp)
  double c_inverse = 9.0;                           ///< C_I of τ_M (kernels.hpp)
  /// τ_M includes (2/Δt)² (false: only the convective and viscous terms, independent of Δt)
  bool tau_time_term = true;
  /// Factor on the continuity residual (Galerkin and PSPG) of the cells whose vertices all
  /// carry the velocity constraint or Dirichlet velocities, one at least the constraint (inside
  /// an immersed solid). 1: no change.
  double covered_continuity_factor = 1.0;
  /// ... and of which the solids cover at least this fraction (set_velocity_constraint's
  /// cell_coverage): a cell only partly inside, such as one that spans the gap between two
  /// leaflets, holds fluid whose mass balance the factor would spoil. 0: the vertex rule alone.
  double covered_continuity_coverage = 1.0 - 1e-6;
  double newton_relative_tolerance = 1e-8;   ///< ‖R‖ ≤ rtol ‖R₀‖ ...
  double newton_absolute_tolerance = 1e-10;  ///< ... or ‖R‖ ≤ atol
  int newton_max_iterations = 25;
  /// Halvings of a Newton correction that raises ‖R‖ (backtracking while ‖R‖ stays above
  /// the last iterate's; the trial with the smallest ‖R‖ is kept); 0: full corrections.
  int newton_line_search = 0;
  /// With a direct solver (LU, Cholesky): a factorisation serves the later Newton iterations
  /// of its time step (and its coupling iterations) as GMRES's preconditioner until a solve
  /// on it needs more than this many iterations; 0: factored at every Newton iteration.
  /// Other preconditioners, and a factorisation applied alone (-fluid_ksp_type preonly), are
  /// rebuilt at every Newton iteration.
  int reuse_preconditioner = 10;
};

/// The time discretisation of one solve: steady (time_step ≤ 0) or a BDF step with
/// u̇ = (α₀ uⁿ⁺¹ + α₁ uⁿ + α₂ uⁿ⁻¹)/Δt.
struct TimeLevel {
  double time_step = 0;           ///< Δt [s] (≤ 0: steady)
  std::array<double, 3> alpha{};  ///< α₀, α₁, α₂
  Vec previous = nullptr;         ///< uⁿ (state vector; unused when steady)
  Vec before_previous = nullptr;  ///< uⁿ⁻¹ (may be null when α₂ = 0)
};

/// What one Newton solve did.
struct NewtonReport {
  int iterations = 0;
  int linear_iterations = 0;             ///< summed over the Newton steps
  int preconditioner_setups = 0;         ///< factorisations (or preconditioner builds)
  std::vector<double> residual_history;  ///< ‖R‖ of the free dofs, one per iterate
};

/// An outlet: a facet group on which the traction is −P n with P = resistance·Q + offset,
/// Q = ∫_Γ u·n the flow out through the group (the do-nothing condition is P = 0, a fixed
/// pressure has resistance 0, an implicitly coupled Windkessel gives its R_eff and offset per
/// step), plus backflow stabilisation with coefficient β (kernels.hpp).
struct Outlet {
  int tag = -1;           ///< facet tag of the group
  double backflow = 0;    ///< β (0: no backflow stabilisation)
  double resistance = 0;  ///< dP/dQ [Pa s/m³] (2D: per unit depth), ≥ 0
  double offset = 0;      ///< P at Q = 0 [Pa]
};

/// The discrete Navier–Stokes operator on one mesh. Every call is collective on mesh.comm.
class NavierStokes {
 public:
  /// Sets up pattern, vectors and the linear solver. `mesh` must outlive the operator.
  NavierStokes(const mesh::Mesh& mesh, const FluidParameters& parameters);

  /// The state vector (u, p interleaved, ghosted); write Dirichlet values into it.
  Vec state() const { return state_.get(); }
  /// Number of components per vertex (dim + 1).
  int n_components() const { return mesh_.dim + 1; }

  /// Replaces the Dirichlet dofs (owned global dof numbers, any order).
  void set_dirichlet_dofs(std::vector<PetscInt> dofs);
  /// Constrains the velocity at owned local vertices `vertices` to `velocities`
  /// (vertices.size() × dim, row-major) [m/s]; replaces the previous constraint. The state is
  /// updated at those dofs; the matrix pattern stays fixed. `cell_coverage`: per owned cell,
  /// the fraction of it the solids cover (for covered_continuity_coverage; empty: not known,
  /// the vertex rule alone decides).
  void set_velocity_constraint(std::span<const int> vertices, std::span<const double> velocities,
                               std::span<const double> cell_coverage = {});

  /// Draws the velocity at owned local vertices `vertices` towards `targets` (vertices.size()
  /// × dim, row-major) [m/s] by a penalty: R_(v,i) += κ_k (u_(v,i) − w_(k,i)) with
  /// κ_k = weights[k] · (ρ α₀ m_v / Δt + μ g_v), m_v = ∫φ_v and g_v = ∫|∇φ_v|² (steady: the
  /// viscous part alone), so a weight of 1 is as strong as the node's own inertia and
  /// viscosity and a weight → ∞ tends to the constraint u = w. With time_scale τ > 0 the
  /// inertial part is ρ m_v / τ instead, the same for every Δt (transient runs), so that the
  /// penalty is a drag of fixed strength and not one that stiffens as Δt → 0. A vertex may
  /// appear more than once (several solids' penalties add). Replaces the previous penalty.
  /// Not on a vertex of the velocity constraint or a Dirichlet dof (the constraint wins there).
  void set_velocity_penalty(std::span<const int> vertices, std::span<const double> weights,
                            std::span<const double> targets, double time_scale = 0.0);
  /// The force the fluid exerts on each penalty entry (set_velocity_penalty's order and layout),
  /// κ_k (u_v − w_k) [N/m or N]: at a converged solve, −R of the momentum equations without
  /// the penalty, like constraint_reactions.
  std::vector<double> penalty_reactions(const TimeLevel& time) const;

  /// Replaces the outlets (their facet groups must carry no Dirichlet velocity). Collective.
  void set_outlets(const std::vector<Outlet>& outlets);
  /// Sets P = resistance·Q + offset on outlet k (index into set_outlets' list) for the next
  /// solves. Not collective; every rank must give the same values.
  void set_outlet_pressure(std::size_t k, double resistance, double offset);
  /// Q = ∫_Γ u·n [m³/s in 3D, m²/s in 2D] through outlet k at the current state. Collective.
  double outlet_flow(std::size_t k) const;
  /// The outlet's pressure P = resistance·Q + offset at the current state [Pa]. Collective.
  double outlet_pressure(std::size_t k) const;
  /// ∫_Γ u·n over the facets tagged `tag` at the current state (n outward). Collective.
  double boundary_flow(int tag) const;

  /// The full residual R(state) (Dirichlet rows included) into `result`. Collective.
  void residual(const TimeLevel& time, Vec result);
  /// The Newton Jacobian applied to `direction`: J d + Σ_k R_k b_k (b_kᵀ d), the sparse part
  /// assembled at the current state (no Dirichlet rows removed). Collective.
  void jacobian_action(const TimeLevel& time, Vec direction, Vec result);

  /// Newton's method to the tolerances of FluidParameters; throws ConvergenceError with the
  /// residual history when it fails or meets a non-finite residual. `label` names the step.
  NewtonReport solve(const TimeLevel& time, const std::string& label);
  /// The next Newton iteration rebuilds the preconditioner (FluidParameters::
  /// reuse_preconditioner): called at the start of every time step and of every retry, so
  /// that a step's solves do not depend on the steps before it (a restart repeats them).
  void refresh_preconditioner() { preconditioner_current_ = false; }

  /// Force exerted by the fluid on the boundary group with facet tag `tag` [N/m in 2D, N in
  /// 3D], computed variationally: F_i = −R(u_h, p_h; w = e_i χ_Γ) with χ_Γ the P1 indicator of
  /// the group's vertices and R the full (stabilised) momentum residual at the current state.
  std::vector<double> boundary_force(int tag, const TimeLevel& time);
  /// The force the fluid exerts at every local vertex whose velocity is prescribed (a velocity
  /// or no-slip condition, or the immersed constraint), −R at its velocity dofs, and zero at
  /// the other vertices: n_vertices() × dim values, ghosts included, for output [N/m or N].
  /// Summed over a group's vertices it is boundary_force. Collective.
  std::vector<double> vertex_reactions(const TimeLevel& time);
  /// Reaction forces at the constrained vertices (same order and layout as the velocities
  /// given to set_velocity_constraint): the force the fluid exerts on the constraint, −R at
  /// those velocity dofs (R = the force the constraint applies to the fluid) [N/m or N].
  std::vector<double> constraint_reactions(const TimeLevel& time);

  /// The linear solver's description ("gmres + lu (options prefix -fluid_)").
  std::string describe_solver() const { return solver_.describe(); }

 private:
  template <int Dim>
  void assemble(const TimeLevel& time, bool with_matrix);
  /// Residual of the current state into residual_ (no Dirichlet rows removed).
  void assemble_residual(const TimeLevel& time);
  void assemble_system(const TimeLevel& time);
  /// ‖R‖ over the free dofs (a copy with Dirichlet rows zeroed goes into free_residual_).
  double free_residual_norm();
  std::vector<PetscInt> all_fixed_dofs() const;
  /// b with b_(v,i) = ∫_Γ φ_v n_i over the owned-cell facets tagged `tag` (pressure entries 0),
  /// so that Q = bᵀx for P1 velocities.
  OwnedVec flux_vector(int tag) const;
  /// Adds Σ_k P_k(Q_k) b_k to residual_.
  void add_outlet_tractions();
  /// Adds the velocity penalty to residual_ (and to the matrix's diagonal). Collective.
  void add_penalty(const TimeLevel& time, bool with_matrix);
  /// κ_k of penalty entry k for this time level.
  double penalty_coefficient(std::size_t k, const TimeLevel& time) const;
  /// Solves (J + Σ_k R_k b̃_k b̃_kᵀ) x = rhs (b̃: b with fixed dofs zeroed) with the factorised
  /// J and the Woodbury formula; returns the Krylov iterations of all solves, each capped at
  /// `max_iterations` when > 0.
  int solve_with_outlets(Vec rhs, Vec solution, const std::vector<PetscInt>& fixed,
                         int max_iterations);
  /// The Newton correction for −free_residual_ into correction_, with the assembled, row-fixed
  /// matrix: on the reused preconditioner when FluidParameters::reuse_preconditioner allows
  /// (factored afresh if GMRES fails on it), else on a new one (counted in `report`). Returns
  /// the Krylov iterations.
  int solve_correction(const TimeLevel& time, const std::vector<PetscInt>& fixed,
                       NewtonReport& report);

  /// The default preconditioner (navier_stokes.cpp, solver_defaults): with -fluid_pc_type
  /// fieldsplit, velocity and pressure splits "u", "p" and a Schur complement factorisation
  /// whose pressure preconditioner update_schur_preconditioner assembles, unless the options
  /// choose another one.
  void configure_preconditioner();
  /// S_p = A_pp − A_pu diag(A_uu)⁻¹ A_up + c M_p/μ_eff for the current (row-fixed) Jacobian,
  /// handed to the Schur split. Collective.
  void update_schur_preconditioner(const TimeLevel& time);

  /// Per outlet: its settings and flux vector b.
  std::vector<Outlet> outlets_;
  std::vector<OwnedVec> outlet_flux_;
  /// Backflow facets grouped by local cell (CSR: offsets per cell into the facet data).
  std::vector<int> backflow_offsets_;
  std::vector<double> backflow_data_;  ///< per facet: local[dim], normal[dim], measure, βρ/2

  const mesh::Mesh& mesh_;
  const FluidParameters parameters_;
  fem::P1Matrix matrix_;
  OwnedVec state_, residual_, free_residual_, correction_;
  fem::LinearSolver solver_;
  std::vector<PetscInt> dirichlet_dofs_;
  std::vector<int> constrained_vertices_;
  /// Per local vertex (owned and ghost): 2 carries the velocity constraint, 1 has Dirichlet
  /// velocities, 0 free (set only when covered_continuity_factor ≠ 1).
  std::vector<char> constrained_vertex_flag_;
  OwnedVec vertex_flags_;  ///< the ghosted vector that brings the flags of ghost vertices
  /// Per local cell (owned and ghost: the matrix is assembled over both): the fraction the
  /// solids cover (set only when covered_continuity_factor ≠ 1 and the caller gave it), and
  /// the ghosted vector that brings the ghost cells' values from their owners.
  std::vector<double> cell_coverage_;
  OwnedVec cell_fraction_;
  /// The velocity penalty: owned local vertices, weights, targets (dim each), and per owned
  /// vertex ∫φ_v and ∫|∇φ_v|² (computed on the first penalty).
  std::vector<int> penalty_vertices_;
  std::vector<double> penalty_weights_, penalty_targets_, lumped_mass_, stiffness_;
  double penalty_time_scale_ = 0.0;  ///< τ of the inertial part [s] (0: the step, ρ α₀ m/Δt)
  bool penalty_active_ = false;      ///< some rank has penalty vertices
  /// Owned velocity and pressure dofs (the splits) and the assembled Schur preconditioner.
  OwnedIS velocity_dofs_, pressure_dofs_;
  OwnedMat schur_preconditioner_;
  bool user_schur_ = false;  ///< update_schur_preconditioner supplies S_p
  /// the preconditioner is LU or Cholesky inside a Krylov method
  bool factorisation_ = false;
  /// the preconditioner is a fieldsplit inside a Krylov method (reused within a time step)
  bool fieldsplit_ = false;
  bool preconditioner_current_ = false;  ///< built in this time step, may be reused
  int fresh_iterations_ = 0;  ///< Krylov iterations of the last solve on a new preconditioner
};

}  // namespace coapt::fluid
