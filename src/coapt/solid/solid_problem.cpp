// The solid driver: setup (bodies, boundary conditions, loads, probes), then either per load
// step Newton's method on R(u) = f_int(u) − s f_ext = 0 with s = step/steps (static), or per
// time step Newton's method on M a(u) + f_int(u) − f_ext = 0 with Newmark's a(u) (dynamic,
// dynamics.hpp), and output.
#include "coapt/solid/solid_problem.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "coapt/core/context.hpp"
#include "coapt/core/log.hpp"
#include "coapt/core/progress.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/kernels.hpp"
#include "coapt/fem/linear_solver.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/io/json.hpp"
#include "coapt/mesh/mesh_input.hpp"
#include "coapt/solid/dynamics.hpp"
#include "coapt/solid/elements.hpp"
#include "coapt/solid/solid_parameters.hpp"

namespace coapt::solid {
namespace {

constexpr const char* kComponentNames[3] = {"x", "y", "z"};

/// A probe located in the reference mesh: the rank holding it keeps its cell and λ.
struct ProbeLocation {
  int owner = -1;  ///< rank that evaluates it (lowest rank with an owned cell containing it)
  int cell = -1;   ///< local cell on the owner
  std::vector<double> barycentric;
};

class SolidProblem final : public run::Problem {
 public:
  SolidProblem(const config::Section& root, MPI_Comm comm)
      : parameters_(SolidParameters::read(root)),
        comm_(comm),
        mesh_(mesh::load_mesh(parameters_.mesh, comm, &quality_)),
        dim_(mesh_.dim) {
    MPI_Comm_rank(comm_, &rank_);
    parameters_.check_dimension(dim_);
    assign_bodies();
    collect_dirichlet();
    locate_probes();
  }

  void describe() const override {
    log::info("solid: {} finite strain, P1 {}, {}",
              parameters_.time.dynamic ? "dynamic" : "quasi-static",
              dim_ == 2 ? "plane strain" : "3D", parameters_.mesh.describe());
    log::info("mesh: {} cells, {} vertices, {} rank(s); cell measure in [{:.3e}, {:.3e}]",
              mesh_.n_global_cells, mesh_.n_global_vertices, size_of(comm_), quality_.min_measure,
              quality_.max_measure);
    for (const auto& body : parameters_.bodies)
      log::info("body '{}': {}, density {:g} kg/m^3", body.name, name(body.material), body.density);
    if (parameters_.time.dynamic)
      log::info("Newmark (beta 1/4, gamma 1/2): {} steps of {:g} s to t = {:g} s",
                parameters_.time.n_steps, parameters_.time.step, parameters_.time.end_time);
    else
      log::info("{} load step(s)", parameters_.steps);
    log::info("Newton: relative tolerance {:g}, absolute {:g}, update {:g}, at most {} its",
              parameters_.newton.relative_tolerance, parameters_.newton.absolute_tolerance,
              parameters_.newton.update_tolerance, parameters_.newton.max_iterations);
  }

  void run(run::RunOutput& output) override {
    describe();
    if (parameters_.time.dynamic) {
      if (dim_ == 2)
        solve_dynamic<2>(output);
      else
        solve_dynamic<3>(output);
    } else if (dim_ == 2) {
      solve<2>(output);
    } else {
      solve<3>(output);
    }
  }

 private:
  // --- setup -------------------------------------------------------------------------------

  /// body_of_cell_[c] for every local cell; an InputError (on every rank) if an owned cell
  /// has no body or a group is not a cell group of the mesh.
  void assign_bodies() {
    body_of_cell_.assign(static_cast<std::size_t>(mesh_.n_cells()), -1);
    int catch_all = -1;
    for (std::size_t b = 0; b < parameters_.bodies.size(); ++b) {
      const auto& body = parameters_.bodies[b];
      if (body.cell_groups.empty()) catch_all = static_cast<int>(b);
      for (const auto& name : body.cell_groups) {
        const auto& group = mesh_.group(name);
        if (group.dim != dim_)
          throw InputError(fmt::format("{}: cell_groups: '{}' is not a cell group of {}",
                                       body.where, name, mesh_.source));
        for (int c = 0; c < mesh_.n_cells(); ++c)
          if (mesh_.cell_tags[c] == group.tag) body_of_cell_[c] = static_cast<int>(b);
      }
    }
    long unassigned = 0;
    for (int c = 0; c < mesh_.n_cells(); ++c)
      if (body_of_cell_[c] < 0) {
        if (catch_all >= 0)
          body_of_cell_[c] = catch_all;
        else if (c < mesh_.n_owned_cells)
          ++unassigned;
      }
    MPI_Allreduce(MPI_IN_PLACE, &unassigned, 1, MPI_LONG, MPI_SUM, comm_);
    if (unassigned > 0)
      throw InputError(
          fmt::format("{}: {} cell(s) of {} belong to no body (list their groups in "
                      "cell_groups, or leave one body without cell_groups)",
                      parameters_.bodies.front().where, unassigned, mesh_.source));
  }

  int facet_tag(const std::string& name, const std::string& where) const {
    const auto* group = mesh_.find_group(name);
    if (!group || group->dim != dim_ - 1) {
      std::string names;
      for (const auto& g : mesh_.groups)
        if (g.dim == dim_ - 1) names += (names.empty() ? "" : ", ") + g.name;
      throw InputError(fmt::format("{}: no boundary group '{}' in {} (it has: {})", where, name,
                                   mesh_.source, names.empty() ? "none" : names));
    }
    return group->tag;
  }

