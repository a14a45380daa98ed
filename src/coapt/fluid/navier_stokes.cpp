#include "coapt/fluid/navier_stokes.hpp"

#include <fmt/format.h>
#include <petscksp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>

#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/fem/line_search.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fluid/kernels.hpp"

namespace coapt::fluid {
namespace {

/// 3D: GMRES with a Schur-complement fieldsplit: velocity split "u", pressure split "p"
/// (configure_preconditioner), upper-triangular factorisation, one BoomerAMG V-cycle on the
/// velocity block and one on the pressure preconditioner S_p of update_schur_preconditioner.
/// GMRES restarts after 100 iterations. The work per iteration is linear in the mesh and the
/// iterations per Newton step grew by 1.3x or less per refinement on a 3D channel and 1.6x on
/// DFG 3D-1Z (configure_preconditioner, update_schur_preconditioner); a Newton step needs only an
/// inexact solve (1e-6 keeps the Newton residual histories of the direct solver); a time step's
/// later solves reuse its fieldsplit (solve_correction). 2D: GMRES + LU
/// (MUMPS, any number of ranks), 1 iteration per Newton step on a new factorisation, a few on a
/// time step's reused one (solve_correction). The 2D meshes are small enough for
/// it, and the fieldsplit took 55–105 iterations per step on DFG 2D-1 (the convection-dominated
/// flow there is where the S_p above is weakest). docs/verification/fluid.md, "Linear solver", has
/// the measurements; -fluid_pc_type fieldsplit or lu switches in either dimension.
fem::LinearSolverDefaults solver_defaults(int dim) {
  fem::LinearSolverDefaults defaults;
  defaults.ksp_type = "gmres";
  defaults.pc_type = dim == 3 ? "fieldsplit" : "lu";
  defaults.relative_tolerance = dim == 3 ? 1e-6 : 1e-10;
  defaults.absolute_tolerance = 1e-14;
  defaults.max_iterations = 1000;
  return defaults;
}

/// Sets the option -name to value unless it was given (the user's options win).
void default_option(const std::string& name, const char* value) {
  PetscBool given = PETSC_FALSE;
  COAPT_PETSC_CHECK(PetscOptionsHasName(nullptr, nullptr, name.c_str(), &given));
  if (!given) COAPT_PETSC_CHECK(PetscOptionsSetValue(nullptr, name.c_str(), value));
}

std::string format_history(const std::vector<double>& history) {
  std::string text;
  for (std::size_t k = 0; k < history.size(); ++k)
    text += fmt::format("{}{:.3e}", k ? ", " : "", history[k]);
  return text;
}

/// Unit normal out of the domain (away from the facet's cell) and measure of boundary facet f.
void facet_geometry(const mesh::Mesh& mesh, int f, double* normal, double& measure) {
  const int dim = mesh.dim;
  const int* v = mesh.facets.data() + static_cast<std::size_t>(f) * dim;
  const auto p0 = mesh.point(v[0]), p1 = mesh.point(v[1]);
  double direction[3] = {};
  if (dim == 2) {
    direction[0] = p1[1] - p0[1];
    direction[1] = -(p1[0] - p0[0]);
  } else {
    const auto p2 = mesh.point(v[2]);
    const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    direction[0] = e1[1] * e2[2] - e1[2] * e2[1];
    direction[1] = e1[2] * e2[0] - e1[0] * e2[2];
    direction[2] = e1[0] * e2[1] - e1[1] * e2[0];
  }
  const double length = std::sqrt(direction[0] * direction[0] + direction[1] * direction[1] +
                                  direction[2] * direction[2]);
  measure = dim == 2 ? length : 0.5 * length;
  // The cell's vertex off the facet lies on the inner side.
  double inward = 0;
  for (const int w : mesh.cell(mesh.facet_cell[f]))
    if (std::find(v, v + dim, w) == v + dim)
      for (int i = 0; i < dim; ++i) inward += direction[i] * (mesh.point(w)[i] - p0[i]);
  const double sign = inward > 0 ? -1.0 : 1.0;
  for (int i = 0; i < dim; ++i) normal[i] = sign * direction[i] / length;
}

/// Adds ∫φ_v and ∫|∇φ_v|² over the local cells to mass[v] and stiffness[v] of each owned
/// vertex v.
template <int Dim>
void add_vertex_integrals(const mesh::Mesh& mesh, std::vector<double>& mass,
                          std::vector<double>& stiffness) {
  constexpr int k = Dim + 1;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    const auto cell = mesh.cell(c);
    const double* points[k];
    for (int a = 0; a < k; ++a) points[a] = mesh.point(cell[a]).data();
    const auto geometry = fem::p1_geometry<Dim>(points);
    for (int a = 0; a < k; ++a) {
      const int v = cell[a];
      if (v >= mesh.n_owned_vertices) continue;
      double square = 0;
      for (int i = 0; i < Dim; ++i) square += geometry.gradients(a, i) * geometry.gradients(a, i);
      mass[static_cast<std::size_t>(v)] += geometry.measure / k;
      stiffness[static_cast<std::size_t>(v)] += geometry.measure * square;
    }
  }
}

}  // namespace

