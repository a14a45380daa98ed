// The quasi-static solid driver: setup (bodies, boundary conditions, loads, probes), then per
// load step Newton's method on R(u) = f_int(u) − s f_ext = 0 with s = step/steps, and output.
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
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/linear_solver.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/mesh/mesh_input.hpp"
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
    log::info("solid: quasi-static finite strain, P1 {}, {}", dim_ == 2 ? "plane strain" : "3D",
              parameters_.mesh.describe());
    log::info("mesh: {} cells, {} vertices, {} rank(s); cell measure in [{:.3e}, {:.3e}]",
              mesh_.n_global_cells, mesh_.n_global_vertices, size_of(comm_), quality_.min_measure,
              quality_.max_measure);
    for (const auto& body : parameters_.bodies)
      log::info("body '{}': {}, density {:g} kg/m^3", body.name, name(body.material), body.density);
    log::info("{} load step(s); Newton: relative tolerance {:g}, absolute {:g}, at most {} its",
              parameters_.steps, parameters_.newton.relative_tolerance,
              parameters_.newton.absolute_tolerance, parameters_.newton.max_iterations);
  }

  void run(run::RunOutput& output) override {
    describe();
    if (dim_ == 2)
      solve<2>(output);
    else
      solve<3>(output);
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

  /// R = f_int(u) − s f_ext with the Dirichlet rows zeroed; returns ‖R‖₂, or +∞ when some
  /// cell is inverted (det F ≤ 0 or not finite) on any rank. Collective.
  template <int Dim>
  double assemble_residual(Vec u, Vec external, double factor, Vec residual) {
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

  template <int Dim>
  void solve(run::RunOutput& output) {
    auto u = fem::create_vertex_vector(mesh_, Dim);
    auto external = fem::create_vertex_vector(mesh_, Dim);
    auto residual = fem::create_vertex_vector(mesh_, Dim);
    auto rhs = fem::create_vertex_vector(mesh_, Dim);
    auto update = fem::create_vertex_vector(mesh_, Dim);
    auto zero = fem::create_vertex_vector(mesh_, Dim);
    fem::P1Matrix matrix(mesh_, Dim);
    fem::set_rigid_body_modes(mesh_, matrix.mat());
    // GMRES rather than CG: the tangent is symmetric but loses definiteness near buckling.
    fem::LinearSolver solver(comm_, "solid_", {"gmres", "gamg", 1e-10, 1e-50, 2000});
    assemble_external_load<Dim>(external);
    log::info("linear solver: {}", solver.describe());

    const auto& newton = parameters_.newton;
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
      const double tolerance =
          std::max(newton.relative_tolerance * norm, newton.absolute_tolerance);
      int iteration = 0;
      bool small_update = false;
      log::info("step {}/{} (load factor {:.4g}): newton 0  |R| = {:.6e}", step, parameters_.steps,
                factor, norm);
      while (norm > tolerance && !small_update) {
        if (iteration == newton.max_iterations)
          throw ConvergenceError(fmt::format(
              "solid: Newton did not converge in load step {}/{} (load factor {:g}) within {} "
              "iterations: |R| = [{:.3e}] (tolerance {:.3e})",
              step, parameters_.steps, factor, newton.max_iterations, fmt::join(history, ", "),
              tolerance));
        ++iteration;
        fem::SolveStats stats;
        {
          ScopedTimer timer(output.timers(), "assemble");
          assemble_tangent<Dim>(u, matrix);
          COAPT_PETSC_CHECK(VecCopy(residual, rhs));
          COAPT_PETSC_CHECK(VecScale(rhs, -1.0));
          fem::apply_dirichlet(matrix.mat(), rhs, dirichlet_dofs_, zero);
        }
        {
          ScopedTimer timer(output.timers(), "solve");
          solver.set_operator(matrix.mat());
          COAPT_PETSC_CHECK(VecSet(update, 0.0));
          stats = solver.solve(rhs, update);
        }
        total_linear += stats.iterations;
        // Full Newton step; halved while it inverts a cell (the residual is then +∞).
        double step_length = 1.0;
        COAPT_PETSC_CHECK(VecAXPY(u, step_length, update));
        fem::update_ghosts(u);
        {
          ScopedTimer timer(output.timers(), "assemble");
          norm = assemble_residual<Dim>(u, external, factor, residual);
        }
        for (int halving = 0; !std::isfinite(norm) && halving < 12; ++halving) {
          step_length *= 0.5;
          COAPT_PETSC_CHECK(VecAXPY(u, -step_length, update));
          fem::update_ghosts(u);
          norm = assemble_residual<Dim>(u, external, factor, residual);
        }
        if (!std::isfinite(norm))
          throw ConvergenceError(fmt::format(
              "solid: load step {}/{}: every Newton step inverts a cell (|R| history [{:.3e}]); "
              "use more load steps",
              step, parameters_.steps, fmt::join(history, ", ")));
        history.push_back(norm);
        // The residual of a stiff, thin body bottoms out at the round-off of the internal
        // forces (ε times element forces that cancel at each vertex), so Newton also stops
        // once the update no longer changes u: ‖δu‖ ≤ dtol ‖u‖.
        PetscReal update_norm = 0, u_norm = 0;
        COAPT_PETSC_CHECK(VecNorm(update, NORM_2, &update_norm));
        COAPT_PETSC_CHECK(VecNorm(u, NORM_2, &u_norm));
        small_update = step_length * update_norm <= newton.update_tolerance * u_norm;
        log::info(
            "step {}/{}: newton {}  |R| = {:.6e}  (|R|/|R0| = {:.3e}, |du|/|u| = {:.3e}, "
            "step {:g}, {} linear its)",
            step, parameters_.steps, iteration, norm, norm / history.front(),
            step_length * update_norm / u_norm, step_length, stats.iterations);
      }
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