  /// The owned Dirichlet dofs with their final values (a later condition wins on a dof).
  void collect_dirichlet() {
    std::vector<std::pair<PetscInt, double>> prescribed;
    for (const auto& condition : parameters_.dirichlet) {
      const int tag = facet_tag(condition.boundary, condition.where);
      std::vector<int> components = condition.components;
      if (components.empty())
        for (int i = 0; i < dim_; ++i) components.push_back(i);
      for (std::size_t k = 0; k < components.size(); ++k) {
        const int component[1] = {components[k]};
        const double value = condition.values.empty() ? 0.0 : condition.values[k];
        for (PetscInt dof : fem::boundary_dofs(mesh_, dim_, tag, component))
          prescribed.emplace_back(dof, value);
      }
    }
    std::stable_sort(prescribed.begin(), prescribed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < prescribed.size(); ++i) {
      if (i + 1 < prescribed.size() && prescribed[i + 1].first == prescribed[i].first) continue;
      dirichlet_dofs_.push_back(prescribed[i].first);
      dirichlet_values_.push_back(prescribed[i].second);
    }
  }

  /// Barycentric coordinates of `point` in local cell c.
  std::vector<double> barycentric(int c, const std::vector<double>& point) const {
    Eigen::MatrixXd system(dim_ + 1, dim_ + 1);
    Eigen::VectorXd rhs(dim_ + 1);
    const auto vertices = mesh_.cell(c);
    for (int a = 0; a <= dim_; ++a) {
      system(0, a) = 1.0;
      for (int d = 0; d < dim_; ++d) system(d + 1, a) = mesh_.point(vertices[a])[d];
    }
    rhs(0) = 1.0;
    for (int d = 0; d < dim_; ++d) rhs(d + 1) = point[d];
    const Eigen::VectorXd lambda = system.partialPivLu().solve(rhs);
    return {lambda.data(), lambda.data() + lambda.size()};
  }

  /// Finds, for each probe, the lowest rank with an owned cell containing it. Collective.
  void locate_probes() {
    constexpr double tolerance = 1e-10;
    for (const auto& probe : parameters_.probes) {
      ProbeLocation location;
      for (int c = 0; c < mesh_.n_owned_cells && location.cell < 0; ++c) {
        auto lambda = barycentric(c, probe.point);
        if (*std::min_element(lambda.begin(), lambda.end()) >= -tolerance) {
          location.cell = c;
          location.barycentric = std::move(lambda);
        }
      }
      int candidate = location.cell >= 0 ? rank_ : std::numeric_limits<int>::max();
      MPI_Allreduce(&candidate, &location.owner, 1, MPI_INT, MPI_MIN, comm_);
      if (location.owner == std::numeric_limits<int>::max())
        throw InputError(fmt::format("{}: point ({}) lies in no cell of {}", probe.where,
                                     fmt::join(probe.point, ", "), mesh_.source));
      probes_.push_back(std::move(location));
    }
  }

  // --- assembly ------------------------------------------------------------------------------

  template <int Dim>
  fem::P1Geometry<Dim> geometry(int c) const {
    const double* points[Dim + 1];
    for (int a = 0; a <= Dim; ++a) points[a] = mesh_.point(mesh_.cell(c)[a]).data();
    return fem::p1_geometry<Dim>(points);
  }

  template <int Dim>
  NodalValues<Dim> nodal(const fem::LocalValues& u, int c) const {
    NodalValues<Dim> values;
    const auto vertices = mesh_.cell(c);
    for (int a = 0; a <= Dim; ++a)
      for (int i = 0; i < Dim; ++i)
        values(a, i) = u[static_cast<std::size_t>(vertices[a]) * Dim + i];
    return values;
  }

  const BodyParameters& body(int c) const { return parameters_.bodies[body_of_cell_[c]]; }