NavierStokes::NavierStokes(const mesh::Mesh& mesh, const FluidParameters& parameters)
    : mesh_(mesh),
      parameters_(parameters),
      matrix_(mesh, mesh.dim + 1),
      state_(fem::create_vertex_vector(mesh, mesh.dim + 1)),
      residual_(fem::create_vertex_vector(mesh, mesh.dim + 1)),
      free_residual_(fem::create_vertex_vector(mesh, mesh.dim + 1)),
      correction_(fem::create_vertex_vector(mesh, mesh.dim + 1)),
      solver_(mesh.comm, "fluid_", solver_defaults(mesh.dim)) {
  if (mesh.dim != 2 && mesh.dim != 3)
    throw InputError(fmt::format("{}: the fluid solver needs a 2D or 3D mesh", mesh.source));
  configure_preconditioner();
  PetscBool given = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscOptionsHasName(nullptr, nullptr, "-fluid_pc_factor_mat_solver_type", &given));
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(solver_.ksp(), &pc));
  PCType type = nullptr;
  COAPT_PETSC_CHECK(PCGetType(pc, &type));
  if (!given && type && std::string(type) == PCLU)
    COAPT_PETSC_CHECK(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  // A reused preconditioner needs a Krylov method around it: -fluid_ksp_type preonly applies a
  // factorisation once, a stale Jacobian's Newton step. The LU factorisation and, in time
  // steps, the 3D default's fieldsplit (its AMG hierarchies and S_p) may be reused; others
  // are rebuilt.
  KSPType ksp_type = nullptr;
  COAPT_PETSC_CHECK(KSPGetType(solver_.ksp(), &ksp_type));
  const bool krylov = ksp_type && std::string(ksp_type) != KSPPREONLY;
  factorisation_ = solver_.is_factorisation() && krylov;
  fieldsplit_ = type && std::string(type) == PCFIELDSPLIT && krylov;
  // Rows of fixed dofs are zeroed in place: the CSR pattern P1Matrix writes into must stay.
  COAPT_PETSC_CHECK(MatSetOption(matrix_.mat(), MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
}

void NavierStokes::configure_preconditioner() {
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(solver_.ksp(), &pc));
  PetscBool fieldsplit = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCFIELDSPLIT, &fieldsplit));
  if (!fieldsplit) return;
  // The splits by index sets: the owned rows are whole vertices (u_1..u_dim, p).
  const int dim = mesh_.dim, n = dim + 1;
  PetscInt start = 0, end = 0;
  COAPT_PETSC_CHECK(MatGetOwnershipRange(matrix_.mat(), &start, &end));
  std::vector<PetscInt> velocity, pressure;
  for (PetscInt k = start; k < end; ++k)
    ((k - start) % n == dim ? pressure : velocity).push_back(k);
  COAPT_PETSC_CHECK(ISCreateGeneral(mesh_.comm, static_cast<PetscInt>(velocity.size()),
                                    velocity.data(), PETSC_COPY_VALUES, velocity_dofs_.out()));
  COAPT_PETSC_CHECK(ISSetBlockSize(velocity_dofs_, dim));
  COAPT_PETSC_CHECK(ISCreateGeneral(mesh_.comm, static_cast<PetscInt>(pressure.size()),
                                    pressure.data(), PETSC_COPY_VALUES, pressure_dofs_.out()));
  COAPT_PETSC_CHECK(PCFieldSplitSetIS(pc, "u", velocity_dofs_));
  COAPT_PETSC_CHECK(PCFieldSplitSetIS(pc, "p", pressure_dofs_));
  COAPT_PETSC_CHECK(PCFieldSplitSetType(pc, PC_COMPOSITE_SCHUR));
  COAPT_PETSC_CHECK(PCFieldSplitSetSchurFactType(pc, PC_FIELDSPLIT_SCHUR_FACT_UPPER));
  default_option("-fluid_fieldsplit_u_ksp_type", "preonly");
  default_option("-fluid_fieldsplit_u_pc_type", "hypre");
  default_option("-fluid_fieldsplit_p_ksp_type", "preonly");
  default_option("-fluid_fieldsplit_p_pc_type", "hypre");
  PetscBool given = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscOptionsHasName(nullptr, nullptr, "-fluid_pc_fieldsplit_schur_precondition", &given));
  user_schur_ = !given;
  PetscBool restart_given = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscOptionsHasName(nullptr, nullptr, "-fluid_ksp_gmres_restart", &restart_given));
  // The user's options override the set-up above (Schur factorisation, sub-solvers, ...).
  COAPT_PETSC_CHECK(KSPSetFromOptions(solver_.ksp()));
  // GMRES(30) restarted 6–10 times per solve on DFG 3D-1Z, taking 3–4 times the iterations
  // of GMRES(100) there (a no-op for other Krylov methods).
  if (!restart_given) COAPT_PETSC_CHECK(KSPGMRESSetRestart(solver_.ksp(), 100));
  PCCompositeType type = PC_COMPOSITE_SCHUR;
  COAPT_PETSC_CHECK(PCFieldSplitGetType(pc, &type));
  user_schur_ = user_schur_ && type == PC_COMPOSITE_SCHUR;
}

