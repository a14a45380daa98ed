#include "coapt/fluid/navier_stokes.hpp"

#include <fmt/format.h>
#include <petscksp.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "coapt/core/error.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fluid/kernels.hpp"

namespace coapt::fluid {
namespace {

/// Direct solve (LU through MUMPS, which runs on any number of ranks) inside GMRES: robust for
/// the non-symmetric saddle-point Jacobian with its PSPG pressure block; GMRES reports the
/// iterations (1 with an exact factorisation) and keeps -fluid_pc_type fieldsplit etc. usable.
fem::LinearSolverDefaults solver_defaults() {
  fem::LinearSolverDefaults defaults;
  defaults.ksp_type = "gmres";
  defaults.pc_type = "lu";
  defaults.relative_tolerance = 1e-10;
  defaults.absolute_tolerance = 1e-14;
  defaults.max_iterations = 1000;
  return defaults;
}

std::string format_history(const std::vector<double>& history) {
  std::string text;
  for (std::size_t k = 0; k < history.size(); ++k)
    text += fmt::format("{}{:.3e}", k ? ", " : "", history[k]);
  return text;
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
      solver_(mesh.comm, "fluid_", solver_defaults()) {
  if (mesh.dim != 2 && mesh.dim != 3)
    throw InputError(fmt::format("{}: the fluid solver needs a 2D or 3D mesh", mesh.source));
  PetscBool given = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscOptionsHasName(nullptr, nullptr, "-fluid_pc_factor_mat_solver_type", &given));
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(solver_.ksp(), &pc));
  PCType type = nullptr;
  COAPT_PETSC_CHECK(PCGetType(pc, &type));
  if (!given && type && std::string(type) == PCLU)
    COAPT_PETSC_CHECK(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  // Rows of fixed dofs are zeroed in place: the CSR pattern P1Matrix writes into must stay.
  COAPT_PETSC_CHECK(MatSetOption(matrix_.mat(), MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
}

void NavierStokes::set_dirichlet_dofs(std::vector<PetscInt> dofs) {
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  dirichlet_dofs_ = std::move(dofs);
}

void NavierStokes::set_velocity_constraint(std::span<const int> vertices,
                                           std::span<const double> velocities) {
  const int dim = mesh_.dim, n = dim + 1;
  if (velocities.size() != vertices.size() * static_cast<std::size_t>(dim))
    throw InternalError("set_velocity_constraint: velocities must be vertices × dim");
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
    set_stabilisation<Dim>(data, mean, time.time_step, parameters_.c_inverse);
  };
  fem::assemble_vector(mesh_, n, residual_, [&](int c, double* r) {
    ElementData<Dim> data;
    double x[m];
    element(c, data, x);
    element_residual<Dim, double>(data, x, r);
  });
  if (with_matrix)
    matrix_.assemble([&](int c, double* K) {
      ElementData<Dim> data;
      double x[m];
      element(c, data, x);
      element_residual_and_jacobian<Dim>(data, x, nullptr, K);
    });
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
  for (int iteration = 0;; ++iteration) {
    assemble_residual(time);
    const double norm = free_residual_norm();
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
    COAPT_PETSC_CHECK(VecSet(correction_, 0.0));
    solver_.set_operator(matrix_.mat());
    try {
      const auto stats = solver_.solve(free_residual_, correction_);
      report.linear_iterations += stats.iterations;
    } catch (const ConvergenceError& error) {
      throw ConvergenceError(fmt::format("fluid Newton, {}, iteration {}: {}; residual history {}",
                                         label, iteration + 1, error.what(),
                                         format_history(report.residual_history)));
    }
    COAPT_PETSC_CHECK(VecAXPY(state_, 1.0, correction_));
    fem::update_ghosts(state_);
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