  /// The full external load f_ext (gravity and tractions at load factor 1). Collective.
  template <int Dim>
  void assemble_external_load(Vec load) {
    using VectorD = Eigen::Matrix<double, Dim, 1>;
    VectorD gravity = VectorD::Zero();
    for (std::size_t d = 0; d < parameters_.gravity.size(); ++d)
      gravity(d) = parameters_.gravity[d];
    // Tractions: per load, the owned-cell facets of its group (each facet counted once) and,
    // for a total force, the group's reference measure.
    std::vector<std::pair<int, VectorD>> facet_loads;  // facet, traction
    for (const auto& load : parameters_.tractions) {
      const int tag = facet_tag(load.boundary, load.where);
      double measure = 0;
      std::vector<int> facets;
      for (int f = 0; f < mesh_.n_facets(); ++f)
        if (mesh_.facet_tags[f] == tag && mesh_.facet_cell[f] < mesh_.n_owned_cells) {
          facets.push_back(f);
          measure += facet_measure<Dim>(f);
        }
      MPI_Allreduce(MPI_IN_PLACE, &measure, 1, MPI_DOUBLE, MPI_SUM, comm_);
      VectorD traction;
      for (int d = 0; d < Dim; ++d) traction(d) = load.vector[d];
      if (load.total) traction /= measure;
      log::info("traction on '{}' (measure {:.6g}): ({:.6g}) {}", load.boundary, measure,
                fmt::join(traction.data(), traction.data() + Dim, ", "), Dim == 2 ? "N/m^2" : "Pa");
      for (int f : facets) facet_loads.emplace_back(f, traction);
    }
    Vec local = nullptr;
    COAPT_PETSC_CHECK(VecSet(load, 0.0));
    COAPT_PETSC_CHECK(VecGhostGetLocalForm(load, &local));
    PetscScalar* data = nullptr;
    COAPT_PETSC_CHECK(VecGetArray(local, &data));
    for (int c = 0; c < mesh_.n_owned_cells; ++c) {
      const VectorD f =
          uniform_nodal_load<Dim>(body(c).density * gravity, geometry<Dim>(c).measure, Dim + 1);
      for (int v : mesh_.cell(c))
        for (int i = 0; i < Dim; ++i) data[static_cast<std::size_t>(v) * Dim + i] += f(i);
    }
    for (const auto& [f, traction] : facet_loads) {
      const VectorD nodal_force = uniform_nodal_load<Dim>(traction, facet_measure<Dim>(f), Dim);
      for (int a = 0; a < Dim; ++a)
        for (int i = 0; i < Dim; ++i)
          data[static_cast<std::size_t>(mesh_.facets[static_cast<std::size_t>(f) * Dim + a]) * Dim +
               i] += nodal_force(i);
    }
    COAPT_PETSC_CHECK(VecRestoreArray(local, &data));
    COAPT_PETSC_CHECK(VecGhostRestoreLocalForm(load, &local));
    fem::add_local_to_global(load);
  }

  template <int Dim>
  double facet_measure(int f) const {
    const int* v = mesh_.facets.data() + static_cast<std::size_t>(f) * Dim;
    if constexpr (Dim == 2) {
      const auto p = mesh_.point(v[0]), q = mesh_.point(v[1]);
      return std::hypot(q[0] - p[0], q[1] - p[1]);
    } else {
      Eigen::Vector3d p, q, r;
      for (int d = 0; d < 3; ++d) {
        p(d) = mesh_.point(v[0])[d];
        q(d) = mesh_.point(v[1])[d];
        r(d) = mesh_.point(v[2])[d];
      }
      return 0.5 * (q - p).cross(r - p).norm();
    }
  }

  /// R = f_int(u) − s f_ext (+ M a when `inertia` holds M a) with the Dirichlet rows zeroed;
  /// returns ‖R‖₂, or +∞ when some cell is inverted (det F ≤ 0 or not finite) on any rank.
  /// Collective.
  template <int Dim>
  double assemble_residual(Vec u, Vec external, double factor, Vec residual,
                           Vec inertia = nullptr) {
    double min_J = std::numeric_limits<double>::infinity();
    {
      fem::LocalValues values(u);
      fem::assemble_vector(mesh_, Dim, residual, [&](int c, double* element) {
        const auto g = geometry<Dim>(c);
        const NodalValues<Dim> displacement = nodal<Dim>(values, c);
        const double J = deformation_gradient<Dim>(g.gradients, displacement).determinant();
        min_J = std::isfinite(J) ? std::min(min_J, J) : -1.0;
        if (!(J > 0.0)) return;  // the whole residual is rejected below
        const auto r = element_residual<Dim>(g, body(c).material, body(c).fibres, displacement);
        std::copy(r.data(), r.data() + r.size(), element);
      });
    }
    MPI_Allreduce(MPI_IN_PLACE, &min_J, 1, MPI_DOUBLE, MPI_MIN, comm_);
    if (!(min_J > 0.0)) return std::numeric_limits<double>::infinity();
    COAPT_PETSC_CHECK(VecAXPY(residual, -factor, external));
    if (inertia) COAPT_PETSC_CHECK(VecAXPY(residual, 1.0, inertia));
    PetscScalar* data = nullptr;
    COAPT_PETSC_CHECK(VecGetArray(residual, &data));
    for (PetscInt dof : dirichlet_dofs_) data[dof - mesh_.vertex_offset * Dim] = 0.0;
    COAPT_PETSC_CHECK(VecRestoreArray(residual, &data));
    PetscReal norm = 0;
    COAPT_PETSC_CHECK(VecNorm(residual, NORM_2, &norm));
    return std::isfinite(norm) ? norm : std::numeric_limits<double>::infinity();
  }

  template <int Dim>
  void assemble_tangent(Vec u, fem::P1Matrix& matrix) {
    fem::LocalValues values(u);
    matrix.assemble([&](int c, double* element) {
      const auto K = element_tangent<Dim>(geometry<Dim>(c), body(c).material, body(c).fibres,
                                          nodal<Dim>(values, c));
      std::copy(K.data(), K.data() + K.size(), element);
    });
  }

  // --- the load-stepping Newton loop ---------------------------------------------------------

  /// What one Newton solve did.
  struct NewtonReport {
    int iterations = 0;
    int linear_iterations = 0;
    double norm = 0;  ///< final |R|
  };