void NavierStokes::update_schur_preconditioner(const TimeLevel& time) {
  // S = A_pp − A_pu A_uu⁻¹ A_up. Its selfp approximation (A_uu⁻¹ → diag(A_uu)⁻¹) is good
  // where the velocity block is dominated by the mass ρα₀/Δt, but misses the smooth pressure
  // modes of the viscous regime, where S ≈ M_p/μ: iterations grew by about 1.6 per refinement
  // on a steady 3D channel. Adding the lumped pressure mass with the weight c/μ_eff,
  // μ_eff = μ + ρ h_K² α₀/Δt + ρ |ū_K| h_K, restores the limits: the first two terms are those
  // of the Cahouet–Chabard preconditioner S⁻¹ ≈ μ M_p⁻¹ + (ρ/Δt) L_p⁻¹, lumped element by
  // element; the third is the convective counterpart, as an element Péclet number enlarges
  // the viscosity seen by the pressure (without it, DFG 3D-1Z at Re = 20 took 176–228 GMRES
  // iterations per Newton step: the mass term 1/μ outweighed the selfp part where the flow
  // convects).
  Mat jacobian = matrix_.mat();
  const int dim = mesh_.dim, n = dim + 1;
  OwnedVec diagonal;
  COAPT_PETSC_CHECK(MatCreateVecs(jacobian, diagonal.out(), nullptr));
  COAPT_PETSC_CHECK(MatGetDiagonal(jacobian, diagonal));
  OwnedMat pressure_velocity, velocity_pressure, pressure_pressure;
  COAPT_PETSC_CHECK(MatCreateSubMatrix(jacobian, pressure_dofs_, velocity_dofs_, MAT_INITIAL_MATRIX,
                                       pressure_velocity.out()));
  COAPT_PETSC_CHECK(MatCreateSubMatrix(jacobian, velocity_dofs_, pressure_dofs_, MAT_INITIAL_MATRIX,
                                       velocity_pressure.out()));
  COAPT_PETSC_CHECK(MatCreateSubMatrix(jacobian, pressure_dofs_, pressure_dofs_, MAT_INITIAL_MATRIX,
                                       pressure_pressure.out()));
  {
    Vec velocity_diagonal = nullptr;
    COAPT_PETSC_CHECK(VecGetSubVector(diagonal, velocity_dofs_, &velocity_diagonal));
    COAPT_PETSC_CHECK(VecReciprocal(velocity_diagonal));
    COAPT_PETSC_CHECK(MatDiagonalScale(velocity_pressure, velocity_diagonal, nullptr));
    COAPT_PETSC_CHECK(VecRestoreSubVector(diagonal, velocity_dofs_, &velocity_diagonal));
  }
  COAPT_PETSC_CHECK(MatMatMult(pressure_velocity, velocity_pressure, MAT_INITIAL_MATRIX,
                               PETSC_DEFAULT, schur_preconditioner_.out()));
  COAPT_PETSC_CHECK(MatScale(schur_preconditioner_, -1.0));
  COAPT_PETSC_CHECK(
      MatAXPY(schur_preconditioner_, 1.0, pressure_pressure, UNKNOWN_NONZERO_PATTERN));
  // Lumped pressure mass / μ_eff over the owned cells (each cell once).
  const double mass_rate = time.time_step > 0 ? time.alpha[0] / time.time_step : 0.0;
  // The weight c of the mass term (-fluid_schur_mass_scale). With the convective part of
  // μ_eff, 0.1 took the fewest GMRES iterations per Newton step on both the viscous box
  // channel (15, 20, 26 on three levels) and DFG 3D-1Z (34, 53 on levels 0–1); 0.3 took 20,
  // 23, 28 and 43, 70; 1 and 3 many more; 0 (selfp alone) 25 and 45 on 3D-1Z, growing fastest.
  // An exact solve of the velocity block or of S_p does not lower these counts: they are the
  // quality of S_p as an approximation of S (docs/verification/fluid.md, "Linear solver").
  PetscReal mass_scale = 0.1;
  COAPT_PETSC_CHECK(
      PetscOptionsGetReal(nullptr, "fluid_", "-schur_mass_scale", &mass_scale, nullptr));
  OwnedVec mass;
  COAPT_PETSC_CHECK(VecDuplicate(diagonal, mass.out()));
  COAPT_PETSC_CHECK(VecSet(mass, 0.0));
  std::vector<PetscInt> rows(static_cast<std::size_t>(n));
  std::vector<PetscScalar> values(static_cast<std::size_t>(n));
  const fem::LocalValues state(state_);  // its ghosts are current: assemble() updated them
  for (int c = 0; c < mesh_.n_owned_cells; ++c) {
    const auto cell = mesh_.cell(c);
    const auto p0 = mesh_.point(cell[0]);
    double mean[3] = {};  // ū_K, the element-mean velocity of the current iterate
    for (int a = 0; a < n; ++a)
      for (int i = 0; i < dim; ++i) mean[i] += state[static_cast<std::size_t>(cell[a]) * n + i] / n;
    const double speed = std::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
    double edges[3][3] = {};
    for (int a = 0; a < dim; ++a)
      for (int i = 0; i < dim; ++i) edges[a][i] = mesh_.point(cell[a + 1])[i] - p0[i];
    const double determinant =
        dim == 2 ? edges[0][0] * edges[1][1] - edges[0][1] * edges[1][0]
                 : edges[0][0] * (edges[1][1] * edges[2][2] - edges[1][2] * edges[2][1]) -
                       edges[0][1] * (edges[1][0] * edges[2][2] - edges[1][2] * edges[2][0]) +
                       edges[0][2] * (edges[1][0] * edges[2][1] - edges[1][1] * edges[2][0]);
    const double measure = std::abs(determinant) / (dim == 2 ? 2.0 : 6.0);
    const double size = std::pow(std::abs(determinant), 1.0 / dim);  // h_K
    const double convection = parameters_.convection ? parameters_.density * speed * size : 0.0;
    const double viscosity = parameters_.viscosity + parameters_.density * size * size * mass_rate +
                             convection;  // μ_eff
    for (int a = 0; a < n; ++a) {
      rows[a] = mesh_.global_vertex[cell[a]] * n + dim;
      values[a] = mass_scale * measure / n / viscosity;
    }
    COAPT_PETSC_CHECK(VecSetValues(mass, n, rows.data(), values.data(), ADD_VALUES));
  }
  COAPT_PETSC_CHECK(VecAssemblyBegin(mass));
  COAPT_PETSC_CHECK(VecAssemblyEnd(mass));
  {
    Vec pressure_mass = nullptr;
    COAPT_PETSC_CHECK(VecGetSubVector(mass, pressure_dofs_, &pressure_mass));
    COAPT_PETSC_CHECK(MatDiagonalSet(schur_preconditioner_, pressure_mass, ADD_VALUES));
    COAPT_PETSC_CHECK(VecRestoreSubVector(mass, pressure_dofs_, &pressure_mass));
  }
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(solver_.ksp(), &pc));
  COAPT_PETSC_CHECK(
      PCFieldSplitSetSchurPre(pc, PC_FIELDSPLIT_SCHUR_PRE_USER, schur_preconditioner_));
}

void NavierStokes::set_dirichlet_dofs(std::vector<PetscInt> dofs) {
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  dirichlet_dofs_ = std::move(dofs);
}

void NavierStokes::set_velocity_constraint(std::span<const int> vertices,
                                           std::span<const double> velocities,
                                           std::span<const double> cell_coverage) {
  const int dim = mesh_.dim, n = dim + 1;
  if (velocities.size() != vertices.size() * static_cast<std::size_t>(dim))
    throw InternalError("set_velocity_constraint: velocities must be vertices × dim");
  if (!cell_coverage.empty() &&
      cell_coverage.size() != static_cast<std::size_t>(mesh_.n_owned_cells))
    throw InternalError(
        "set_velocity_constraint: cell_coverage must have one entry per owned cell");
  constrained_vertices_.assign(vertices.begin(), vertices.end());
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const int v = vertices[k];
    if (v < 0 || v >= mesh_.n_owned_vertices)
      throw InternalError("set_velocity_constraint: vertices must be owned local vertices");
    for (int i = 0; i < dim; ++i)
      COAPT_PETSC_CHECK(VecSetValue(state_, mesh_.global_vertex[v] * n + i, velocities[k * dim + i],
                                    INSERT_VALUES));
  }
  COAPT_PETSC_CHECK(VecAssemblyBegin(state_));
  COAPT_PETSC_CHECK(VecAssemblyEnd(state_));
  fem::update_ghosts(state_);
  if (parameters_.covered_continuity_factor == 1.0) return;
  cell_coverage_.clear();
  // The cells' covered fractions: the owned cells' given, the ghost cells' from their owners.
  if (!cell_coverage.empty()) {
    if (!cell_fraction_) cell_fraction_ = fem::create_cell_vector(mesh_);
    PetscScalar* owned = nullptr;
    COAPT_PETSC_CHECK(VecGetArray(cell_fraction_, &owned));
    std::copy(cell_coverage.begin(), cell_coverage.end(), owned);
    COAPT_PETSC_CHECK(VecRestoreArray(cell_fraction_, &owned));
    fem::update_ghosts(cell_fraction_);
    fem::LocalValues local(cell_fraction_);
    cell_coverage_.assign(local.values().begin(), local.values().end());
  }
  // Per vertex 2: constrained, 1: all its velocity dofs Dirichlet (a wall inside the solid's
  // region), 0: free; the ghost vertices' flags come from their owners.
  if (!vertex_flags_) vertex_flags_ = fem::create_vertex_vector(mesh_, 1);
  Vec flags = vertex_flags_.get();
  COAPT_PETSC_CHECK(VecSet(flags, 0.0));
  for (int v = 0; v < mesh_.n_owned_vertices; ++v) {
    bool fixed = true;
    for (int i = 0; i < dim && fixed; ++i)
      fixed = std::binary_search(dirichlet_dofs_.begin(), dirichlet_dofs_.end(),
                                 static_cast<PetscInt>(mesh_.global_vertex[v] * n + i));
    if (fixed) COAPT_PETSC_CHECK(VecSetValue(flags, mesh_.global_vertex[v], 1.0, INSERT_VALUES));
  }
  for (const int v : vertices)
    COAPT_PETSC_CHECK(VecSetValue(flags, mesh_.global_vertex[v], 2.0, INSERT_VALUES));
  COAPT_PETSC_CHECK(VecAssemblyBegin(flags));
  COAPT_PETSC_CHECK(VecAssemblyEnd(flags));
  fem::update_ghosts(flags);
  fem::LocalValues local(flags);
  const auto values = local.values();
  constrained_vertex_flag_.assign(values.size(), 0);
  for (std::size_t v = 0; v < values.size(); ++v)
    constrained_vertex_flag_[v] = static_cast<char>(std::lround(values[v]));
}

void NavierStokes::set_velocity_penalty(std::span<const int> vertices,
                                        std::span<const double> weights,
                                        std::span<const double> targets, double time_scale) {
  const int dim = mesh_.dim;
  if (!(time_scale >= 0.0)) throw InternalError("set_velocity_penalty: time_scale must be >= 0");
  if (weights.size() != vertices.size() ||
      targets.size() != vertices.size() * static_cast<std::size_t>(dim))
    throw InternalError("set_velocity_penalty: one weight and dim targets per vertex");
  for (const int v : vertices)
    if (v < 0 || v >= mesh_.n_owned_vertices)
      throw InternalError("set_velocity_penalty: vertices must be owned local vertices");
  penalty_vertices_.assign(vertices.begin(), vertices.end());
  penalty_weights_.assign(weights.begin(), weights.end());
  penalty_targets_.assign(targets.begin(), targets.end());
  penalty_time_scale_ = time_scale;
  int active = penalty_vertices_.empty() ? 0 : 1;  // add_penalty is collective
  MPI_Allreduce(MPI_IN_PLACE, &active, 1, MPI_INT, MPI_MAX, mesh_.comm);
  penalty_active_ = active != 0;
  if (penalty_vertices_.empty() || !lumped_mass_.empty()) return;
  // ∫φ_v and ∫|∇φ_v|² of the owned vertices: every cell touching an owned vertex is local
  // (owned or in the ghost layer).
  lumped_mass_.assign(static_cast<std::size_t>(mesh_.n_owned_vertices), 0.0);
  stiffness_.assign(lumped_mass_.size(), 0.0);
  if (dim == 2)
    add_vertex_integrals<2>(mesh_, lumped_mass_, stiffness_);
  else
    add_vertex_integrals<3>(mesh_, lumped_mass_, stiffness_);
}

double NavierStokes::penalty_coefficient(std::size_t k, const TimeLevel& time) const {
  const auto v = static_cast<std::size_t>(penalty_vertices_[k]);
  double scale = parameters_.viscosity * stiffness_[v];
  if (time.time_step > 0)
    scale += penalty_time_scale_ > 0.0
                 ? parameters_.density * lumped_mass_[v] / penalty_time_scale_
                 : parameters_.density * time.alpha[0] * lumped_mass_[v] / time.time_step;
  return penalty_weights_[k] * scale;
}

void NavierStokes::add_penalty(const TimeLevel& time, bool with_matrix) {
  const int dim = mesh_.dim, n = dim + 1;
  const std::vector<PetscScalar> residuals = penalty_reactions(time);  // κ_k (u_v − w_k)
  std::vector<PetscInt> dofs;
  std::vector<PetscScalar> diagonal;
  for (std::size_t k = 0; k < penalty_vertices_.size(); ++k) {
    const double kappa = penalty_coefficient(k, time);
    for (int i = 0; i < dim; ++i) {
      dofs.push_back(mesh_.global_vertex[penalty_vertices_[k]] * n + i);
      diagonal.push_back(kappa);
    }
  }
  COAPT_PETSC_CHECK(VecSetValues(residual_, static_cast<PetscInt>(dofs.size()), dofs.data(),
                                 residuals.data(), ADD_VALUES));
  COAPT_PETSC_CHECK(VecAssemblyBegin(residual_));
  COAPT_PETSC_CHECK(VecAssemblyEnd(residual_));
  if (!with_matrix) return;
  for (std::size_t q = 0; q < dofs.size(); ++q)
    COAPT_PETSC_CHECK(MatSetValue(matrix_.mat(), dofs[q], dofs[q], diagonal[q], ADD_VALUES));
  COAPT_PETSC_CHECK(MatAssemblyBegin(matrix_.mat(), MAT_FINAL_ASSEMBLY));
  COAPT_PETSC_CHECK(MatAssemblyEnd(matrix_.mat(), MAT_FINAL_ASSEMBLY));
}