  /// Newton on R(u) = 0 from the current u (ghosts current) whose residual norm is
  /// history.back(): `jacobian()` assembles the tangent into `matrix`, `residual_norm()`
  /// re-evaluates R(u) into `residual` and returns |R| (+∞ when a cell inverts). Each update
  /// is halved while it inverts a cell; the update's Dirichlet entries are zeroed so that the
  /// prescribed dofs stay exactly as set (an iterative solve leaves round-off there). Stops at
  /// |R| ≤ max(rtol |R0|, atol) or ‖δu‖ ≤ dtol ‖u‖: the residual of a stiff, thin body bottoms
  /// out at the round-off of the internal forces (ε times element forces that cancel at each
  /// vertex). `where` names the step in messages, `remedy` what to try when every step inverts
  /// a cell; `verbose` logs every iteration at info level (else debug). Collective.
  template <int Dim, class Jacobian, class ResidualNorm>
  NewtonReport newton_solve(run::RunOutput& output, Vec u, Vec residual, fem::P1Matrix& matrix,
                            fem::LinearSolver& solver, Jacobian&& jacobian,
                            ResidualNorm&& residual_norm, std::vector<double>& history,
                            const std::string& where, const std::string& remedy, bool verbose) {
    const auto& newton = parameters_.newton;
    auto rhs = fem::create_vertex_vector(mesh_, Dim);
    auto update = fem::create_vertex_vector(mesh_, Dim);
    auto zero = fem::create_vertex_vector(mesh_, Dim);
    NewtonReport report;
    report.norm = history.back();
    const double tolerance =
        std::max(newton.relative_tolerance * history.front(), newton.absolute_tolerance);
    bool small_update = false;
    while (report.norm > tolerance && !small_update) {
      if (report.iterations == newton.max_iterations)
        throw ConvergenceError(
            fmt::format("solid: Newton did not converge in {} within {} iterations: |R| = [{:.3e}] "
                        "(tolerance {:.3e})",
                        where, newton.max_iterations, fmt::join(history, ", "), tolerance));
      ++report.iterations;
      {
        ScopedTimer timer(output.timers(), "assemble");
        jacobian();
        COAPT_PETSC_CHECK(VecCopy(residual, rhs));
        COAPT_PETSC_CHECK(VecScale(rhs, -1.0));
        fem::apply_dirichlet(matrix.mat(), rhs, dirichlet_dofs_, zero);
      }
      fem::SolveStats stats;
      {
        ScopedTimer timer(output.timers(), "solve");
        solver.set_operator(matrix.mat());
        COAPT_PETSC_CHECK(VecSet(update, 0.0));
        stats = solver.solve(rhs, update);
      }
      set_dirichlet<Dim>(update, false);
      report.linear_iterations += stats.iterations;
      double step_length = 1.0;
      COAPT_PETSC_CHECK(VecAXPY(u, step_length, update));
      fem::update_ghosts(u);
      report.norm = residual_norm();
      for (int halving = 0; !std::isfinite(report.norm) && halving < 12; ++halving) {
        step_length *= 0.5;
        COAPT_PETSC_CHECK(VecAXPY(u, -step_length, update));
        fem::update_ghosts(u);
        report.norm = residual_norm();
      }
      if (!std::isfinite(report.norm))
        throw ConvergenceError(
            fmt::format("solid: {}: every Newton step inverts a cell (|R| history [{:.3e}]); {}",
                        where, fmt::join(history, ", "), remedy));
      history.push_back(report.norm);
      PetscReal update_norm = 0, u_norm = 0;
      COAPT_PETSC_CHECK(VecNorm(update, NORM_2, &update_norm));
      COAPT_PETSC_CHECK(VecNorm(u, NORM_2, &u_norm));
      small_update = step_length * update_norm <= newton.update_tolerance * u_norm;
      const std::string line = fmt::format(
          "{}: newton {}  |R| = {:.6e}  (|R|/|R0| = {:.3e}, |du|/|u| = {:.3e}, step {:g}, {} "
          "linear its)",
          where, report.iterations, report.norm, report.norm / history.front(),
          step_length * update_norm / u_norm, step_length, stats.iterations);
      if (verbose)
        log::info("{}", line);
      else
        log::debug("{}", line);
    }
    return report;
  }