std::vector<double> NavierStokes::penalty_reactions(const TimeLevel& time) const {
  const int dim = mesh_.dim, n = dim + 1;
  std::vector<double> reactions;
  reactions.reserve(penalty_vertices_.size() * dim);
  fem::LocalValues state(state_);
  for (std::size_t k = 0; k < penalty_vertices_.size(); ++k) {
    const int v = penalty_vertices_[k];
    const double kappa = penalty_coefficient(k, time);
    for (int i = 0; i < dim; ++i)
      reactions.push_back(
          kappa * (state[static_cast<std::size_t>(v) * n + i] - penalty_targets_[k * dim + i]));
  }
  return reactions;
}

void NavierStokes::set_outlets(const std::vector<Outlet>& outlets) {
  const int dim = mesh_.dim;
  outlets_ = outlets;
  outlet_flux_.clear();
  for (const auto& outlet : outlets_) outlet_flux_.push_back(flux_vector(outlet.tag));
  // Backflow facets of every local cell (ghost cells too: the matrix rows of owned vertices
  // need them), packed as local[dim], normal[dim], measure, βρ/2 and grouped by cell.
  const std::size_t stride = 2 * static_cast<std::size_t>(dim) + 2;
  std::vector<std::pair<int, std::vector<double>>> facets;
  for (int f = 0; f < mesh_.n_facets(); ++f)
    for (const auto& outlet : outlets_) {
      if (outlet.tag != mesh_.facet_tags[f] || outlet.backflow <= 0) continue;
      std::vector<double> data(stride);
      const int c = mesh_.facet_cell[f];
      const auto cell = mesh_.cell(c);
      for (int a = 0; a < dim; ++a) {
        const int v = mesh_.facets[static_cast<std::size_t>(f) * dim + a];
        data[a] = static_cast<double>(std::find(cell.begin(), cell.end(), v) - cell.begin());
      }
      facet_geometry(mesh_, f, data.data() + dim, data[2 * dim]);
      data[2 * dim + 1] = 0.5 * outlet.backflow * parameters_.density;
      facets.emplace_back(c, std::move(data));
      break;
    }
  std::stable_sort(facets.begin(), facets.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  backflow_offsets_.assign(static_cast<std::size_t>(mesh_.n_cells()) + 1, 0);
  backflow_data_.clear();
  for (const auto& [c, data] : facets) {
    ++backflow_offsets_[c + 1];
    backflow_data_.insert(backflow_data_.end(), data.begin(), data.end());
  }
  for (int c = 0; c < mesh_.n_cells(); ++c) backflow_offsets_[c + 1] += backflow_offsets_[c];
}

void NavierStokes::set_outlet_pressure(std::size_t k, double resistance, double offset) {
  if (k >= outlets_.size()) throw InternalError("set_outlet_pressure: no such outlet");
  if (!(resistance >= 0) || !std::isfinite(resistance) || !std::isfinite(offset))
    throw InternalError("set_outlet_pressure: the resistance must be finite and >= 0");
  outlets_[k].resistance = resistance;
  outlets_[k].offset = offset;
}

double NavierStokes::outlet_flow(std::size_t k) const {
  PetscScalar flow = 0;
  COAPT_PETSC_CHECK(VecDot(outlet_flux_.at(k), state_, &flow));
  return flow;
}

double NavierStokes::outlet_pressure(std::size_t k) const {
  return outlets_.at(k).resistance * outlet_flow(k) + outlets_[k].offset;
}

double NavierStokes::boundary_flow(int tag) const {
  const auto flux = flux_vector(tag);
  PetscScalar flow = 0;
  COAPT_PETSC_CHECK(VecDot(flux, state_, &flow));
  return flow;
}

OwnedVec NavierStokes::flux_vector(int tag) const {
  const int dim = mesh_.dim, n = dim + 1;
  auto flux = fem::create_vertex_vector(mesh_, n);
  Vec local = nullptr;
  COAPT_PETSC_CHECK(VecGhostGetLocalForm(flux, &local));
  COAPT_PETSC_CHECK(VecSet(local, 0.0));
  PetscScalar* data = nullptr;
  COAPT_PETSC_CHECK(VecGetArray(local, &data));
  // ∫_F φ_v n = |F|/dim n for each vertex of a flat facet; owned cells count each facet once.
  for (int f = 0; f < mesh_.n_facets(); ++f) {
    if (mesh_.facet_tags[f] != tag || mesh_.facet_cell[f] >= mesh_.n_owned_cells) continue;
    double normal[3], measure = 0;
    facet_geometry(mesh_, f, normal, measure);
    for (int a = 0; a < dim; ++a) {
      const int v = mesh_.facets[static_cast<std::size_t>(f) * dim + a];
      for (int i = 0; i < dim; ++i)
        data[static_cast<std::size_t>(v) * n + i] += measure / dim * normal[i];
    }
  }
  COAPT_PETSC_CHECK(VecRestoreArray(local, &data));
  COAPT_PETSC_CHECK(VecGhostRestoreLocalForm(flux, &local));
  fem::add_local_to_global(flux);
  return flux;
}

void NavierStokes::add_outlet_tractions() {
  // The traction −P n tested with w gives ∫_Γ P n·w = P bᵀw.
  for (std::size_t k = 0; k < outlets_.size(); ++k) {
    const double pressure = outlet_pressure(k);
    if (pressure != 0.0) COAPT_PETSC_CHECK(VecAXPY(residual_, pressure, outlet_flux_[k]));
  }
}

void NavierStokes::residual(const TimeLevel& time, Vec result) {
  assemble_residual(time);
  COAPT_PETSC_CHECK(VecCopy(residual_, result));
}

void NavierStokes::jacobian_action(const TimeLevel& time, Vec direction, Vec result) {
  assemble_system(time);
  COAPT_PETSC_CHECK(MatMult(matrix_.mat(), direction, result));
  for (std::size_t k = 0; k < outlets_.size(); ++k) {
    PetscScalar projection = 0;
    COAPT_PETSC_CHECK(VecDot(outlet_flux_[k], direction, &projection));
    COAPT_PETSC_CHECK(VecAXPY(result, outlets_[k].resistance * projection, outlet_flux_[k]));
  }
}

int NavierStokes::solve_with_outlets(Vec rhs, Vec solution, const std::vector<PetscInt>& fixed,
                                     int max_iterations) {
  int iterations = solver_.solve(rhs, solution, max_iterations).iterations;
  std::vector<std::size_t> coupled;
  for (std::size_t k = 0; k < outlets_.size(); ++k)
    if (outlets_[k].resistance != 0.0) coupled.push_back(k);
  if (coupled.empty()) return iterations;
  // Woodbury: (J + B D Bᵀ)⁻¹r = y − Z (I + D BᵀZ)⁻¹ D Bᵀy with y = J⁻¹r, Z = J⁻¹B, one extra
  // solve per coupled outlet with the factorisation J already has. B's columns are the flux
  // vectors with the fixed dofs zeroed (their rows of J are identity rows).
  const std::size_t m = coupled.size();
  std::vector<OwnedVec> columns(m), images(m);
  const std::vector<PetscScalar> zeros(fixed.size(), 0.0);
  for (std::size_t j = 0; j < m; ++j) {
    COAPT_PETSC_CHECK(VecDuplicate(outlet_flux_[coupled[j]], columns[j].out()));
    COAPT_PETSC_CHECK(VecCopy(outlet_flux_[coupled[j]], columns[j]));
    COAPT_PETSC_CHECK(VecSetValues(columns[j], static_cast<PetscInt>(fixed.size()), fixed.data(),
                                   zeros.data(), INSERT_VALUES));
    COAPT_PETSC_CHECK(VecAssemblyBegin(columns[j]));
    COAPT_PETSC_CHECK(VecAssemblyEnd(columns[j]));
    COAPT_PETSC_CHECK(VecDuplicate(columns[j], images[j].out()));
    COAPT_PETSC_CHECK(VecSet(images[j], 0.0));
    iterations += solver_.solve(columns[j], images[j], max_iterations).iterations;
  }
  Eigen::MatrixXd capacitance(m, m);
  Eigen::VectorXd projected(m);
  for (std::size_t j = 0; j < m; ++j) {
    const double resistance = outlets_[coupled[j]].resistance;
    PetscScalar value = 0;
    COAPT_PETSC_CHECK(VecDot(columns[j], solution, &value));
    projected(static_cast<Eigen::Index>(j)) = resistance * value;
    for (std::size_t l = 0; l < m; ++l) {
      COAPT_PETSC_CHECK(VecDot(columns[j], images[l], &value));
      capacitance(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(l)) =
          (j == l ? 1.0 : 0.0) + resistance * value;
    }
  }
  const Eigen::VectorXd coefficients = capacitance.partialPivLu().solve(projected);
  for (std::size_t l = 0; l < m; ++l)
    COAPT_PETSC_CHECK(VecAXPY(solution, -coefficients(static_cast<Eigen::Index>(l)), images[l]));
  return iterations;
}

int NavierStokes::solve_correction(const TimeLevel& time, const std::vector<PetscInt>& fixed,
                                   NewtonReport& report) {
  // The fieldsplit is reused within a time step only: a steady Newton solve goes from the
  // Stokes-like first Jacobian to the converged one, and its iterations per Newton step are
  // the measure of the preconditioner (docs/verification/fluid.md).
  const bool reusable = factorisation_ || (fieldsplit_ && time.time_step > 0);
  const int limit = reusable ? parameters_.reuse_preconditioner : 0;
  if (limit > 0 && preconditioner_current_) {
    // GMRES on the time step's preconditioner, capped: a solve that would need more than a
    // few times the allowance costs more than a new preconditioner. On a factorisation a
    // fresh solve takes one iteration and the allowance is the limit; on the fieldsplit it
    // is the limit beyond the iterations of the last solve on a fresh preconditioner.
    const int allowed = factorisation_ ? limit : fresh_iterations_ + limit;
    const int cap = factorisation_ ? 4 * limit : 2 * allowed;
    COAPT_PETSC_CHECK(VecSet(correction_, 0.0));
    solver_.set_operator(matrix_.mat(), true);
    try {
      const int iterations = solve_with_outlets(free_residual_, correction_, fixed, cap);
      if (iterations > allowed) preconditioner_current_ = false;
      return iterations;
    } catch (const ConvergenceError& error) {
      log::debug("fluid: {} on the reused preconditioner; building it afresh", error.what());
    }
  }
  COAPT_PETSC_CHECK(VecSet(correction_, 0.0));
  preconditioner_current_ = false;
  solver_.set_operator(matrix_.mat());
  if (user_schur_) update_schur_preconditioner(time);
  ++report.preconditioner_setups;
  const int iterations = solve_with_outlets(free_residual_, correction_, fixed, 0);
  preconditioner_current_ = true;
  fresh_iterations_ = iterations;
  return iterations;
}

std::vector<PetscInt> NavierStokes::all_fixed_dofs() const {
  std::vector<PetscInt> dofs = dirichlet_dofs_;
  const int n = mesh_.dim + 1;
  for (int v : constrained_vertices_)
    for (int i = 0; i < mesh_.dim; ++i) dofs.push_back(mesh_.global_vertex[v] * n + i);
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  return dofs;
}

template <int Dim>
void NavierStokes::assemble(const TimeLevel& time, bool with_matrix) {
  constexpr int n = Dim + 1, m = n * n;
  const bool transient = time.time_step > 0;
  if (transient && !time.previous)
    throw InternalError("NavierStokes: a transient step needs the previous state");
  fem::update_ghosts(state_);
  fem::LocalValues state(state_);
  std::optional<fem::LocalValues> previous, before;
  if (transient) previous.emplace(time.previous);
  if (transient && time.alpha[2] != 0.0) {
    if (!time.before_previous)
      throw InternalError("NavierStokes: a BDF2 step needs the state before the previous one");
    before.emplace(time.before_previous);
  }
  // Builds the element data of local cell c (τ from the current element-mean velocity) and
  // gathers its unknowns.
  auto element = [&](int c, ElementData<Dim>& data, double* x) {
    const auto vertices = mesh_.cell(c);
    const double* points[n];
    for (int a = 0; a < n; ++a) points[a] = mesh_.point(vertices[a]).data();
    double edges[Dim][Dim];
    fem::detail::edges_from_pointers<Dim>(points, edges);
    const double det = fem::detail::gradients_from_edges<Dim>(edges, data.gradients);
    data.measure = std::abs(det) / fem::detail::factorial(Dim);
    data.density = parameters_.density;
    data.viscosity = parameters_.viscosity;
    data.convection = parameters_.convection;
    data.viscous_form = parameters_.viscous_form;
    data.mass_coefficient = transient ? time.alpha[0] / time.time_step : 0.0;
    double mean[Dim] = {};
    for (int a = 0; a < n; ++a) {
      const std::size_t base = static_cast<std::size_t>(vertices[a]) * n;
      for (int i = 0; i < n; ++i) x[a * n + i] = state[base + i];
      for (int i = 0; i < Dim; ++i) {
        mean[i] += x[a * n + i] / n;
        double history = 0;
        if (transient) history += time.alpha[1] * (*previous)[base + i];
        if (before) history += time.alpha[2] * (*before)[base + i];
        data.history[a][i] = transient ? history / time.time_step : 0.0;
      }
    }
    set_stabilisation<Dim>(data, mean, parameters_.tau_time_term ? time.time_step : 0.0,
                           parameters_.c_inverse);
  };
  // The factor on local cell c's continuity rows: covered_continuity_factor if its vertices
  // all carry the velocity constraint or have Dirichlet velocities, at least one the
  // constraint, and the solids cover covered_continuity_coverage of it; else 1.
  auto continuity_factor = [&](int c) {
    if (constrained_vertex_flag_.empty()) return 1.0;
    if (!cell_coverage_.empty() &&
        cell_coverage_[static_cast<std::size_t>(c)] < parameters_.covered_continuity_coverage)
      return 1.0;
    const auto vertices = mesh_.cell(c);
    bool constrained = false;
    for (int a = 0; a < n; ++a) {
      const char flag = constrained_vertex_flag_[vertices[a]];
      if (flag == 0) return 1.0;
      constrained = constrained || flag == 2;
    }
    return constrained ? parameters_.covered_continuity_factor : 1.0;
  };
  // The backflow facets of local cell c, unpacked from set_outlets' layout.
  auto backflow_facets = [&](int c, auto&& use) {
    if (backflow_offsets_.empty()) return;
    constexpr std::size_t stride = 2 * Dim + 2;
    for (int k = backflow_offsets_[c]; k < backflow_offsets_[c + 1]; ++k) {
      const double* packed = backflow_data_.data() + static_cast<std::size_t>(k) * stride;
      OutletFacet<Dim> facet;
      for (int a = 0; a < Dim; ++a) {
        facet.local[a] = static_cast<int>(packed[a]);
        facet.normal[a] = packed[Dim + a];
      }
      facet.measure = packed[2 * Dim];
      facet.backflow_coefficient = packed[2 * Dim + 1];
      use(facet);
    }
  };
  fem::assemble_vector(mesh_, n, residual_, [&](int c, double* r) {
    ElementData<Dim> data;
    double x[m];
    element(c, data, x);
    element_residual<Dim, double>(data, x, r);
    if (const double factor = continuity_factor(c); factor != 1.0)
      for (int a = 0; a < n; ++a) r[a * n + Dim] *= factor;
    backflow_facets(c, [&](const OutletFacet<Dim>& facet) {
      backflow_facet_residual<Dim, double>(facet, x, r);
    });
  });
  add_outlet_tractions();
  if (with_matrix)
    matrix_.assemble([&](int c, double* K) {
      ElementData<Dim> data;
      double x[m];
      element(c, data, x);
      element_residual_and_jacobian<Dim>(data, x, nullptr, K);
      if (const double factor = continuity_factor(c); factor != 1.0)
        for (int a = 0; a < n; ++a)
          for (int col = 0; col < m; ++col) K[(a * n + Dim) * m + col] *= factor;
      backflow_facets(c, [&](const OutletFacet<Dim>& facet) {
        backflow_facet_residual_and_jacobian<Dim>(facet, x, nullptr, K);
      });
    });
  if (penalty_active_) add_penalty(time, with_matrix);
}

void NavierStokes::assemble_residual(const TimeLevel& time) {
  if (mesh_.dim == 2)
    assemble<2>(time, false);
  else
    assemble<3>(time, false);
}

void NavierStokes::assemble_system(const TimeLevel& time) {
  if (mesh_.dim == 2)
    assemble<2>(time, true);
  else
    assemble<3>(time, true);
}

double NavierStokes::free_residual_norm() {
  COAPT_PETSC_CHECK(VecCopy(residual_, free_residual_));
  const auto fixed = all_fixed_dofs();
  std::vector<PetscScalar> zeros(fixed.size(), 0.0);
  COAPT_PETSC_CHECK(VecSetValues(free_residual_, static_cast<PetscInt>(fixed.size()), fixed.data(),
                                 zeros.data(), INSERT_VALUES));
  COAPT_PETSC_CHECK(VecAssemblyBegin(free_residual_));
  COAPT_PETSC_CHECK(VecAssemblyEnd(free_residual_));
  PetscReal norm = 0;
  COAPT_PETSC_CHECK(VecNorm(free_residual_, NORM_2, &norm));
  return norm;
}

NewtonReport NavierStokes::solve(const TimeLevel& time, const std::string& label) {
  NewtonReport report;
  const auto fixed = all_fixed_dofs();
  double initial = 0;
  // ‖R‖ of the current state when the line search has already assembled it (free_residual_
  // holds it too)
  std::optional<double> evaluated;
  for (int iteration = 0;; ++iteration) {
    if (!evaluated) assemble_residual(time);
    const double norm = evaluated ? *evaluated : free_residual_norm();
    evaluated.reset();
    report.residual_history.push_back(norm);
    if (!std::isfinite(norm))
      throw ConvergenceError(fmt::format("fluid Newton, {}: non-finite residual (history {})",
                                         label, format_history(report.residual_history)));
    if (iteration == 0) initial = norm;
    if (norm <= std::max(parameters_.newton_absolute_tolerance,
                         parameters_.newton_relative_tolerance * initial))
      break;
    if (iteration == parameters_.newton_max_iterations)
      throw ConvergenceError(fmt::format(
          "fluid Newton, {}: no convergence in {} iterations (rtol {:g}, atol {:g}); residual "
          "history {}",
          label, iteration, parameters_.newton_relative_tolerance,
          parameters_.newton_absolute_tolerance, format_history(report.residual_history)));
    assemble_system(time);
    // Fixed rows become identity rows scaled like the rest of the diagonal; the right-hand
    // side −R is already zero there (free_residual_), so the correction keeps the values.
    OwnedVec diagonal;
    COAPT_PETSC_CHECK(MatCreateVecs(matrix_.mat(), diagonal.out(), nullptr));
    COAPT_PETSC_CHECK(MatGetDiagonal(matrix_.mat(), diagonal));
    PetscReal sum = 0;
    PetscInt size = 0;
    COAPT_PETSC_CHECK(VecNorm(diagonal, NORM_1, &sum));
    COAPT_PETSC_CHECK(VecGetSize(diagonal, &size));
    const PetscScalar scale = size > 0 && sum > 0 ? sum / static_cast<PetscReal>(size) : 1.0;
    COAPT_PETSC_CHECK(MatZeroRows(matrix_.mat(), static_cast<PetscInt>(fixed.size()), fixed.data(),
                                  scale, nullptr, nullptr));
    COAPT_PETSC_CHECK(VecScale(free_residual_, -1.0));
    try {
      const int setups = report.preconditioner_setups;
      const int linear = solve_correction(time, fixed, report);
      report.linear_iterations += linear;
      // a 3D Newton iteration can take minutes: one line each (--log-level debug)
      log::debug("fluid Newton, {}: iteration {}, |R| {:.3e}, {} linear iterations{}", label,
                 iteration + 1, norm, linear,
                 report.preconditioner_setups > setups ? " (new preconditioner)" : "");
    } catch (const ConvergenceError& error) {
      throw ConvergenceError(fmt::format("fluid Newton, {}, iteration {}: {}; residual history {}",
                                         label, iteration + 1, error.what(),
                                         format_history(report.residual_history)));
    }
    COAPT_PETSC_CHECK(VecAXPY(state_, 1.0, correction_));
    fem::update_ghosts(state_);
    if (parameters_.newton_line_search > 0) {
      // newton.line_search: halve the correction while it raises ‖R‖ (fem/line_search.hpp)
      const auto evaluate = [&] {
        assemble_residual(time);
        return free_residual_norm();
      };
      evaluated = evaluate();
      if (!(*evaluated <= norm)) {
        const auto kept = fem::backtrack(
            parameters_.newton_line_search, 1.0, *evaluated, norm,
            [&](double from, double to) {
              COAPT_PETSC_CHECK(VecAXPY(state_, to - from, correction_));
              fem::update_ghosts(state_);
            },
            evaluate);
        log::debug("fluid Newton: correction scaled by {:g} (|R| {:.3e} -> {:.3e})", kept.length,
                   norm, kept.norm);
        evaluated = kept.norm;
      }
    }
    report.iterations = iteration + 1;
  }
  return report;
}

std::vector<double> NavierStokes::boundary_force(int tag, const TimeLevel& time) {
  assemble_residual(time);
  const int dim = mesh_.dim, n = dim + 1;
  std::vector<char> on_boundary(static_cast<std::size_t>(mesh_.n_owned_vertices), 0);
  for (int f = 0; f < mesh_.n_facets(); ++f) {
    if (mesh_.facet_tags[f] != tag) continue;
    for (int a = 0; a < dim; ++a) {
      const int v = mesh_.facets[static_cast<std::size_t>(f) * dim + a];
      if (v < mesh_.n_owned_vertices) on_boundary[v] = 1;
    }
  }
  std::vector<double> force(static_cast<std::size_t>(dim), 0.0);
  {
    fem::LocalValues residual(residual_);
    for (int v = 0; v < mesh_.n_owned_vertices; ++v)
      if (on_boundary[v])
        for (int i = 0; i < dim; ++i) force[i] -= residual[static_cast<std::size_t>(v) * n + i];
  }
  MPI_Allreduce(MPI_IN_PLACE, force.data(), dim, MPI_DOUBLE, MPI_SUM, mesh_.comm);
  return force;
}

std::vector<double> NavierStokes::vertex_reactions(const TimeLevel& time) {
  assemble_residual(time);
  const int dim = mesh_.dim, n = dim + 1;
  const auto fixed = all_fixed_dofs();  // sorted global dofs
  OwnedVec reactions = fem::create_vertex_vector(mesh_, dim);
  COAPT_PETSC_CHECK(VecSet(reactions, 0.0));
  {
    fem::LocalValues residual(residual_);
    PetscScalar* values = nullptr;
    COAPT_PETSC_CHECK(VecGetArray(reactions, &values));
    for (int v = 0; v < mesh_.n_owned_vertices; ++v)
      for (int i = 0; i < dim; ++i)
        if (std::binary_search(fixed.begin(), fixed.end(),
                               static_cast<PetscInt>(mesh_.global_vertex[v] * n + i)))
          values[static_cast<std::size_t>(v) * dim + i] =
              -residual[static_cast<std::size_t>(v) * n + i];
    // the penalty's vertices: its force (the residual there includes the penalty itself)
    const auto penalty = penalty_reactions(time);
    for (std::size_t k = 0; k < penalty_vertices_.size(); ++k) {
      const auto v = static_cast<std::size_t>(penalty_vertices_[k]);
      for (int i = 0; i < dim; ++i) values[v * dim + i] = 0.0;
    }
    for (std::size_t k = 0; k < penalty_vertices_.size(); ++k) {
      const auto v = static_cast<std::size_t>(penalty_vertices_[k]);
      for (int i = 0; i < dim; ++i) values[v * dim + i] += penalty[k * dim + i];
    }
    COAPT_PETSC_CHECK(VecRestoreArray(reactions, &values));
  }
  fem::update_ghosts(reactions);
  fem::LocalValues local(reactions);
  const auto all = local.values();
  return {all.begin(), all.begin() + static_cast<std::ptrdiff_t>(mesh_.n_vertices()) * dim};
}

std::vector<double> NavierStokes::constraint_reactions(const TimeLevel& time) {
  assemble_residual(time);
  const int dim = mesh_.dim, n = dim + 1;
  std::vector<double> reactions;
  reactions.reserve(constrained_vertices_.size() * dim);
  fem::LocalValues residual(residual_);
  for (int v : constrained_vertices_)
    for (int i = 0; i < dim; ++i)
      reactions.push_back(-residual[static_cast<std::size_t>(v) * n + i]);
  return reactions;
}

}  // namespace coapt::fluid