  template <int Dim>
  void solve(run::RunOutput& output) {
    auto u = fem::create_vertex_vector(mesh_, Dim);
    auto external = fem::create_vertex_vector(mesh_, Dim);
    auto residual = fem::create_vertex_vector(mesh_, Dim);
    fem::P1Matrix matrix(mesh_, Dim);
    fem::set_rigid_body_modes(mesh_, matrix.mat());
    // GMRES rather than CG: the tangent is symmetric but loses definiteness near buckling.
    fem::LinearSolver solver(comm_, "solid_", {"gmres", "gamg", 1e-10, 1e-50, 2000});
    assemble_external_load<Dim>(external);
    log::info("linear solver: {}", solver.describe());

    int total_newton = 0, total_linear = 0;
    for (int step = 1; step <= parameters_.steps; ++step) {
      const double factor = static_cast<double>(step) / parameters_.steps;
      {  // prescribed displacements at this load factor
        PetscScalar* data = nullptr;
        COAPT_PETSC_CHECK(VecGetArray(u, &data));
        for (std::size_t k = 0; k < dirichlet_dofs_.size(); ++k)
          data[dirichlet_dofs_[k] - mesh_.vertex_offset * Dim] = factor * dirichlet_values_[k];
        COAPT_PETSC_CHECK(VecRestoreArray(u, &data));
        fem::update_ghosts(u);
      }
      std::vector<double> history;
      double norm = 0;
      {
        ScopedTimer timer(output.timers(), "assemble");
        norm = assemble_residual<Dim>(u, external, factor, residual);
      }
      if (!std::isfinite(norm))
        throw ConvergenceError(
            fmt::format("solid: load step {}/{}: the prescribed displacements invert a cell", step,
                        parameters_.steps));
      history.push_back(norm);
      log::info("step {}/{} (load factor {:.4g}): newton 0  |R| = {:.6e}", step, parameters_.steps,
                factor, norm);
      const auto report = newton_solve<Dim>(
          output, u, residual, matrix, solver, [&] { assemble_tangent<Dim>(u, matrix); },
          [&] {
            ScopedTimer timer(output.timers(), "assemble");
            return assemble_residual<Dim>(u, external, factor, residual);
          },
          history,
          fmt::format("load step {}/{} (load factor {:g})", step, parameters_.steps, factor),
          "use more load steps", true);
      const int iteration = report.iterations;
      norm = report.norm;
      total_linear += report.linear_iterations;
      total_newton += iteration;
      const auto values = probe_values<Dim>(u);
      auto& series = output.series();
      series.add("step", step);
      series.add("load_factor", factor);
      series.add("newton_iterations", iteration);
      series.add("residual_norm", norm);
      for (std::size_t p = 0; p < values.size(); ++p)
        for (int i = 0; i < Dim; ++i)
          series.add(parameters_.probes[p].name + "_displacement_" + kComponentNames[i],
                     values[p][i]);
      series.end_row();
      if (parameters_.write_vtk) write_vtk<Dim>(output, u, factor);
    }

    const auto values = probe_values<Dim>(u);
    auto& benchmark = output.summary()["benchmark"];
    for (std::size_t p = 0; p < values.size(); ++p)
      for (int i = 0; i < Dim; ++i) {
        const std::string key = parameters_.probes[p].name + "_displacement_" + kComponentNames[i];
        benchmark[key] = values[p][i];
        log::info("{} = {:.8e} m", key, values[p][i]);
      }
    benchmark["cells"] = static_cast<std::int64_t>(mesh_.n_global_cells);
    benchmark["vertices"] = static_cast<std::int64_t>(mesh_.n_global_vertices);
    benchmark["level"] = parameters_.mesh.level;
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = total_newton;
    iterations["linear"] = total_linear;
  }

  // --- the Newmark time loop ------------------------------------------------------------------

  /// Writes ρ M_ab δ_ij (consistent P1 mass, node-major) of cell c into `element`, scaled.
  template <int Dim>
  void add_element_mass(int c, double scale, double* element) const {
    constexpr int n = (Dim + 1) * Dim;
    const auto mass = fem::element_mass<Dim>(geometry<Dim>(c));
    const double factor = scale * body(c).density;
    for (int a = 0; a <= Dim; ++a)
      for (int b = 0; b <= Dim; ++b)
        for (int i = 0; i < Dim; ++i)
          element[(a * Dim + i) * n + b * Dim + i] += factor * mass(a, b);
  }

  /// ∫ ψ(F) dX over the owned cells, summed over ranks [J, or J/m in 2D]. Collective.
  template <int Dim>
  double strain_energy(Vec u) const {
    fem::LocalValues values(u);
    double sum = 0;
    for (int c = 0; c < mesh_.n_owned_cells; ++c) {
      const auto g = geometry<Dim>(c);
      const MatrixD<Dim> F = deformation_gradient<Dim>(g.gradients, nodal<Dim>(values, c));
      if constexpr (Dim == 2)
        sum += g.measure * plane_strain::energy(body(c).material, F, body(c).fibres);
      else
        sum += g.measure * solid::energy(body(c).material, F, body(c).fibres);
    }
    MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm_);
    return sum;
  }

  /// Sets the Dirichlet dofs of `vector` to their values (or to zero). Ghosts not updated.
  template <int Dim>
  void set_dirichlet(Vec vector, bool values) {
    PetscScalar* data = nullptr;
    COAPT_PETSC_CHECK(VecGetArray(vector, &data));
    for (std::size_t k = 0; k < dirichlet_dofs_.size(); ++k)
      data[dirichlet_dofs_[k] - mesh_.vertex_offset * Dim] = values ? dirichlet_values_[k] : 0.0;
    COAPT_PETSC_CHECK(VecRestoreArray(vector, &data));
  }

  /// Newmark (β = 1/4, γ = 1/2) from u₀ (Dirichlet values, else 0), v₀ (the initial velocity
  /// on the free dofs) and M a₀ = f_ext − f_int(u₀); per step Newton's method on
  /// R(u) = M a(u) + f_int(u) − f_ext with tangent 4/Δt² M + K(u). Collective.
  template <int Dim>
  void solve_dynamic(run::RunOutput& output) {
    const auto& time = parameters_.time;
    const auto& newton = parameters_.newton;
    const Newmark scheme{time.step};
    auto u = fem::create_vertex_vector(mesh_, Dim);
    auto u_old = fem::create_vertex_vector(mesh_, Dim);
    auto v = fem::create_vertex_vector(mesh_, Dim);
    auto a = fem::create_vertex_vector(mesh_, Dim);
    auto a_old = fem::create_vertex_vector(mesh_, Dim);
    auto inertia = fem::create_vertex_vector(mesh_, Dim);
    auto external = fem::create_vertex_vector(mesh_, Dim);
    auto residual = fem::create_vertex_vector(mesh_, Dim);
    auto rhs = fem::create_vertex_vector(mesh_, Dim);
    auto zero = fem::create_vertex_vector(mesh_, Dim);
    fem::P1Matrix mass(mesh_, Dim);
    fem::P1Matrix matrix(mesh_, Dim);
    fem::set_rigid_body_modes(mesh_, matrix.mat());
    // A direct solver by default: every Newton iteration of every step factors a new matrix
    // anyway, and on thin bodies (the Turek–Hron bar) GMRES + GAMG needs hundreds of
    // iterations per solve and stalls in the last Newton iterations. -solid_ksp_type gmres
    // -solid_pc_type gamg brings the iterative solver back.
    fem::LinearSolver solver(comm_, "solid_", {"preonly", "lu", 1e-10, 1e-50, 2000});
    {
      PetscBool given = PETSC_FALSE;
      COAPT_PETSC_CHECK(
          PetscOptionsHasName(nullptr, "solid_", "-pc_factor_mat_solver_type", &given));
      PC pc = nullptr;
      COAPT_PETSC_CHECK(KSPGetPC(solver.ksp(), &pc));
      if (!given) COAPT_PETSC_CHECK(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    }
    assemble_external_load<Dim>(external);
    log::info("linear solver: {}", solver.describe());
    constexpr int n_element = (Dim + 1) * Dim * (Dim + 1) * Dim;
    mass.assemble([&](int c, double* element) {
      std::fill(element, element + n_element, 0.0);
      add_element_mass<Dim>(c, 1.0, element);
    });

    // Initial state.
    COAPT_PETSC_CHECK(VecSet(u, 0.0));
    set_dirichlet<Dim>(u, true);
    fem::update_ghosts(u);
    {
      PetscScalar* data = nullptr;
      PetscInt n_local = 0;
      COAPT_PETSC_CHECK(VecGetLocalSize(v, &n_local));
      COAPT_PETSC_CHECK(VecGetArray(v, &data));
      for (PetscInt k = 0; k < n_local; ++k)
        data[k] = time.initial_velocity.empty() ? 0.0 : time.initial_velocity[k % Dim];
      COAPT_PETSC_CHECK(VecRestoreArray(v, &data));
      set_dirichlet<Dim>(v, false);
    }
    int total_linear = 0, total_newton = 0;
    {  // M a₀ = f_ext − f_int(u₀) on the free dofs, a₀ = 0 on the Dirichlet ones
      const double norm = assemble_residual<Dim>(u, external, 1.0, residual);
      if (!std::isfinite(norm))
        throw ConvergenceError("solid: the prescribed displacements invert a cell at t = 0");
      matrix.assemble([&](int c, double* element) {
        std::fill(element, element + n_element, 0.0);
        add_element_mass<Dim>(c, 1.0, element);
      });
      COAPT_PETSC_CHECK(VecCopy(residual, rhs));
      COAPT_PETSC_CHECK(VecScale(rhs, -1.0));
      fem::apply_dirichlet(matrix.mat(), rhs, dirichlet_dofs_, zero);
      solver.set_operator(matrix.mat());
      COAPT_PETSC_CHECK(VecSet(a_old, 0.0));
      total_linear += solver.solve(rhs, a_old).iterations;
      set_dirichlet<Dim>(a_old, false);
    }

    // Energies: kinetic ½ vᵀMv, strain ∫ψ, work of the (constant) loads f_extᵀu.
    std::vector<double> times;
    std::vector<std::vector<double>> probe_history(probes_.size() * Dim);
    double initial_energy = 0, energy_scale = 0, largest_change = 0;
    const auto record = [&](int step, double t, int iterations, Vec velocity) {
      COAPT_PETSC_CHECK(MatMult(mass.mat(), velocity, inertia));
      PetscScalar twice_kinetic = 0, work = 0;
      COAPT_PETSC_CHECK(VecDot(velocity, inertia, &twice_kinetic));
      COAPT_PETSC_CHECK(VecDot(external, u, &work));
      const double kinetic = 0.5 * twice_kinetic, strain = strain_energy<Dim>(u);
      const double total = kinetic + strain - work;
      if (step == 0) initial_energy = total;
      energy_scale = std::max(energy_scale, kinetic + strain);
      largest_change = std::max(largest_change, std::abs(total - initial_energy));
      const auto values = probe_values<Dim>(u);
      times.push_back(t);
      auto& series = output.series();
      series.add("step", step);
      series.add("time", t);
      for (std::size_t p = 0; p < values.size(); ++p)
        for (int i = 0; i < Dim; ++i) {
          series.add(parameters_.probes[p].name + "_displacement_" + kComponentNames[i],
                     values[p][i]);
          probe_history[p * Dim + i].push_back(values[p][i]);
        }
      series.add("kinetic_energy", kinetic);
      series.add("strain_energy", strain);
      series.add("external_work", work);
      series.add("total_energy", total);
      series.add("newton_iterations", iterations);
      series.end_row();
    };
    record(0, 0.0, 0, v);
    if (parameters_.write_vtk) write_vtk<Dim>(output, u, 0.0);

    // a(u) into `a` and M a(u) into `inertia`, from u and the old state (u_old, v, a_old).
    const auto update_inertia = [&]() {
      const PetscScalar *un = nullptr, *vn = nullptr, *an = nullptr, *un1 = nullptr;
      PetscScalar* acceleration = nullptr;
      PetscInt n_local = 0;
      COAPT_PETSC_CHECK(VecGetLocalSize(u, &n_local));
      COAPT_PETSC_CHECK(VecGetArrayRead(u, &un1));
      COAPT_PETSC_CHECK(VecGetArrayRead(u_old, &un));
      COAPT_PETSC_CHECK(VecGetArrayRead(v, &vn));
      COAPT_PETSC_CHECK(VecGetArrayRead(a_old, &an));
      COAPT_PETSC_CHECK(VecGetArray(a, &acceleration));
      for (PetscInt k = 0; k < n_local; ++k)
        acceleration[k] = scheme.acceleration(un1[k], un[k], vn[k], an[k]);
      COAPT_PETSC_CHECK(VecRestoreArray(a, &acceleration));
      COAPT_PETSC_CHECK(VecRestoreArrayRead(a_old, &an));
      COAPT_PETSC_CHECK(VecRestoreArrayRead(v, &vn));
      COAPT_PETSC_CHECK(VecRestoreArrayRead(u_old, &un));
      COAPT_PETSC_CHECK(VecRestoreArrayRead(u, &un1));
      COAPT_PETSC_CHECK(MatMult(mass.mat(), a, inertia));
    };
    const auto residual_norm = [&]() {
      update_inertia();
      ScopedTimer timer(output.timers(), "assemble");
      return assemble_residual<Dim>(u, external, 1.0, residual, inertia);
    };

    Progress progress(time.n_steps, time.end_time);
    std::vector<double> history;
    history.reserve(static_cast<std::size_t>(newton.max_iterations) + 1);
    for (int step = 1; step <= time.n_steps; ++step) {
      const double t = step * time.step;
      COAPT_PETSC_CHECK(VecCopy(u, u_old));
      {  // predictor u = u_n + Δt v_n + Δt²/2 a_n (Dirichlet dofs: v = a = 0, u stays)
        PetscScalar* un1 = nullptr;
        const PetscScalar *vn = nullptr, *an = nullptr;
        PetscInt n_local = 0;
        COAPT_PETSC_CHECK(VecGetLocalSize(u, &n_local));
        COAPT_PETSC_CHECK(VecGetArray(u, &un1));
        COAPT_PETSC_CHECK(VecGetArrayRead(v, &vn));
        COAPT_PETSC_CHECK(VecGetArrayRead(a_old, &an));
        for (PetscInt k = 0; k < n_local; ++k) un1[k] = scheme.predictor(un1[k], vn[k], an[k]);
        COAPT_PETSC_CHECK(VecRestoreArrayRead(a_old, &an));
        COAPT_PETSC_CHECK(VecRestoreArrayRead(v, &vn));
        COAPT_PETSC_CHECK(VecRestoreArray(u, &un1));
        fem::update_ghosts(u);
      }
      history.clear();
      double norm = residual_norm();
      if (!std::isfinite(norm)) {  // the predictor inverts a cell: start from u_n instead
        COAPT_PETSC_CHECK(VecCopy(u_old, u));
        fem::update_ghosts(u);
        norm = residual_norm();
      }
      history.push_back(norm);
      const auto report = newton_solve<Dim>(
          output, u, residual, matrix, solver,
          [&] {
            fem::LocalValues values(u);
            matrix.assemble([&](int c, double* element) {
              const auto K = element_tangent<Dim>(geometry<Dim>(c), body(c).material,
                                                  body(c).fibres, nodal<Dim>(values, c));
              std::copy(K.data(), K.data() + K.size(), element);
              add_element_mass<Dim>(c, scheme.mass_factor(), element);
            });
          },
          residual_norm, history, fmt::format("time step {} (t = {:g} s)", step, t),
          "use a smaller time step", false);
      const int iteration = report.iterations, linear = report.linear_iterations;
      norm = report.norm;
      total_newton += iteration;
      total_linear += linear;
      // v_{n+1} = v_n + Δt/2 (a_n + a_{n+1}); `a` holds a(u_{n+1}) from the last residual.
      {
        PetscScalar *vn = nullptr, *an = nullptr;
        const PetscScalar* an1 = nullptr;
        PetscInt n_local = 0;
        COAPT_PETSC_CHECK(VecGetLocalSize(v, &n_local));
        COAPT_PETSC_CHECK(VecGetArray(v, &vn));
        COAPT_PETSC_CHECK(VecGetArray(a_old, &an));
        COAPT_PETSC_CHECK(VecGetArrayRead(a, &an1));
        for (PetscInt k = 0; k < n_local; ++k) {
          vn[k] = scheme.velocity(vn[k], an[k], an1[k]);
          an[k] = an1[k];
        }
        COAPT_PETSC_CHECK(VecRestoreArrayRead(a, &an1));
        COAPT_PETSC_CHECK(VecRestoreArray(a_old, &an));
        COAPT_PETSC_CHECK(VecRestoreArray(v, &vn));
      }
      record(step, t, iteration, v);
      progress.step(step, t,
                    fmt::format("newton {} (|R| {:.2e} -> {:.2e}), ksp {}", iteration,
                                history.front(), norm, linear));
      if (parameters_.write_vtk && step % parameters_.vtk_interval == 0)
        write_vtk<Dim>(output, u, t);
    }

    auto& benchmark = output.summary()["benchmark"];
    for (std::size_t p = 0; p < probes_.size(); ++p)
      for (int i = 0; i < Dim; ++i) {
        const std::string key = (p == 0 ? std::string() : parameters_.probes[p].name + "_") +
                                "displacement_" + kComponentNames[i];
        const OscillationSummary summary = last_period(times, probe_history[p * Dim + i]);
        const auto number = [](double x) { return std::isfinite(x) ? io::Json(x) : io::Json(); };
        auto& entry = benchmark[key];
        entry["mean"] = number(summary.mean);
        entry["amplitude"] = number(summary.amplitude);
        entry["frequency"] = number(summary.frequency);
        entry["periods"] = summary.periods;
        entry["final"] = probe_history[p * Dim + i].back();
        log::info(
            "{} {}: mean {:.6e} m, amplitude {:.6e} m, frequency {:.6g} Hz ({} full "
            "period(s) seen)",
            parameters_.probes[p].name, key, summary.mean, summary.amplitude, summary.frequency,
            summary.periods);
      }
    const double drift = energy_scale > 0 ? largest_change / energy_scale : 0.0;
    benchmark["energy_initial"] = initial_energy;
    benchmark["energy_scale"] = energy_scale;
    benchmark["energy_max_relative_change"] = drift;
    log::info("total energy: initial {:.10e}, max |E - E0| / max(kinetic + strain) = {:.3e}",
              initial_energy, drift);
    benchmark["cells"] = static_cast<std::int64_t>(mesh_.n_global_cells);
    benchmark["vertices"] = static_cast<std::int64_t>(mesh_.n_global_vertices);
    benchmark["level"] = parameters_.mesh.level;
    benchmark["time_step"] = time.step;
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = total_newton;
    iterations["linear"] = total_linear;
  }

  /// Displacement at each probe (every rank gets every value). Collective.
  template <int Dim>
  std::vector<std::vector<double>> probe_values(Vec u) const {
    std::vector<std::vector<double>> result;
    fem::LocalValues values(u);
    for (const auto& probe : probes_) {
      std::vector<double> value(Dim, 0.0);
      if (probe.owner == rank_) {
        const auto vertices = mesh_.cell(probe.cell);
        for (int a = 0; a <= Dim; ++a)
          for (int i = 0; i < Dim; ++i)
            value[i] +=
                probe.barycentric[a] * values[static_cast<std::size_t>(vertices[a]) * Dim + i];
      }
      MPI_Bcast(value.data(), Dim, MPI_DOUBLE, probe.owner, comm_);
      result.push_back(std::move(value));
    }
    return result;
  }

  /// Displacement (vertices), Cauchy stress (3×3 per cell, σ₃₃ included in plane strain),
  /// von Mises stress and det F (cells), at "time" = the load factor. Collective.
  template <int Dim>
  void write_vtk(run::RunOutput& output, Vec u, double factor) const {
    ScopedTimer timer(output.timers(), "output");
    fem::LocalValues values(u);
    const std::size_t n_cells = static_cast<std::size_t>(mesh_.n_owned_cells);
    std::vector<double> stress(n_cells * 9), von_mises_stress(n_cells), volume_ratio(n_cells),
        body_index(n_cells);
    for (int c = 0; c < mesh_.n_owned_cells; ++c) {
      const MatrixD<Dim> F =
          deformation_gradient<Dim>(geometry<Dim>(c).gradients, nodal<Dim>(values, c));
      const Matrix3 sigma = cauchy_stress<Dim>(body(c).material, F, body(c).fibres);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          stress[static_cast<std::size_t>(c) * 9 + 3 * i + j] = sigma(i, j);
      von_mises_stress[c] = von_mises(sigma);
      volume_ratio[c] = F.determinant();
      body_index[c] = body_of_cell_[c];
    }
    const std::vector<io::Field> fields = {
        {"displacement", Dim, io::Field::Location::vertex, values.values()},
        {"cauchy_stress", 9, io::Field::Location::cell, stress},
        {"von_mises_stress", 1, io::Field::Location::cell, von_mises_stress},
        {"volume_ratio", 1, io::Field::Location::cell, volume_ratio},
        {"body", 1, io::Field::Location::cell, body_index},
    };
    output.vtk("solid").write(mesh_, factor, fields);
  }

  const SolidParameters parameters_;
  MPI_Comm comm_;
  mesh::QualityReport quality_;
  mesh::Mesh mesh_;
  int dim_;
  int rank_ = 0;
  std::vector<int> body_of_cell_;
  std::vector<PetscInt> dirichlet_dofs_;  ///< owned, sorted
  std::vector<double> dirichlet_values_;  ///< final value of each, [m]
  std::vector<ProbeLocation> probes_;
};

}  // namespace

std::unique_ptr<run::Problem> create_solid_problem(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<SolidProblem>(root, comm);
}

}  // namespace coapt::solid
