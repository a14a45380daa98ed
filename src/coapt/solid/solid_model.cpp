// The solid model: setup (bodies, Dirichlet dofs, loads, probes), assembly of residual and
// tangent, one Newton routine shared by load steps and Newmark steps, the Newmark state
// (committed and trial), energies, probes and VTK output.
#include "coapt/solid/solid_model.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <type_traits>
#include <vector>

#include "coapt/core/collective.hpp"
#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/core/timer.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/kernels.hpp"
#include "coapt/fem/line_search.hpp"
#include "coapt/fem/linear_solver.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/mesh/mesh_input.hpp"
#include "coapt/solid/dynamics.hpp"
#include "coapt/solid/elements.hpp"
#include "coapt/solid/mixed_elements.hpp"
#include "coapt/solid/mixed_solver.hpp"

namespace coapt::solid {
namespace detail {

namespace {

/// A probe located in the reference mesh: the rank holding it keeps its cell and λ.
struct ProbeLocation {
  int owner = -1;  ///< rank that evaluates it (lowest rank with an owned cell containing it)
  int cell = -1;   ///< local cell on the owner
  std::vector<double> barycentric;
};

/// A boundary facet under a follower pressure, seen from the local cell it bounds.
struct PressureFacet {
  int facet = -1;
  double pressure = 0;         ///< p [Pa] at load factor 1
  std::array<int, 3> local{};  ///< position in the cell of each facet vertex
};

/// Applies `operation(k)` for every owned entry k of the vectors, with raw arrays.
template <class Operation>
void for_each_owned(Vec vector, Operation&& operation) {
  PetscInt n_local = 0;
  COAPT_PETSC_CHECK(VecGetLocalSize(vector, &n_local));
  for (PetscInt k = 0; k < n_local; ++k) operation(k);
}

/// Read-only and writable views of a PETSc vector's owned entries (RAII).
class ReadArray {
 public:
  explicit ReadArray(Vec vector) : vector_(vector) {
    COAPT_PETSC_CHECK(VecGetArrayRead(vector_, &data_));
  }
  ~ReadArray() { VecRestoreArrayRead(vector_, &data_); }
  ReadArray(const ReadArray&) = delete;
  ReadArray& operator=(const ReadArray&) = delete;
  double operator[](PetscInt k) const { return data_[k]; }

 private:
  Vec vector_;
  const PetscScalar* data_ = nullptr;
};

class WriteArray {
 public:
  explicit WriteArray(Vec vector) : vector_(vector) {
    COAPT_PETSC_CHECK(VecGetArray(vector_, &data_));
  }
  ~WriteArray() { VecRestoreArray(vector_, &data_); }
  WriteArray(const WriteArray&) = delete;
  WriteArray& operator=(const WriteArray&) = delete;
  double& operator[](PetscInt k) { return data_[k]; }

 private:
  Vec vector_;
  PetscScalar* data_ = nullptr;
};

/// The case's keys with what a driver owning the solid sets (SolidModelOptions).
SolidParameters read_parameters(const config::Section& root, const SolidModelOptions& options) {
  auto parameters = SolidParameters::read(root);
  mesh::add_refinement_levels(parameters.mesh, options.extra_mesh_levels, options.extra_levels_key);
  if (options.driver_dynamic) parameters.time.dynamic = true;
  return parameters;
}

}  // namespace

class SolidModelImpl {
 public:
  SolidModelImpl(const config::Section& root, MPI_Comm comm, const SolidModelOptions& options)
      : parameters_(read_parameters(root, options)),
        driver_dynamic_(options.driver_dynamic),
        comm_(comm),
        mesh_(mesh::load_mesh(parameters_.mesh, comm, &quality_)),
        dim_(mesh_.dim),
        u_(fem::create_vertex_vector(mesh_, dim_)),
        v_(fem::create_vertex_vector(mesh_, dim_)),
        a_(fem::create_vertex_vector(mesh_, dim_)),
        u_committed_(fem::create_vertex_vector(mesh_, dim_)),
        v_committed_(fem::create_vertex_vector(mesh_, dim_)),
        a_committed_(fem::create_vertex_vector(mesh_, dim_)),
        external_(fem::create_vertex_vector(mesh_, dim_)),
        residual_(fem::create_vertex_vector(mesh_, dim_)),
        inertia_(fem::create_vertex_vector(mesh_, dim_)),
        predictor_(fem::create_vertex_vector(mesh_, dim_)),
        static_residual_(fem::create_vertex_vector(mesh_, dim_)),
        work_(fem::create_vertex_vector(mesh_, dim_)),
        matrix_(mesh_, dim_),
        solver_(comm_, "solid_",
                // Quasi-static: GMRES rather than CG (the tangent is symmetric but loses
                // definiteness near buckling) with GAMG given the rigid-body modes. Dynamic:
                // a direct solver, since every Newton iteration of every step factors a new
                // matrix anyway and on thin bodies (the Turek–Hron bar) GMRES + GAMG needs
                // hundreds of iterations per solve; -solid_ksp_type gmres -solid_pc_type gamg
                // brings the iterative solver back.
                parameters_.time.dynamic
                    ? fem::LinearSolverDefaults{"preonly", "lu", 1e-10, 1e-50, 2000}
                    : fem::LinearSolverDefaults{"gmres", "gamg", 1e-10, 1e-50, 2000}) {
    MPI_Comm_rank(comm_, &rank_);
    if (parameters_.newton.reuse_factorisation > 0 && !parameters_.time.dynamic)
      throw InputError(fmt::format(
          "{}: only for a dynamic solid (time.scheme newmark or contact_stabilized_newmark, or "
          "an immersed solid in a transient coupling)",
          parameters_.newton.reuse_where));
    parameters_.check_dimension(dim_);
    assign_bodies();
    assign_fibres();
    collect_pressures();
    collect_dirichlet();
    if (parameters_.mixed) setup_mixed();
    locate_probes();
    fem::set_rigid_body_modes(mesh_, matrix_.mat());
    if (parameters_.time.dynamic) {
      PetscBool given = PETSC_FALSE;
      COAPT_PETSC_CHECK(
          PetscOptionsHasName(nullptr, "solid_", "-pc_factor_mat_solver_type", &given));
      PC pc = nullptr;
      COAPT_PETSC_CHECK(KSPGetPC(solver_.ksp(), &pc));
      if (!given) COAPT_PETSC_CHECK(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
      // A kept factorisation is not exact for a later matrix: GMRES corrects it, where preonly
      // (a contact solid's default, or -solid_ksp_type preonly) would turn Newton into a
      // modified Newton.
      PetscBool preonly = PETSC_FALSE;
      COAPT_PETSC_CHECK(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(solver_.ksp()),
                                               KSPPREONLY, &preonly));
      if (parameters_.newton.reuse_factorisation > 0 && preonly)
        COAPT_PETSC_CHECK(KSPSetType(solver_.ksp(), KSPGMRES));
    }
    if (dim_ == 2)
      assemble_external_load<2>();
    else
      assemble_external_load<3>();
    set_dirichlet(u_, 1.0);
    fem::update_ghosts(u_);
  }

  void describe() const {
    log::info("solid: {} finite strain, P1 {}, {}",
              parameters_.time.dynamic ? "dynamic" : "quasi-static",
              dim_ == 2 ? "plane strain" : "3D", parameters_.mesh.describe());
    log::info("mesh: {} cells, {} vertices, {} rank(s); cell measure in [{:.3e}, {:.3e}]",
              mesh_.n_global_cells, mesh_.n_global_vertices, size_of(comm_), quality_.min_measure,
              quality_.max_measure);
    for (const auto& body : parameters_.bodies) {
      log::info("body '{}': {}, density {:g} kg/m^3", body.name, name(body.material), body.density);
      if (const auto* law = std::get_if<FibreReinforced>(&body.material))
        log::info("body '{}': fibres {}", body.name,
                  body.fibre_field.describe(law->n_fibre_families));
    }
    for (const auto& load : parameters_.pressures)
      log::info("follower pressure on '{}': {:g} Pa", load.boundary, load.pressure);
    if (density_offset_ != 0)
      log::info("inertia density: body density - {:g} kg/m^3", density_offset_);
    const char* scheme = parameters_.time.contact_stabilized
                             ? "contact-stabilized Newmark, lumped mass"
                             : "Newmark, consistent mass";
    if (driver_dynamic_)
      log::info("{} (beta 1/4, gamma 1/2): the coupling's time steps", scheme);
    else if (parameters_.time.dynamic)
      log::info("{} (beta 1/4, gamma 1/2): {} steps of {:g} s to t = {:g} s", scheme,
                parameters_.time.n_steps, parameters_.time.step, parameters_.time.end_time);
    else
      log::info("{} load step(s)", parameters_.steps);
    const int reuse = parameters_.newton.reuse_factorisation;
    log::info("Newton: relative tolerance {:g}, absolute {:g}, update {:g}, at most {} its{}",
              parameters_.newton.relative_tolerance, parameters_.newton.absolute_tolerance,
              parameters_.newton.update_tolerance, parameters_.newton.max_iterations,
              reuse > 0 ? fmt::format("; a step's factorisation kept while GMRES on it takes at "
                                      "most {} iterations",
                                      reuse)
                        : "");
    if (parameters_.mixed)
      log::info(
          "formulation: mixed P1-P1 displacement-pressure, Brezzi-Pitkaranta alpha = {:g}; "
          "linear solver: {}",
          kPressureStabilisation, mixed_solver_->describe());
    else
      log::info("linear solver: {}", solver_.describe());
  }

  // --- access -------------------------------------------------------------------------------

  const SolidParameters& parameters() const { return parameters_; }
  MPI_Comm comm() const { return comm_; }
  const mesh::Mesh& mesh() const { return mesh_; }
  const mesh::QualityReport& quality() const { return quality_; }
  int dim() const { return dim_; }
  const std::vector<int>& body_of_cell() const { return body_of_cell_; }
  const std::vector<PetscInt>& dirichlet_dofs() const { return dirichlet_dofs_; }
  Vec displacement() const { return u_.get(); }
  Vec velocity() const { return v_.get(); }
  Vec acceleration() const { return a_.get(); }
  void set_external_force(Vec force) { extra_force_ = force; }
  void set_immersed_pressure(Vec pressure) {
    if (pressure && parameters_.mixed)
      throw InputError(
          "solid: formulation: mixed cannot carry the fluid's pressure "
          "(coupling.pressure_in_solid) yet: use formulation: displacement");
    immersed_pressure_ = pressure;
  }
  void set_hook(NewtonHook* hook) {
    if (hook && parameters_.mixed)
      throw InputError(
          "solid: formulation: mixed cannot be combined with a Newton hook (contact) yet: use "
          "formulation: displacement");
    hook_ = hook;
  }

  void set_contact_stabilized(bool contact_stabilized) {
    if (mass_) throw InternalError("solid: set_contact_stabilized() after initialize_dynamics()");
    parameters_.time.contact_stabilized = contact_stabilized;
  }

  void set_iteration_density(double density) {
    if (!(density >= 0))
      throw InternalError("solid: set_iteration_density() with a negative density");
    iteration_density_ = density;
    iteration_mass_.reset();
  }

  void iteration_force(Vec out) const {
    if (iteration_force_)
      COAPT_PETSC_CHECK(VecCopy(iteration_force_, out));
    else
      COAPT_PETSC_CHECK(VecSet(out, 0.0));
  }

  void set_density_offset(double offset) {
    for (const auto& body : parameters_.bodies)
      if (body.density - offset < 0)
        throw InputError(fmt::format(
            "{}: density: {:g} kg/m^3 is below the density {:g} kg/m^3 the body is immersed in",
            body.where, body.density, offset));
    density_offset_ = offset;
  }

  // --- quasi-static ---------------------------------------------------------------------------

  StepReport solve_static(double factor, run::RunOutput& output, const std::string& label,
                          bool verbose) {
    if (parameters_.mixed) return solve_static_mixed(factor, output, label, verbose);
    StepReport report;
    if (parameters_.newton.extrapolate) {
      extrapolate_static(factor);
      if (lift_dirichlet(factor, output)) ++report.newton_iterations;
    }
    set_dirichlet(u_, factor);
    fem::update_ghosts(u_);
    const auto residual_norm = [&] {
      ScopedTimer timer(output.timers(), "assemble");
      return assemble_residual(u_.get(), factor, nullptr);
    };
    if (hook_) hook_->begin_step(u_.get());
    const double norm = residual_norm();
    if (!std::isfinite(norm))
      throw ConvergenceError(
          fmt::format("solid: {}: the prescribed displacements invert a cell", label));
    report.history.push_back(norm);
    if (verbose) log::info("{}: newton 0  |R| = {:.6e}", label, norm);
    newton_solve(
        output, report, [&] { assemble_tangent(u_.get(), 0.0); }, residual_norm, label,
        "use more load steps", verbose);
    return report;
  }

  /// newton.predictor: extrapolate. u_ holds uₙ (load factor sₙ) on entry and
  /// uₙ + (s − sₙ)/(sₙ − sₙ₋₁) (uₙ − uₙ₋₁) on return (uₙ₋₁ = 0 at sₙ₋₁ = 0 before the first
  /// step, so the first step starts from uₙ = 0); the step is assumed to converge at s.
  void extrapolate_static(double factor) {
    if (!previous_static_) {
      previous_static_ = fem::create_vertex_vector(mesh_, dim_);
      COAPT_PETSC_CHECK(VecSet(previous_static_, 0.0));
    }
    const double span = static_factors_[1] - static_factors_[0];
    auto difference = fem::create_vertex_vector(mesh_, dim_);
    COAPT_PETSC_CHECK(VecWAXPY(difference, -1.0, previous_static_, u_));
    COAPT_PETSC_CHECK(VecCopy(u_, previous_static_));
    const double ratio = span > 0.0 ? (factor - static_factors_[1]) / span : 0.0;
    if (ratio != 0.0) COAPT_PETSC_CHECK(VecAXPY(u_, ratio, difference));
    // The Dirichlet dofs extrapolated the same way (u_ holds the full values before the
    // first step, so they are computed from the ramps, not taken from u_).
    {
      WriteArray data(u_);
      for (std::size_t k = 0; k < dirichlet_dofs_.size(); ++k) {
        const auto& condition = *dirichlet_conditions_[k];
        const double last = condition.ramp_fraction(static_factors_[1]);
        data[dirichlet_dofs_[k] - mesh_.vertex_offset * dim_] =
            dirichlet_values_[k] *
            (last + ratio * (last - condition.ramp_fraction(static_factors_[0])));
      }
    }
    static_factors_ = {static_factors_[1], factor};
  }

  /// newton.predictor: extrapolate, second part. Where the prescribed values at `factor`
  /// differ from u_ (a new phase of the loading, which the extrapolation cannot know), one
  /// linearised step K Δu = −R(u) with Δu = ΔD on the Dirichlet dofs (through the hook's
  /// system) carries the difference ΔD into the body, instead of moving the boundary nodes
  /// alone (which shears the layer of cells under them and can invert it). The step is kept
  /// only if no cell inverts. Returns whether it was taken. Collective.
  bool lift_dirichlet(double factor, run::RunOutput& output) {
    auto increment = fem::create_vertex_vector(mesh_, dim_);
    COAPT_PETSC_CHECK(VecSet(increment, 0.0));
    double jump = 0.0, scale = 0.0;
    {
      ReadArray u(u_);
      WriteArray d(increment);
      for (std::size_t k = 0; k < dirichlet_dofs_.size(); ++k) {
        const PetscInt local = dirichlet_dofs_[k] - mesh_.vertex_offset * dim_;
        d[local] =
            dirichlet_conditions_[k]->ramp_fraction(factor) * dirichlet_values_[k] - u[local];
        jump = std::max(jump, std::abs(d[local]));
        scale = std::max(scale, std::abs(dirichlet_values_[k]));
      }
    }
    double extremes[2] = {jump, scale};
    MPI_Allreduce(MPI_IN_PLACE, extremes, 2, MPI_DOUBLE, MPI_MAX, comm_);
    if (extremes[0] <= 1e-10 * extremes[1]) return false;  // the extrapolation already has it
    fem::update_ghosts(u_);
    if (hook_) hook_->begin_step(u_.get());
    {
      ScopedTimer timer(output.timers(), "assemble");
      if (!std::isfinite(assemble_residual(u_.get(), factor, nullptr))) return false;
      assemble_tangent(u_.get(), 0.0);
    }
    auto rhs = fem::create_vertex_vector(mesh_, dim_);
    auto update = fem::create_vertex_vector(mesh_, dim_);
    COAPT_PETSC_CHECK(VecCopy(residual_, rhs));
    COAPT_PETSC_CHECK(VecScale(rhs, -1.0));
    fem::apply_dirichlet(matrix_.mat(), rhs, dirichlet_dofs_, increment);
    Mat system = hook_ ? hook_->linear_system(u_.get(), matrix_.mat(), rhs) : matrix_.mat();
    {
      ScopedTimer timer(output.timers(), "solve");
      factorisation_current_ = false;
      solver_.set_operator(system);
      COAPT_PETSC_CHECK(VecSet(update, 0.0));
      solver_.solve(rhs, update);
    }
    COAPT_PETSC_CHECK(VecAXPY(u_, 1.0, update));
    set_dirichlet(u_, factor);
    fem::update_ghosts(u_);
    double norm = 0.0;
    {
      ScopedTimer timer(output.timers(), "assemble");
      norm = assemble_residual(u_.get(), factor, nullptr);
    }
    if (std::isfinite(norm)) return true;
    COAPT_PETSC_CHECK(VecAXPY(u_, -1.0, update));  // set_dirichlet follows in solve_static
    return false;
  }

  // --- dynamics -------------------------------------------------------------------------------

  bool has_mass() const {
    for (const auto& body : parameters_.bodies)
      if (body.density - density_offset_ > 0) return true;
    return false;
  }

  void assemble_mass() {
    mass_.emplace(mesh_, dim_);
    mass_->assemble([&](int c, double* element) {
      const int n = (dim_ + 1) * dim_;
      std::fill(element, element + n * n, 0.0);
      add_element_mass(c, 1.0, element);
    });
  }

  void initialize_dynamics(run::RunOutput& output) {
    assemble_mass();
    COAPT_PETSC_CHECK(VecSet(u_, 0.0));
    set_dirichlet(u_, 1.0);
    fem::update_ghosts(u_);
    {  // each vertex takes the initial velocity of the first body it belongs to
      std::vector<int> first_body(static_cast<std::size_t>(mesh_.n_vertices()),
                                  static_cast<int>(parameters_.bodies.size()));
      for (int c = 0; c < mesh_.n_cells(); ++c)
        for (const int vertex : mesh_.cell(c))
          first_body[vertex] = std::min(first_body[vertex], body_of_cell_[c]);
      WriteArray v(v_);
      for_each_owned(v_, [&](PetscInt k) {
        const int b = first_body[static_cast<std::size_t>(k / dim_)];
        const auto& own = b < static_cast<int>(parameters_.bodies.size())
                              ? parameters_.bodies[b].initial_velocity
                              : parameters_.time.initial_velocity;
        const auto& initial = own.empty() ? parameters_.time.initial_velocity : own;
        v[k] = initial.empty() ? 0.0 : initial[k % dim_];
      });
    }
    zero_dirichlet(v_);
    fem::update_ghosts(v_);
    COAPT_PETSC_CHECK(VecSet(a_, 0.0));
    // M a₀ = f_ext − f_int(u₀) on the free dofs, a₀ = 0 on the Dirichlet ones.
    const double norm = assemble_residual(u_.get(), 1.0, nullptr);
    if (!std::isfinite(norm))
      throw ConvergenceError("solid: the prescribed displacements invert a cell at t = 0");
    if (has_mass()) {
      ScopedTimer timer(output.timers(), "solve");
      auto rhs = fem::create_vertex_vector(mesh_, dim_);
      auto zero = fem::create_vertex_vector(mesh_, dim_);
      matrix_.assemble([&](int c, double* element) {
        const int n = (dim_ + 1) * dim_;
        std::fill(element, element + n * n, 0.0);
        add_element_mass(c, 1.0, element);
      });
      COAPT_PETSC_CHECK(VecCopy(residual_, rhs));
      COAPT_PETSC_CHECK(VecScale(rhs, -1.0));
      fem::apply_dirichlet(matrix_.mat(), rhs, dirichlet_dofs_, zero);
      factorisation_current_ = false;
      solver_.set_operator(matrix_.mat());
      solver_.solve(rhs, a_);
      zero_dirichlet(a_);
    }
    fem::update_ghosts(a_);
    commit();
  }

  StepReport step(double time, double time_step, run::RunOutput& output, bool from_current) {
    if (!mass_) throw InternalError("solid: step() before initialize_dynamics()");
    const Newmark scheme{time_step};
    const std::string label = fmt::format("time step to t = {:g} s", time);
    if (from_current) {
      if (!warm_start_) COAPT_PETSC_CHECK(VecDuplicate(u_, warm_start_.out()));
      COAPT_PETSC_CHECK(VecCopy(u_, warm_start_));
    }
    if (parameters_.time.contact_stabilized) {
      // Contact-stabilized predictor: the increment δ = Δt vₙ, projected by the hook onto
      // the admissible set (no penetration at uₙ + δ); Newton starts from uₙ + δ.
      COAPT_PETSC_CHECK(VecCopy(v_committed_, predictor_));
      COAPT_PETSC_CHECK(VecScale(predictor_, time_step));
      zero_dirichlet(predictor_);
      if (hook_) {
        if (!lumped_mass_) {  // the mass is lumped by rows here: its diagonal is the whole of it
          COAPT_PETSC_CHECK(VecDuplicate(predictor_, lumped_mass_.out()));
          COAPT_PETSC_CHECK(MatGetDiagonal(mass_->mat(), lumped_mass_));
        }
        hook_->project_predictor(u_committed_, predictor_, lumped_mass_);
      }
      COAPT_PETSC_CHECK(VecWAXPY(u_, 1.0, predictor_, u_committed_));
    } else {  // predictor u = uₙ + Δt vₙ + Δt²/2 aₙ (Dirichlet dofs: v = a = 0, u stays)
      WriteArray u(u_);
      ReadArray un(u_committed_), vn(v_committed_), an(a_committed_);
      for_each_owned(u_, [&](PetscInt k) { u[k] = scheme.predictor(un[k], vn[k], an[k]); });
    }
    fem::update_ghosts(u_);
    const auto residual_norm = [&] {
      update_acceleration(scheme);
      if (iteration_density_ > 0) add_iteration_inertia();
      ScopedTimer timer(output.timers(), "assemble");
      return assemble_residual(u_.get(), 1.0, inertia_.get());
    };
    if (iteration_density_ > 0) prepare_iteration_inertia(scheme);
    StepReport report;
    if (hook_) hook_->begin_step(u_.get());
    double norm = residual_norm();
    if (!std::isfinite(norm)) {  // the predictor inverts a cell: start from uₙ instead
      COAPT_PETSC_CHECK(VecCopy(u_committed_, u_));
      fem::update_ghosts(u_);
      norm = residual_norm();
    }
    report.history.push_back(norm);
    if (from_current) {
      // The last solve's state instead, if nearer: history.front() stays the predictor's
      // residual, which the tolerance is relative to.
      if (!predicted_) COAPT_PETSC_CHECK(VecDuplicate(u_, predicted_.out()));
      COAPT_PETSC_CHECK(VecCopy(u_, predicted_));
      COAPT_PETSC_CHECK(VecCopy(warm_start_, u_));
      fem::update_ghosts(u_);
      const double warm = residual_norm();
      if (std::isfinite(warm) && warm < norm) {
        report.history.push_back(warm);
      } else {
        COAPT_PETSC_CHECK(VecCopy(predicted_, u_));
        fem::update_ghosts(u_);
        residual_norm();
      }
    }
    newton_solve(
        output, report, [&] { assemble_tangent(u_.get(), scheme.mass_factor()); }, residual_norm,
        label, "use a smaller time step", false);
    {  // v = vₙ + Δt/2 (aₙ + a); `a_` holds a(u) from the last residual
      WriteArray v(v_);
      ReadArray vn(v_committed_), an(a_committed_), a(a_);
      for_each_owned(v_, [&](PetscInt k) { v[k] = scheme.velocity(vn[k], an[k], a[k]); });
    }
    fem::update_ghosts(v_);
    fem::update_ghosts(a_);
    return report;
  }

  void commit() {
    factorisation_current_ = false;  // newton.reuse_factorisation: within a time step only
    COAPT_PETSC_CHECK(VecCopy(u_, u_committed_));
    COAPT_PETSC_CHECK(VecCopy(v_, v_committed_));
    COAPT_PETSC_CHECK(VecCopy(a_, a_committed_));
    // VecCopy copies the owned entries only: the ghosts of uₙ are read by the assembly below.
    fem::update_ghosts(u_committed_);
    if (parameters_.time.contact_stabilized) commit_static_residual();
  }

  /// Contact-stabilized Newmark: Rₙ = f_int(uₙ) − f_ext − f_extra at the committed state,
  /// without the hook's (contact) terms, for the next step's inertia term (update_acceleration).
  void commit_static_residual() {
    NewtonHook* hook = hook_;
    hook_ = nullptr;
    const double norm = assemble_residual(u_committed_, 1.0, nullptr);
    hook_ = hook;
    if (!std::isfinite(norm))
      throw ConvergenceError("solid: the committed state has an inverted cell");
    COAPT_PETSC_CHECK(VecCopy(residual_, static_residual_));
  }

  void restore() {
    factorisation_current_ = false;
    COAPT_PETSC_CHECK(VecCopy(u_committed_, u_));
    COAPT_PETSC_CHECK(VecCopy(v_committed_, v_));
    COAPT_PETSC_CHECK(VecCopy(a_committed_, a_));
    fem::update_ghosts(u_);
    fem::update_ghosts(v_);
    fem::update_ghosts(a_);
  }

  void write_checkpoint(run::CheckpointWriter& writer, const std::string& prefix) const {
    writer.add_vertex_field(prefix + "u", mesh_, u_committed_, dim_);
    writer.add_vertex_field(prefix + "v", mesh_, v_committed_, dim_);
    writer.add_vertex_field(prefix + "a", mesh_, a_committed_, dim_);
  }

  void read_checkpoint(const run::CheckpointReader& reader, const std::string& prefix) {
    reader.read_vertex_field(prefix + "u", mesh_, u_committed_, dim_);
    reader.read_vertex_field(prefix + "v", mesh_, v_committed_, dim_);
    reader.read_vertex_field(prefix + "a", mesh_, a_committed_, dim_);
    restore();
    if (parameters_.time.contact_stabilized) commit_static_residual();
  }

  // --- reported quantities --------------------------------------------------------------------

  std::vector<std::vector<double>> probe_values() const {
    std::vector<std::vector<double>> result;
    fem::LocalValues values(u_.get());
    for (const auto& probe : probes_) {
      std::vector<double> value(static_cast<std::size_t>(dim_), 0.0);
      if (probe.owner == rank_) {
        const auto vertices = mesh_.cell(probe.cell);
        for (int a = 0; a <= dim_; ++a)
          for (int i = 0; i < dim_; ++i)
            value[i] +=
                probe.barycentric[a] * values[static_cast<std::size_t>(vertices[a]) * dim_ + i];
      }
      MPI_Bcast(value.data(), dim_, MPI_DOUBLE, probe.owner, comm_);
      result.push_back(std::move(value));
    }
    return result;
  }

  double kinetic_energy() const {
    if (!mass_) return 0.0;
    auto product = fem::create_vertex_vector(mesh_, dim_);
    COAPT_PETSC_CHECK(MatMult(mass_->mat(), v_, product));
    PetscScalar twice = 0;
    COAPT_PETSC_CHECK(VecDot(v_, product, &twice));
    return 0.5 * twice;
  }

  double external_work() const {
    PetscScalar work = 0;
    COAPT_PETSC_CHECK(VecDot(external_, u_, &work));
    return work;
  }

  double strain_energy() const {
    return dim_ == 2 ? cell_integral<2>(Integrand::energy) : cell_integral<3>(Integrand::energy);
  }

  double volume() const {
    return dim_ == 2 ? cell_integral<2>(Integrand::volume) : cell_integral<3>(Integrand::volume);
  }

  std::vector<BodyMotion> body_motion() const {
    const std::size_t n_bodies = parameters_.bodies.size();
    // per body: mass, Σ m x (3), Σ m v (3), Σ m x × v (3)
    std::vector<double> sums(n_bodies * 10, 0.0);
    fem::LocalValues u(u_.get()), v(v_.get());
    const double share = 1.0 / (dim_ + 1);
    for (int c = 0; c < mesh_.n_cells(); ++c) {
      const int b = body_of_cell_[c];
      const double measure = dim_ == 2 ? geometry<2>(c).measure : geometry<3>(c).measure;
      const double m = parameters_.bodies[b].density * measure * share;
      for (const int vertex : mesh_.cell(c)) {
        if (vertex >= mesh_.n_owned_vertices) continue;  // ghost: its owner adds it
        std::array<double, 3> x{}, w{};
        for (int i = 0; i < dim_; ++i) {
          const std::size_t k = static_cast<std::size_t>(vertex) * dim_ + i;
          x[i] = mesh_.coordinates[k] + u[k];
          w[i] = v[k];
        }
        double* sum = &sums[static_cast<std::size_t>(b) * 10];
        sum[0] += m;
        for (int i = 0; i < 3; ++i) {
          sum[1 + i] += m * x[i];
          sum[4 + i] += m * w[i];
        }
        sum[7] += m * (x[1] * w[2] - x[2] * w[1]);
        sum[8] += m * (x[2] * w[0] - x[0] * w[2]);
        sum[9] += m * (x[0] * w[1] - x[1] * w[0]);
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM,
                  comm_);
    std::vector<BodyMotion> motions(n_bodies);
    for (std::size_t b = 0; b < n_bodies; ++b) {
      const double* sum = &sums[b * 10];
      auto& motion = motions[b];
      motion.name = parameters_.bodies[b].name;
      motion.mass = sum[0];
      for (int i = 0; i < 3; ++i) {
        motion.barycentre[i] = sum[0] > 0 ? sum[1 + i] / sum[0] : 0.0;
        motion.momentum[i] = sum[4 + i];
        motion.angular_momentum[i] = sum[7 + i];
      }
    }
    return motions;
  }

  /// surface_swept_volumes; empty `vertex_levels`: every facet at level 0.
  std::vector<double> surface_swept_volumes(const std::string& boundary,
                                            std::span<const char> vertex_levels,
                                            int n_levels) const {
    const int tag = facet_tag(boundary, "surface_swept_volume");
    if (!vertex_levels.empty() && vertex_levels.size() != mesh_.global_vertex.size())
      throw InternalError(fmt::format("surface_swept_volume: {} vertex levels for {} vertices",
                                      vertex_levels.size(), mesh_.global_vertex.size()));
    fem::update_ghosts(u_committed_.get());
    fem::update_ghosts(u_.get());
    fem::LocalValues start(u_committed_.get()), end(u_.get());
    const auto d = static_cast<std::size_t>(dim_);
    // the point of vertex `vertex` at the fraction tau of the straight path from X + uₙ to X + u
    const auto x = [&](int vertex, int i, double tau) {
      const auto k = static_cast<std::size_t>(vertex) * d + static_cast<std::size_t>(i);
      return mesh_.coordinates[k] + (1 - tau) * start[k] + tau * end[k];
    };
    // |F| n at tau, n out of the body by the facets' orientation (mesh.hpp): the edge turned
    // clockwise in 2D, half the cross product of two edges in 3D.
    const auto area_normal = [&](const int* v, double tau, double* an) {
      if (dim_ == 2) {
        an[0] = x(v[1], 1, tau) - x(v[0], 1, tau);
        an[1] = -(x(v[1], 0, tau) - x(v[0], 0, tau));
        return;
      }
      double e1[3], e2[3];
      for (int i = 0; i < 3; ++i) {
        e1[i] = x(v[1], i, tau) - x(v[0], i, tau);
        e2[i] = x(v[2], i, tau) - x(v[0], i, tau);
      }
      an[0] = 0.5 * (e1[1] * e2[2] - e1[2] * e2[1]);
      an[1] = 0.5 * (e1[2] * e2[0] - e1[0] * e2[2]);
      an[2] = 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]);
    };
    std::vector<double> volumes(static_cast<std::size_t>(n_levels), 0.0);
    for (int f = 0; f < mesh_.n_facets(); ++f) {
      if (mesh_.facet_tags[f] != tag || mesh_.facet_cell[f] >= mesh_.n_owned_cells) continue;
      const int* v = mesh_.facets.data() + static_cast<std::size_t>(f) * d;
      int level = 0;
      if (!vertex_levels.empty())
        for (int a = 0; a < dim_; ++a) level = std::max(level, int{vertex_levels[v[a]]});
      if (level < 0 || level >= n_levels)
        throw InternalError(fmt::format("surface_swept_volume: level {} of {}", level, n_levels));
      double& volume = volumes[static_cast<std::size_t>(level)];
      // Along the path every point of the facet moves by the P1 interpolant of the vertices'
      // moves, constant in tau, and the facet stays flat, so ∫_F Δx·n da = (mean Δx)·|F|n(tau).
      // |F|n is linear in tau in 2D and quadratic in 3D: the midpoint rule, resp. Simpson's
      // rule, integrates it over tau ∈ [0, 1] exactly.
      double mean_move[3] = {};
      for (int a = 0; a < dim_; ++a)
        for (int i = 0; i < dim_; ++i) mean_move[i] += (x(v[a], i, 1.0) - x(v[a], i, 0.0)) / dim_;
      double an[3] = {}, path[3] = {};
      if (dim_ == 2) {
        area_normal(v, 0.5, path);
      } else {
        constexpr double tau[] = {0.0, 0.5, 1.0}, weight[] = {1.0 / 6, 4.0 / 6, 1.0 / 6};
        for (int q = 0; q < 3; ++q) {
          area_normal(v, tau[q], an);
          for (int i = 0; i < 3; ++i) path[i] += weight[q] * an[i];
        }
      }
      for (int i = 0; i < dim_; ++i) volume += mean_move[i] * path[i];
    }
    MPI_Allreduce(MPI_IN_PLACE, volumes.data(), n_levels, MPI_DOUBLE, MPI_SUM, comm_);
    return volumes;
  }

  std::vector<double> current_coordinates() const {
    fem::LocalValues values(u_.get());
    std::vector<double> coordinates = mesh_.coordinates;
    for (std::size_t k = 0; k < coordinates.size(); ++k) coordinates[k] += values[k];
    return coordinates;
  }

  void write_vtk(run::RunOutput& output, double time, const std::vector<io::Field>& extra) const {
    if (dim_ == 2)
      write_vtk<2>(output, time, extra);
    else
      write_vtk<3>(output, time, extra);
  }

  enum class Average { deformation_gradient, cauchy_stress };

  /// ∫ F dX / ∫ dX or ∫ σ dx / ∫ dx over the owned cells of every rank. Collective.
  std::array<double, 9> mean(Average what) const {
    return dim_ == 2 ? mean<2>(what) : mean<3>(what);
  }

  template <int Dim>
  std::array<double, 9> mean(Average what) const {
    fem::LocalValues values(u_.get());
    std::array<double, 10> sum{};  // 9 components and the volume
    for (int c = 0; c < mesh_.n_owned_cells; ++c) {
      const auto g = geometry<Dim>(c);
      const MatrixD<Dim> F = deformation_gradient<Dim>(g.gradients, nodal<Dim>(values, c));
      Matrix3 value = Matrix3::Identity();
      double weight = g.measure;
      if (what == Average::deformation_gradient) {
        value.topLeftCorner<Dim, Dim>() = F;
      } else {
        value = cauchy_stress<Dim>(body(c).material, F, fibres(c));
        weight *= F.determinant();
      }
      for (int k = 0; k < 9; ++k) sum[k] += weight * value(k / 3, k % 3);
      sum[9] += weight;
    }
    MPI_Allreduce(MPI_IN_PLACE, sum.data(), 10, MPI_DOUBLE, MPI_SUM, comm_);
    std::array<double, 9> result{};
    for (int k = 0; k < 9; ++k) result[k] = sum[k] / sum[9];
    return result;
  }

  /// Σ of f_int(u) (with the follower pressures at the last load factor and the immersed
  /// pressure) over the owned vertices of a boundary group. Collective.
  std::vector<double> reaction_force(const std::string& boundary) const {
    const int tag = facet_tag(boundary, "reaction_force");
    auto force = fem::create_vertex_vector(mesh_, dim_);
    fem::LocalValues values(u_.get());
    std::optional<fem::LocalValues> immersed;
    if (immersed_pressure_) immersed.emplace(immersed_pressure_);
    const auto element_forces = [&](auto dimension, int c, double* element) {
      constexpr int Dim = decltype(dimension)::value;
      const NodalValues<Dim> displacement = nodal<Dim>(values, c);
      const auto r =
          element_residual<Dim>(geometry<Dim>(c), body(c).material, fibres(c), displacement);
      std::copy(r.data(), r.data() + r.size(), element);
      add_pressure<Dim>(c, displacement, pressure_factor_, false, element);
      if (immersed) add_immersed_pressure<Dim>(c, displacement, *immersed, false, element);
    };
    fem::assemble_vector(mesh_, dim_, force, [&](int c, double* element) {
      if (dim_ == 2)
        element_forces(std::integral_constant<int, 2>{}, c, element);
      else
        element_forces(std::integral_constant<int, 3>{}, c, element);
    });
    std::vector<double> total(static_cast<std::size_t>(dim_), 0.0);
    {
      ReadArray data(force);
      for (int i = 0; i < dim_; ++i) {
        const int component[1] = {i};
        for (PetscInt dof : fem::boundary_dofs(mesh_, dim_, tag, component))
          total[static_cast<std::size_t>(i)] += data[dof - mesh_.vertex_offset * dim_];
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, total.data(), dim_, MPI_DOUBLE, MPI_SUM, comm_);
    return total;
  }

  // --- mixed displacement-pressure formulation (mixed_elements.hpp) --------------------------

  /// One quasi-static load step of the mixed formulation: Newton on (u, p) with the stopping
  /// rules of newton_solve; u_ follows the displacement part after every update.
  StepReport solve_static_mixed(double factor, run::RunOutput& output, const std::string& label,
                                bool verbose) {
    const auto& newton = parameters_.newton;
    const int m = dim_ + 1;
    set_dirichlet(u_, factor);
    {
      ReadArray u(u_);
      WriteArray w(mixed_state_);
      for (int v = 0; v < mesh_.n_owned_vertices; ++v)
        for (int i = 0; i < dim_; ++i) w[v * m + i] = u[v * dim_ + i];
    }
    fem::update_ghosts(mixed_state_);
    const auto residual_norm = [&] {
      ScopedTimer timer(output.timers(), "assemble");
      return assemble_mixed_residual(factor);
    };
    StepReport report;
    auto& history = report.history;
    double norm = residual_norm();
    if (!std::isfinite(norm))
      throw ConvergenceError(
          fmt::format("solid: {}: the prescribed displacements invert a cell", label));
    history.push_back(norm);
    if (verbose) log::info("{}: newton 0  |R| = {:.6e}", label, norm);
    auto rhs = fem::create_vertex_vector(mesh_, m);
    auto update = fem::create_vertex_vector(mesh_, m);
    auto zero = fem::create_vertex_vector(mesh_, m);
    const double tolerance =
        std::max(newton.relative_tolerance * history.front(), newton.absolute_tolerance);
    bool small_update = false;
    while (norm > tolerance && !small_update) {
      if (report.newton_iterations == newton.max_iterations)
        throw ConvergenceError(
            fmt::format("solid: Newton (mixed) did not converge in {} within {} iterations: |R| = "
                        "[{:.3e}] (tolerance {:.3e})",
                        label, newton.max_iterations, fmt::join(history, ", "), tolerance));
      ++report.newton_iterations;
      {
        ScopedTimer timer(output.timers(), "assemble");
        assemble_mixed_tangent(factor);
        COAPT_PETSC_CHECK(VecCopy(mixed_residual_, rhs));
        COAPT_PETSC_CHECK(VecScale(rhs, -1.0));
        fem::apply_dirichlet(mixed_matrix_->mat(), rhs, mixed_dirichlet_dofs_, zero);
      }
      fem::SolveStats stats;
      {
        ScopedTimer timer(output.timers(), "solve");
        mixed_solver_->set_operator(mixed_matrix_->mat());
        COAPT_PETSC_CHECK(VecSet(update, 0.0));
        stats = mixed_solver_->solve(rhs, update);
      }
      zero_mixed_dirichlet(update);
      report.linear_iterations += stats.iterations;
      double step_length = 1.0;
      COAPT_PETSC_CHECK(VecAXPY(mixed_state_, step_length, update));
      fem::update_ghosts(mixed_state_);
      norm = residual_norm();
      for (int halving = 0; !std::isfinite(norm) && halving < 12; ++halving) {
        step_length *= 0.5;
        COAPT_PETSC_CHECK(VecAXPY(mixed_state_, -step_length, update));
        fem::update_ghosts(mixed_state_);
        norm = residual_norm();
      }
      if (!std::isfinite(norm))
        throw ConvergenceError(fmt::format(
            "solid: {}: every Newton step inverts a cell (|R| history [{:.3e}]); use more load "
            "steps",
            label, fmt::join(history, ", ")));
      history.push_back(norm);
      PetscReal update_norm = 0, state_norm = 0;
      COAPT_PETSC_CHECK(VecNorm(update, NORM_2, &update_norm));
      COAPT_PETSC_CHECK(VecNorm(mixed_state_, NORM_2, &state_norm));
      small_update = step_length * update_norm <= newton.update_tolerance * state_norm;
      const std::string line = fmt::format(
          "{}: newton {}  |R| = {:.6e}  (|R|/|R0| = {:.3e}, step {:g}, {} linear its)", label,
          report.newton_iterations, norm, norm / history.front(), step_length, stats.iterations);
      if (verbose)
        log::info("{}", line);
      else
        log::debug("{}", line);
    }
    {
      ReadArray w(mixed_state_);
      WriteArray u(u_);
      for (int v = 0; v < mesh_.n_owned_vertices; ++v)
        for (int i = 0; i < dim_; ++i) u[v * dim_ + i] = w[v * m + i];
    }
    fem::update_ghosts(u_);
    return report;
  }

 private:
  void setup_mixed() {
    const int m = dim_ + 1;
    mixed_state_ = fem::create_vertex_vector(mesh_, m);
    mixed_residual_ = fem::create_vertex_vector(mesh_, m);
    mixed_matrix_.emplace(mesh_, m);
    for (PetscInt dof : dirichlet_dofs_)
      mixed_dirichlet_dofs_.push_back(dof / dim_ * m + dof % dim_);
    cell_size_.resize(static_cast<std::size_t>(mesh_.n_cells()));
    for (int c = 0; c < mesh_.n_cells(); ++c) {
      double h = 0;
      const auto vertices = mesh_.cell(c);
      for (int a = 0; a <= dim_; ++a)
        for (int b = a + 1; b <= dim_; ++b) {
          double squared = 0;
          for (int d = 0; d < dim_; ++d) {
            const double e = mesh_.point(vertices[a])[d] - mesh_.point(vertices[b])[d];
            squared += e * e;
          }
          h = std::max(h, std::sqrt(squared));
        }
      cell_size_[static_cast<std::size_t>(c)] = h;
    }
    // The pressure unknown is p / S with S = μ_max / h_mean, so that the u–u, u–p and p–p
    // blocks are all of order μ (in physical units they differ by factors h and h², 10 orders
    // of magnitude on a mm mesh, which defeats the pivoting of a direct solver).
    double sums[2] = {0.0, static_cast<double>(mesh_.n_owned_cells)};
    for (int c = 0; c < mesh_.n_owned_cells; ++c)
      sums[0] += cell_size_[static_cast<std::size_t>(c)];
    MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, comm_);
    double shear_max = 0;
    for (const auto& body : parameters_.bodies) {
      double bulk = 0, shear = 0;
      volumetric_split(body.material, bulk, shear);
      shear_max = std::max(shear_max, shear);
    }
    pressure_scale_ = shear_max / (sums[0] / sums[1]);
    // The linear solver (mixed_solver.hpp) and the lumped pressure mass S² |T|/((Dim+1) μ_T)
    // of its Schur-complement preconditioner (S²: the pressure rows and columns hold p / S).
    auto pressure_mass = fem::create_vertex_vector(mesh_, m);
    COAPT_PETSC_CHECK(VecSet(pressure_mass, 0.0));
    for (int c = 0; c < mesh_.n_owned_cells; ++c) {
      double bulk = 0, shear = 0;
      volumetric_split(body(c).material, bulk, shear);
      const double weight = pressure_scale_ * pressure_scale_ *
                            std::abs(mesh::cell_signed_measure(mesh_, c)) / (dim_ + 1) / shear;
      for (const int v : mesh_.cell(c))
        COAPT_PETSC_CHECK(
            VecSetValue(pressure_mass, mesh_.global_vertex[v] * m + dim_, weight, ADD_VALUES));
    }
    COAPT_PETSC_CHECK(VecAssemblyBegin(pressure_mass));
    COAPT_PETSC_CHECK(VecAssemblyEnd(pressure_mass));
    mixed_solver_.emplace(mesh_, pressure_mass);
    // The block preconditioner's sub-matrices are re-extracted in place at every Newton
    // iteration: the Dirichlet elimination must keep the CSR pattern.
    if (mixed_solver_->block_preconditioner())
      COAPT_PETSC_CHECK(MatSetOption(mixed_matrix_->mat(), MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
  }

  void zero_mixed_dirichlet(Vec vector) {
    WriteArray data(vector);
    for (PetscInt dof : mixed_dirichlet_dofs_) data[dof - mesh_.vertex_offset * (dim_ + 1)] = 0.0;
  }

  template <int Dim>
  MixedNodalValues<Dim> mixed_nodal(const fem::LocalValues& w, int c) const {
    MixedNodalValues<Dim> values;
    const auto vertices = mesh_.cell(c);
    for (int a = 0; a <= Dim; ++a)
      for (int i = 0; i <= Dim; ++i)
        values(a, i) = w[static_cast<std::size_t>(vertices[a]) * (Dim + 1) + i];
    values.col(Dim) *= pressure_scale_;  // the state holds p / S
    return values;
  }

  double assemble_mixed_residual(double factor) {
    pressure_factor_ = factor;
    return dim_ == 2 ? assemble_mixed_residual<2>(factor) : assemble_mixed_residual<3>(factor);
  }

  /// The mixed residual into mixed_residual_ (Dirichlet rows zeroed): ‖R‖, +∞ when a cell
  /// inverts. Collective.
  template <int Dim>
  double assemble_mixed_residual(double factor) {
    constexpr int m = Dim + 1;
    double min_J = std::numeric_limits<double>::infinity();
    {
      fem::LocalValues values(mixed_state_.get());
      fem::assemble_vector(mesh_, m, mixed_residual_, [&](int c, double* element) {
        const MixedNodalValues<Dim> w = mixed_nodal<Dim>(values, c);
        MixedElementVector<Dim> r;
        const double J = mixed_element<Dim>(geometry<Dim>(c), cell_size_[c], body(c).material,
                                            fibres(c), w, r, nullptr);
        min_J = std::isfinite(J) ? std::min(min_J, J) : -1.0;
        if (!(J > 0.0)) return;
        for (int a = 0; a <= Dim; ++a) r(a * m + Dim) *= pressure_scale_;
        std::copy(r.data(), r.data() + r.size(), element);
        ElementVector<Dim> pressure = ElementVector<Dim>::Zero();
        add_pressure<Dim>(c, w.template leftCols<Dim>(), factor, false, pressure.data());
        for (int a = 0; a <= Dim; ++a)
          for (int i = 0; i < Dim; ++i) element[a * m + i] += pressure(a * Dim + i);
      });
    }
    MPI_Allreduce(MPI_IN_PLACE, &min_J, 1, MPI_DOUBLE, MPI_MIN, comm_);
    if (!(min_J > 0.0)) return std::numeric_limits<double>::infinity();
    {
      WriteArray R(mixed_residual_);
      ReadArray f(external_);
      std::optional<ReadArray> extra;
      if (extra_force_) extra.emplace(extra_force_);
      for (int v = 0; v < mesh_.n_owned_vertices; ++v)
        for (int i = 0; i < Dim; ++i) {
          R[v * m + i] -= factor * f[v * Dim + i];
          if (extra) R[v * m + i] -= (*extra)[v * Dim + i];
        }
    }
    zero_mixed_dirichlet(mixed_residual_);
    PetscReal norm = 0;
    COAPT_PETSC_CHECK(VecNorm(mixed_residual_, NORM_2, &norm));
    return std::isfinite(norm) ? norm : std::numeric_limits<double>::infinity();
  }

  void assemble_mixed_tangent(double factor) {
    if (dim_ == 2)
      assemble_mixed_tangent<2>(factor);
    else
      assemble_mixed_tangent<3>(factor);
  }

  template <int Dim>
  void assemble_mixed_tangent(double factor) {
    constexpr int m = Dim + 1, n = (Dim + 1) * m, nd = (Dim + 1) * Dim;
    fem::LocalValues values(mixed_state_.get());
    mixed_matrix_->assemble([&](int c, double* element) {
      const MixedNodalValues<Dim> w = mixed_nodal<Dim>(values, c);
      MixedElementVector<Dim> r;
      MixedElementMatrix<Dim> K;
      mixed_element<Dim>(geometry<Dim>(c), cell_size_[c], body(c).material, fibres(c), w, r, &K);
      for (int a = 0; a <= Dim; ++a) {
        K.row(a * m + Dim) *= pressure_scale_;
        K.col(a * m + Dim) *= pressure_scale_;
      }
      std::copy(K.data(), K.data() + K.size(), element);
      ElementMatrix<Dim> pressure = ElementMatrix<Dim>::Zero();
      add_pressure<Dim>(c, w.template leftCols<Dim>(), factor, true, pressure.data());
      for (int a = 0; a < nd; ++a)
        for (int b = 0; b < nd; ++b)
          element[(a / Dim * m + a % Dim) * n + b / Dim * m + b % Dim] += pressure(a, b);
    });
  }

  /// The mixed pressure per local vertex [Pa] (empty for the displacement formulation).
  std::vector<double> mixed_pressure() const {
    if (!parameters_.mixed) return {};
    fem::LocalValues values(mixed_state_.get());
    std::vector<double> pressure(static_cast<std::size_t>(mesh_.n_vertices()));
    for (std::size_t v = 0; v < pressure.size(); ++v)
      pressure[v] = pressure_scale_ * values[v * (dim_ + 1) + dim_];
    return pressure;
  }

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

  /// fibres_of_cell_ for every local cell from each body's fibre rule; in 2D every direction
  /// must lie in the x-y plane. InputError (on every rank) naming the element (its number in
  /// the mesh source) or the file and line.
  void assign_fibres() {
    const std::size_t n_cells = static_cast<std::size_t>(mesh_.n_cells());
    fibres_of_cell_.assign(n_cells, FibreDirections{});
    for (std::size_t b = 0; b < parameters_.bodies.size(); ++b) {
      const auto& body = parameters_.bodies[b];
      const auto* law = std::get_if<FibreReinforced>(&body.material);
      if (!law) continue;
      const auto& field = body.fibre_field;
      std::vector<int> cells;  // owned first, then ghosts
      for (int pass = 0; pass < 2; ++pass)
        for (int c = pass == 0 ? 0 : mesh_.n_owned_cells;
             c < (pass == 0 ? mesh_.n_owned_cells : mesh_.n_cells()); ++c)
          if (body_of_cell_[c] == static_cast<int>(b)) cells.push_back(c);
      std::size_t n_owned = 0;
      while (n_owned < cells.size() && cells[n_owned] < mesh_.n_owned_cells) ++n_owned;
      const auto element_name = [&](int c) {
        return fmt::format("{}: element {} of {}", field.where, mesh_.original_cell[c],
                           mesh_.source);
      };
      std::string message;
      if (field.rule == FibreFieldParameters::Rule::file) {
        std::string text;
        try {
          std::ifstream stream(field.file);
          if (!stream)
            throw InputError(fmt::format("{}: file: cannot read '{}'", field.where, field.file));
          std::ostringstream buffer;
          buffer << stream.rdbuf();
          text = buffer.str();
        } catch (const InputError& e) {
          message = e.what();
        }
        rethrow_collectively(comm_, message, true);
        std::vector<std::int64_t> elements;
        elements.reserve(cells.size());
        for (int c : cells) elements.push_back(mesh_.original_cell[c]);
        const auto directions =
            fibres_from_csv(text, field.file, elements, n_owned, law->n_fibre_families, comm_);
        for (std::size_t k = 0; k < cells.size(); ++k) fibres_of_cell_[cells[k]] = directions[k];
      }
      try {
        for (int c : cells) {
          auto& fibres = fibres_of_cell_[c];
          if (field.rule == FibreFieldParameters::Rule::constant) {
            fibres = field.constant;
          } else if (field.rule == FibreFieldParameters::Rule::circumferential) {
            Vector3 centroid = Vector3::Zero();
            for (int v : mesh_.cell(c))
              for (int d = 0; d < dim_; ++d) centroid(d) += mesh_.point(v)[d] / (dim_ + 1);
            fibres = circumferential_fibres(field, centroid, element_name(c));
          }
          if (law->n_fibre_families < kMaxFibreFamilies) fibres.a0[1].setZero();
          if (dim_ == 2)
            for (int f = 0; f < law->n_fibre_families; ++f)
              if (std::abs(fibres.a0[f].z()) > 1e-12)
                throw InputError(fmt::format("{}: fibre direction {} leaves the x-y plane",
                                             element_name(c), f + 1));
        }
      } catch (const InputError& e) {
        message = e.what();
      }
      rethrow_collectively(comm_, message, true);
    }
  }

  /// pressure_facets_ grouped by local cell (owned and ghost: the tangent assembly visits
  /// ghost cells too), pressure_offset_ their CSR offsets. Nothing when the case has no
  /// pressures.
  void collect_pressures() {
    if (parameters_.pressures.empty()) return;
    std::vector<std::pair<int, PressureFacet>> found;  // cell, facet
    for (const auto& load : parameters_.pressures) {
      const int tag = facet_tag(load.boundary, load.where);
      for (int f = 0; f < mesh_.n_facets(); ++f) {
        if (mesh_.facet_tags[f] != tag) continue;
        const int c = mesh_.facet_cell[f];
        PressureFacet entry;
        entry.facet = f;
        entry.pressure = load.pressure;
        const auto vertices = mesh_.cell(c);
        for (int a = 0; a < dim_; ++a) {
          const int v = mesh_.facets[static_cast<std::size_t>(f) * dim_ + a];
          entry.local[a] =
              static_cast<int>(std::find(vertices.begin(), vertices.end(), v) - vertices.begin());
        }
        found.emplace_back(c, entry);
      }
    }
    std::stable_sort(found.begin(), found.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    pressure_offset_.assign(static_cast<std::size_t>(mesh_.n_cells()) + 1, 0);
    for (const auto& [c, entry] : found) ++pressure_offset_[static_cast<std::size_t>(c) + 1];
    for (std::size_t c = 0; c + 1 < pressure_offset_.size(); ++c)
      pressure_offset_[c + 1] += pressure_offset_[c];
    for (auto& [c, entry] : found) pressure_facets_.push_back(entry);
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

  /// The owned Dirichlet dofs with their final values and conditions (a later condition wins
  /// on a dof).
  void collect_dirichlet() {
    struct Prescribed {
      PetscInt dof;
      double value;
      const DirichletParameters* condition;
    };
    std::vector<Prescribed> prescribed;
    for (const auto& condition : parameters_.dirichlet) {
      const int tag = facet_tag(condition.boundary, condition.where);
      std::vector<int> components = condition.components;
      if (components.empty())
        for (int i = 0; i < dim_; ++i) components.push_back(i);
      for (std::size_t k = 0; k < components.size(); ++k) {
        const int component[1] = {components[k]};
        const double value = condition.values.empty() ? 0.0 : condition.values[k];
        for (PetscInt dof : fem::boundary_dofs(mesh_, dim_, tag, component))
          prescribed.push_back({dof, value, &condition});
      }
    }
    std::stable_sort(prescribed.begin(), prescribed.end(),
                     [](const auto& a, const auto& b) { return a.dof < b.dof; });
    for (std::size_t i = 0; i < prescribed.size(); ++i) {
      if (i + 1 < prescribed.size() && prescribed[i + 1].dof == prescribed[i].dof) continue;
      dirichlet_dofs_.push_back(prescribed[i].dof);
      dirichlet_values_.push_back(prescribed[i].value);
      dirichlet_conditions_.push_back(prescribed[i].condition);
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

  /// Sets the Dirichlet dofs of `vector` to their values at load factor `factor` (each ramped
  /// over its condition's interval: factor × value without a `ramp`). Ghosts not updated.
  void set_dirichlet(Vec vector, double factor) {
    WriteArray data(vector);
    for (std::size_t k = 0; k < dirichlet_dofs_.size(); ++k)
      data[dirichlet_dofs_[k] - mesh_.vertex_offset * dim_] =
          dirichlet_conditions_[k]->ramp_fraction(factor) * dirichlet_values_[k];
  }
  void zero_dirichlet(Vec vector) { set_dirichlet(vector, 0.0); }

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
  /// Fibre directions of local cell c (zero vectors for the isotropic laws).
  const FibreDirections& fibres(int c) const { return fibres_of_cell_[c]; }

  /// The full external load f_ext (gravity and tractions at load factor 1). Collective.
  template <int Dim>
  void assemble_external_load() {
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
    Vec load = external_.get();
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

  /// Adds the follower-pressure terms of cell c's facets at load factor `factor` to its element
  /// vector (`matrix` false) or element matrix (`matrix` true), node-major.
  template <int Dim>
  void add_pressure(int c, const NodalValues<Dim>& displacement, double factor, bool matrix,
                    double* element) const {
    if (pressure_offset_.empty() || factor == 0.0) return;
    constexpr int n = (Dim + 1) * Dim;
    const auto vertices = mesh_.cell(c);
    for (int k = pressure_offset_[c]; k < pressure_offset_[c + 1]; ++k) {
      const auto& entry = pressure_facets_[static_cast<std::size_t>(k)];
      FacetPositions<Dim> x;
      for (int a = 0; a < Dim; ++a)
        for (int i = 0; i < Dim; ++i)
          x(a, i) = mesh_.point(vertices[entry.local[a]])[i] + displacement(entry.local[a], i);
      const double p = factor * entry.pressure;
      if (matrix) {
        const FacetMatrix<Dim> K = pressure_facet_tangent<Dim>(x, p);
        for (int a = 0; a < Dim; ++a)
          for (int i = 0; i < Dim; ++i)
            for (int b = 0; b < Dim; ++b)
              for (int j = 0; j < Dim; ++j)
                element[(entry.local[a] * Dim + i) * n + entry.local[b] * Dim + j] +=
                    K(a * Dim + i, b * Dim + j);
      } else {
        const FacetVector<Dim> r = pressure_facet_residual<Dim>(x, p);
        for (int a = 0; a < Dim; ++a)
          for (int i = 0; i < Dim; ++i) element[entry.local[a] * Dim + i] += r(a * Dim + i);
      }
    }
  }

  /// The fluid's pressure the solid carries (set_immersed_pressure), p̄ the mean of cell c's
  /// nodal values: adds |T| p̄ h_ai = ∫ p div_x N_a (h_a = F⁻ᵀ ∇N_a = ∇_x N_a, |T| = J |T₀|)
  /// to its element vector (`matrix` false), or its derivative |T| p̄ (h_ai h_bk − h_bi h_ak)
  /// to its element matrix (`matrix` true), node-major.
  template <int Dim>
  void add_immersed_pressure(int c, const NodalValues<Dim>& displacement,
                             const fem::LocalValues& pressure, bool matrix, double* element) const {
    const auto vertices = mesh_.cell(c);
    double mean = 0;
    for (int a = 0; a <= Dim; ++a) mean += pressure[static_cast<std::size_t>(vertices[a])];
    mean /= Dim + 1;
    if (mean == 0.0) return;
    const auto g = geometry<Dim>(c);
    const MatrixD<Dim> F = deformation_gradient<Dim>(g.gradients, displacement);
    const double J = F.determinant();
    // row a: (F⁻ᵀ ∇N_a)ᵀ = ∇_x N_a, the spatial gradient
    const NodalValues<Dim> h = g.gradients * F.inverse();
    const double scale = g.measure * mean * J;  // |T| p̄ with |T| = J |T₀|
    constexpr int n = (Dim + 1) * Dim;
    if (!matrix) {
      for (int a = 0; a <= Dim; ++a)
        for (int i = 0; i < Dim; ++i) element[a * Dim + i] += scale * h(a, i);
      return;
    }
    // ∂(J F⁻ᵀ)_iJ/∂F_kL = J (F⁻ᵀ_iJ F⁻ᵀ_kL − F⁻ᵀ_iL F⁻ᵀ_kJ), contracted with ∇N_a and ∇N_b
    for (int a = 0; a <= Dim; ++a)
      for (int i = 0; i < Dim; ++i)
        for (int b = 0; b <= Dim; ++b)
          for (int k = 0; k < Dim; ++k)
            element[(a * Dim + i) * n + b * Dim + k] +=
                scale * (h(a, i) * h(b, k) - h(b, i) * h(a, k));
  }

  /// R = f_int(u) − s f_ext − f_extra (+ M a when `inertia` holds M a) + the hook's terms into
  /// residual_ with the Dirichlet rows zeroed; returns ‖R‖₂, or +∞ when some cell is inverted
  /// (det F ≤ 0 or not finite) on any rank. Collective.
  double assemble_residual(Vec u, double factor, Vec inertia) {
    return dim_ == 2 ? assemble_residual<2>(u, factor, inertia)
                     : assemble_residual<3>(u, factor, inertia);
  }

  template <int Dim>
  double assemble_residual(Vec u, double factor, Vec inertia) {
    pressure_factor_ = factor;  // the tangent that follows is taken at the same load factor
    double min_J = std::numeric_limits<double>::infinity();
    {
      fem::LocalValues values(u);
      std::optional<fem::LocalValues> immersed;
      if (immersed_pressure_) immersed.emplace(immersed_pressure_);
      fem::assemble_vector(mesh_, Dim, residual_, [&](int c, double* element) {
        const auto g = geometry<Dim>(c);
        const NodalValues<Dim> displacement = nodal<Dim>(values, c);
        const double J = deformation_gradient<Dim>(g.gradients, displacement).determinant();
        min_J = std::isfinite(J) ? std::min(min_J, J) : -1.0;
        if (!(J > 0.0)) return;  // the whole residual is rejected below
        const auto r = element_residual<Dim>(g, body(c).material, fibres(c), displacement);
        std::copy(r.data(), r.data() + r.size(), element);
        add_pressure<Dim>(c, displacement, factor, false, element);
        if (immersed) add_immersed_pressure<Dim>(c, displacement, *immersed, false, element);
      });
    }
    MPI_Allreduce(MPI_IN_PLACE, &min_J, 1, MPI_DOUBLE, MPI_MIN, comm_);
    if (!(min_J > 0.0)) return std::numeric_limits<double>::infinity();
    COAPT_PETSC_CHECK(VecAXPY(residual_, -factor, external_));
    if (extra_force_) COAPT_PETSC_CHECK(VecAXPY(residual_, -1.0, extra_force_));
    if (inertia) COAPT_PETSC_CHECK(VecAXPY(residual_, 1.0, inertia));
    if (hook_) hook_->add_residual(u, residual_);
    zero_dirichlet(residual_);
    PetscReal norm = 0;
    COAPT_PETSC_CHECK(VecNorm(residual_, NORM_2, &norm));
    return std::isfinite(norm) ? norm : std::numeric_limits<double>::infinity();
  }

  /// K(u) + mass_factor M into matrix_. Collective.
  void assemble_tangent(Vec u, double mass_factor) {
    if (dim_ == 2)
      assemble_tangent<2>(u, mass_factor);
    else
      assemble_tangent<3>(u, mass_factor);
  }

  template <int Dim>
  void assemble_tangent(Vec u, double mass_factor) {
    fem::LocalValues values(u);
    std::optional<fem::LocalValues> immersed;
    if (immersed_pressure_) immersed.emplace(immersed_pressure_);
    matrix_.assemble([&](int c, double* element) {
      const NodalValues<Dim> displacement = nodal<Dim>(values, c);
      const auto K =
          element_tangent<Dim>(geometry<Dim>(c), body(c).material, fibres(c), displacement);
      std::copy(K.data(), K.data() + K.size(), element);
      add_pressure<Dim>(c, displacement, pressure_factor_, true, element);
      if (immersed) add_immersed_pressure<Dim>(c, displacement, *immersed, true, element);
      if (mass_factor != 0) add_element_mass(c, mass_factor, element);
      if (mass_factor != 0 && iteration_density_ > 0)
        add_lumped_mass<Dim>(c, mass_factor * iteration_density_, element);
    });
  }

  /// Adds factor |c|/(Dim+1) δ_ij to the diagonal of cell c's element matrix (node-major).
  template <int Dim>
  void add_lumped_mass(int c, double factor, double* element) const {
    constexpr int n = (Dim + 1) * Dim;
    const auto mass = fem::element_mass<Dim>(geometry<Dim>(c));
    for (int a = 0; a <= Dim; ++a)
      for (int b = 0; b <= Dim; ++b)
        for (int i = 0; i < Dim; ++i)
          element[(a * Dim + i) * n + a * Dim + i] += factor * mass(a, b);
  }

  /// The iteration inertia of a step (set_iteration_density): the lumped mass m_a of the
  /// iteration density (once), the reference u_p = uₙ + Δt vₙ and the factor 4/Δt². (Not the
  /// Newmark predictor with Δt²/2 aₙ: the acceleration of a solid with little inertia density
  /// is noisy, and on FSI3 that predictor starts each step 50–200 times further off.)
  void prepare_iteration_inertia(const Newmark& scheme) {
    if (!iteration_mass_) {
      fem::P1Matrix lumped(mesh_, dim_);
      lumped.assemble([&](int c, double* element) {
        const int n = (dim_ + 1) * dim_;
        std::fill(element, element + n * n, 0.0);
        if (dim_ == 2)
          add_lumped_mass<2>(c, iteration_density_, element);
        else
          add_lumped_mass<3>(c, iteration_density_, element);
      });
      COAPT_PETSC_CHECK(VecDuplicate(u_, iteration_mass_.out()));
      COAPT_PETSC_CHECK(MatGetDiagonal(lumped.mat(), iteration_mass_));
      COAPT_PETSC_CHECK(VecDuplicate(u_, iteration_reference_.out()));
      COAPT_PETSC_CHECK(VecDuplicate(u_, iteration_force_.out()));
    }
    {
      WriteArray up(iteration_reference_);
      ReadArray un(u_committed_), vn(v_committed_);
      for_each_owned(iteration_reference_,
                     [&](PetscInt k) { up[k] = un[k] + scheme.step * vn[k]; });
    }
    iteration_factor_ = scheme.mass_factor();
  }

  /// iteration_force_ = 4/Δt² m_a (u − u_p) (0 on Dirichlet dofs), added to inertia_.
  void add_iteration_inertia() {
    COAPT_PETSC_CHECK(VecWAXPY(iteration_force_, -1.0, iteration_reference_, u_));
    COAPT_PETSC_CHECK(VecPointwiseMult(iteration_force_, iteration_force_, iteration_mass_));
    COAPT_PETSC_CHECK(VecScale(iteration_force_, iteration_factor_));
    zero_dirichlet(iteration_force_);
    COAPT_PETSC_CHECK(VecAXPY(inertia_, 1.0, iteration_force_));
  }

  /// Adds scale (ρ_body − ρ_offset) M_ab δ_ij (consistent P1 mass, node-major) of cell c.
  void add_element_mass(int c, double scale, double* element) const {
    const double density = body(c).density - density_offset_;
    if (density == 0) return;
    if (dim_ == 2)
      add_element_mass<2>(c, scale * density, element);
    else
      add_element_mass<3>(c, scale * density, element);
  }

  /// Contact-stabilized Newmark lumps the mass by rows (|c|/(Dim+1) per vertex), so that the
  /// projection of its predictor in the mass norm is node-wise.
  template <int Dim>
  void add_element_mass(int c, double factor, double* element) const {
    constexpr int n = (Dim + 1) * Dim;
    const auto mass = fem::element_mass<Dim>(geometry<Dim>(c));
    const bool lumped = parameters_.time.contact_stabilized;
    for (int a = 0; a <= Dim; ++a)
      for (int b = 0; b <= Dim; ++b)
        for (int i = 0; i < Dim; ++i) {
          const int column = lumped ? a : b;
          element[(a * Dim + i) * n + column * Dim + i] += factor * mass(a, b);
        }
  }

  /// a(u) into a_ and the inertia term into inertia_, from u_ and the committed state.
  /// Newmark: M a(u), a(u) = 4/Δt² (u − uₙ − Δt vₙ) − aₙ. Contact-stabilized Newmark
  /// (Deuflhard, Krause, Ertel 2008; method/notes.md): Δt vₙ is replaced by the projected
  /// predictor δ and M aₙ by f_ext − f_int(uₙ) without the contact force of step n, i.e. the
  /// term 4/Δt² M (u − uₙ − δ) + Rₙ, so that the step solves
  ///   4/Δt² M (u − uₙ − δ) + f_int(u) + f_int(uₙ) − 2 f_ext + contact = 0,
  /// and a(u) = 4/Δt² (u − uₙ − δ) − aₙ keeps v = vₙ + Δt/2 (aₙ + a) = vₙ + 2/Δt (u − uₙ − δ).
  void update_acceleration(const Newmark& scheme) {
    const bool stabilized = parameters_.time.contact_stabilized;
    {
      WriteArray a(a_);
      ReadArray u(u_), un(u_committed_), vn(v_committed_), an(a_committed_), d(predictor_);
      for_each_owned(a_, [&](PetscInt k) {
        const double v = stabilized ? d[k] / scheme.step : vn[k];
        a[k] = scheme.acceleration(u[k], un[k], v, an[k]);
      });
    }
    if (!stabilized) {
      COAPT_PETSC_CHECK(MatMult(mass_->mat(), a_, inertia_));
      return;
    }
    COAPT_PETSC_CHECK(VecWAXPY(work_, 1.0, a_, a_committed_));  // 4/Δt² (u − uₙ − δ)
    COAPT_PETSC_CHECK(MatMult(mass_->mat(), work_, inertia_));
    COAPT_PETSC_CHECK(VecAXPY(inertia_, 1.0, static_residual_));
  }

  enum class Integrand { energy, volume };

  /// ∫ ψ(F) dX or ∫ det F dX over the owned cells, summed over ranks. Collective.
  template <int Dim>
  double cell_integral(Integrand integrand) const {
    fem::LocalValues values(u_.get());
    double sum = 0;
    for (int c = 0; c < mesh_.n_owned_cells; ++c) {
      const auto g = geometry<Dim>(c);
      const MatrixD<Dim> F = deformation_gradient<Dim>(g.gradients, nodal<Dim>(values, c));
      if (integrand == Integrand::volume)
        sum += g.measure * F.determinant();
      else if constexpr (Dim == 2)
        sum += g.measure * plane_strain::energy(body(c).material, F, fibres(c));
      else
        sum += g.measure * solid::energy(body(c).material, F, fibres(c));
    }
    MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm_);
    return sum;
  }

  // --- Newton --------------------------------------------------------------------------------

  /// Newton on R(u_) = 0 from the current u_ (ghosts current) whose residual norm is
  /// report.history.back(): `jacobian()` assembles the tangent into matrix_,
  /// `residual_norm()` re-evaluates R(u_) into residual_ and returns |R| (+∞ when a cell
  /// inverts). Each update is halved while it inverts a cell; the update's Dirichlet entries
  /// are zeroed so that the prescribed dofs stay exactly as set (an iterative solve leaves
  /// round-off there). Stops at |R| ≤ max(rtol |R0|, atol) or ‖δu‖ ≤ dtol ‖u‖ (the residual of
  /// a stiff, thin body bottoms out at the round-off of the internal forces: ε times element
  /// forces that cancel at each vertex), and when the hook accepts. `where` names the step
  /// in messages, `remedy` what to try when every step inverts a cell; `verbose` logs every
  /// iteration at info level (else debug). Collective.
  template <class Jacobian, class ResidualNorm>
  void newton_solve(run::RunOutput& output, StepReport& report, Jacobian&& jacobian,
                    ResidualNorm&& residual_norm, const std::string& where,
                    const std::string& remedy, bool verbose) {
    const auto& newton = parameters_.newton;
    auto rhs = fem::create_vertex_vector(mesh_, dim_);
    auto update = fem::create_vertex_vector(mesh_, dim_);
    auto zero = fem::create_vertex_vector(mesh_, dim_);
    auto& history = report.history;
    double norm = history.back();
    const double tolerance =
        std::max(newton.relative_tolerance * history.front(), newton.absolute_tolerance);
    bool small_update = false, accepted = !hook_ || hook_->accept(u_.get());
    while ((norm > tolerance && !small_update) || !accepted) {
      if (report.newton_iterations == newton.max_iterations)
        throw ConvergenceError(
            fmt::format("solid: Newton did not converge in {} within {} iterations: |R| = [{:.3e}] "
                        "(tolerance {:.3e})",
                        where, newton.max_iterations, fmt::join(history, ", "), tolerance));
      ++report.newton_iterations;
      Mat system = nullptr;
      {
        ScopedTimer timer(output.timers(), "assemble");
        jacobian();
        COAPT_PETSC_CHECK(VecCopy(residual_, rhs));
        COAPT_PETSC_CHECK(VecScale(rhs, -1.0));
        fem::apply_dirichlet(matrix_.mat(), rhs, dirichlet_dofs_, zero);
        system = hook_ ? hook_->linear_system(u_.get(), matrix_.mat(), rhs) : matrix_.mat();
      }
      fem::SolveStats stats;
      const int factorisations = report.factorisations;
      {
        ScopedTimer timer(output.timers(), "solve");
        stats = solve_newton_system(system, rhs, update, report);
      }
      const bool kept = report.factorisations == factorisations;
      zero_dirichlet(update);
      report.linear_iterations += stats.iterations;
      double step_length = 1.0;
      COAPT_PETSC_CHECK(VecAXPY(u_, step_length, update));
      fem::update_ghosts(u_);
      norm = residual_norm();
      for (int halving = 0; !std::isfinite(norm) && halving < 12; ++halving) {
        step_length *= 0.5;
        COAPT_PETSC_CHECK(VecAXPY(u_, -step_length, update));
        fem::update_ghosts(u_);
        norm = residual_norm();
      }
      if (!std::isfinite(norm))
        throw ConvergenceError(
            fmt::format("solid: {}: every Newton step inverts a cell (|R| history [{:.3e}]); {}",
                        where, fmt::join(history, ", "), remedy));
      if (newton.line_search > 0 && norm > history.back()) {
        // newton.line_search: halve the update while it raises |R| (fem/line_search.hpp)
        const auto kept = fem::backtrack(
            newton.line_search, step_length, norm, history.back(),
            [&](double from, double to) {
              COAPT_PETSC_CHECK(VecAXPY(u_, to - from, update));
              fem::update_ghosts(u_);
            },
            residual_norm);
        norm = kept.norm;
        step_length = kept.length;
      }
      history.push_back(norm);
      accepted = !hook_ || hook_->accept(u_.get());
      PetscReal update_norm = 0, u_norm = 0;
      COAPT_PETSC_CHECK(VecNorm(update, NORM_2, &update_norm));
      COAPT_PETSC_CHECK(VecNorm(u_, NORM_2, &u_norm));
      small_update = step_length * update_norm <= newton.update_tolerance * u_norm;
      const std::string line = fmt::format(
          "{}: newton {}  |R| = {:.6e}  (|R|/|R0| = {:.3e}, |du|/|u| = {:.3e}, step {:g}, {} "
          "linear its{})",
          where, report.newton_iterations, norm, norm / history.front(),
          step_length * update_norm / u_norm, step_length, stats.iterations,
          kept ? " on the kept factorisation" : "");
      if (verbose)
        log::info("{}", line);
      else
        log::debug("{}", line);
    }
  }

  /// One Newton system: on the step's kept factorisation when newton.reuse_factorisation
  /// allows (GMRES capped at 4 N iterations; more than N, or a failure, and the next solve
  /// factors afresh), else on a new one.
  fem::SolveStats solve_newton_system(Mat system, Vec rhs, Vec update, StepReport& report) {
    const int limit = parameters_.newton.reuse_factorisation;
    if (limit > 0 && factorisation_current_) {
      solver_.set_operator(system, true);
      COAPT_PETSC_CHECK(VecSet(update, 0.0));
      try {
        const auto stats = solver_.solve(rhs, update, 4 * limit);
        if (stats.iterations > limit) factorisation_current_ = false;
        return stats;
      } catch (const ConvergenceError& error) {
        log::debug("solid: {} on the kept factorisation; factoring afresh", error.what());
      }
    }
    factorisation_current_ = false;
    solver_.set_operator(system);
    COAPT_PETSC_CHECK(VecSet(update, 0.0));
    ++report.factorisations;
    const auto stats = solver_.solve(rhs, update);
    factorisation_current_ = limit > 0;
    return stats;
  }

  // --- output --------------------------------------------------------------------------------

  /// Displacement and velocity (vertices), Cauchy stress (3×3 per cell, σ₃₃ included in plane
  /// strain), von Mises stress, det F and body (cells), plus `extra`. Collective.
  template <int Dim>
  void write_vtk(run::RunOutput& output, double time, const std::vector<io::Field>& extra) const {
    ScopedTimer timer(output.timers(), "output");
    fem::LocalValues values(u_.get());
    fem::LocalValues velocities(v_.get());
    const std::size_t n_cells = static_cast<std::size_t>(mesh_.n_owned_cells);
    std::vector<double> stress(n_cells * 9), von_mises_stress(n_cells), volume_ratio(n_cells),
        body_index(n_cells);
    for (int c = 0; c < mesh_.n_owned_cells; ++c) {
      const MatrixD<Dim> F =
          deformation_gradient<Dim>(geometry<Dim>(c).gradients, nodal<Dim>(values, c));
      const Matrix3 sigma = cauchy_stress<Dim>(body(c).material, F, fibres(c));
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          stress[static_cast<std::size_t>(c) * 9 + 3 * i + j] = sigma(i, j);
      von_mises_stress[c] = von_mises(sigma);
      volume_ratio[c] = F.determinant();
      body_index[c] = body_of_cell_[c];
    }
    std::vector<io::Field> fields = {
        {"displacement", Dim, io::Field::Location::vertex, values.values()},
        {"cauchy_stress", 9, io::Field::Location::cell, stress},
        {"von_mises_stress", 1, io::Field::Location::cell, von_mises_stress},
        {"volume_ratio", 1, io::Field::Location::cell, volume_ratio},
        {"body", 1, io::Field::Location::cell, body_index},
    };
    if (mass_)
      fields.push_back({"velocity", Dim, io::Field::Location::vertex, velocities.values()});
    if (parameters_.mixed)
      fields.push_back({"pressure", 1, io::Field::Location::vertex, mixed_pressure()});
    // Reference fibre directions a₀ of each family, where some body has that family.
    for (int f = 0; f < kMaxFibreFamilies; ++f) {
      bool present = false;
      for (const auto& b : parameters_.bodies)
        if (const auto* law = std::get_if<FibreReinforced>(&b.material))
          present = present || law->n_fibre_families > f;
      if (!present) continue;
      std::vector<double> directions(n_cells * 3);
      for (std::size_t c = 0; c < n_cells; ++c)
        for (int i = 0; i < 3; ++i) directions[c * 3 + i] = fibres_of_cell_[c].a0[f](i);
      fields.push_back({f == 0 ? "fibre_direction" : "second_fibre_direction", 3,
                        io::Field::Location::cell, std::move(directions)});
    }
    fields.insert(fields.end(), extra.begin(), extra.end());
    output.vtk("solid").write(mesh_, time, fields);
  }

  SolidParameters parameters_;
  bool driver_dynamic_ = false;  ///< SolidModelOptions::driver_dynamic: the driver steps it
  MPI_Comm comm_;
  mesh::QualityReport quality_;
  mesh::Mesh mesh_;
  int dim_;
  int rank_ = 0;
  std::vector<int> body_of_cell_;
  std::vector<FibreDirections> fibres_of_cell_;  ///< per local cell
  std::vector<PressureFacet> pressure_facets_;   ///< grouped by local cell
  std::vector<int> pressure_offset_;             ///< CSR offsets into it (empty: no pressures)
  double pressure_factor_ = 1.0;                 ///< load factor of the last residual
  // Mixed formulation (parameters_.mixed): state (u, p) per vertex, residual, matrix, solver.
  OwnedVec mixed_state_, mixed_residual_;
  std::optional<fem::P1Matrix> mixed_matrix_;
  std::optional<MixedLinearSolver> mixed_solver_;
  std::vector<PetscInt> mixed_dirichlet_dofs_;  ///< owned, in the (Dim+1)-component layout
  std::vector<double> cell_size_;               ///< longest edge of each local cell [m]
  double pressure_scale_ = 1.0;                 ///< S: the mixed state holds p / S [Pa]
  std::vector<PetscInt> dirichlet_dofs_;        ///< owned, sorted
  std::vector<double> dirichlet_values_;        ///< final value of each, [m]
  /// The condition that prescribes each (its ramp interval); points into parameters_.
  std::vector<const DirichletParameters*> dirichlet_conditions_;
  std::vector<ProbeLocation> probes_;

  OwnedVec u_, v_, a_;                                ///< trial state
  OwnedVec u_committed_, v_committed_, a_committed_;  ///< uₙ, vₙ, aₙ
  OwnedVec external_;                                 ///< f_ext at load factor 1
  OwnedVec residual_, inertia_;
  // contact-stabilized Newmark: the projected predictor increment δ, Rₙ, a work vector
  OwnedVec predictor_, static_residual_, work_;
  OwnedVec warm_start_, predicted_;  ///< step(from_current): the last solve's state, the predictor
  OwnedVec previous_static_;         ///< uₙ₋₁ of newton.predictor: extrapolate
  std::array<double, 2> static_factors_{0, 0};  ///< sₙ₋₁, sₙ of the converged static steps
  fem::P1Matrix matrix_;
  std::optional<fem::P1Matrix> mass_;  ///< inertia-density mass (dynamics only)
  OwnedVec lumped_mass_;               ///< its diagonal (contact-stabilized predictor)
  fem::LinearSolver solver_;
  /// newton.reuse_factorisation: solver_ holds a factorisation of this time step to reuse
  bool factorisation_current_ = false;
  Vec extra_force_ = nullptr;        ///< not owned
  Vec immersed_pressure_ = nullptr;  ///< not owned: the fluid's pressure it carries [Pa]
  NewtonHook* hook_ = nullptr;       ///< not owned
  double density_offset_ = 0;
  // set_iteration_density: the density, its lumped mass m_a, u_p of the step, 4/Δt², and
  // 4/Δt² m_a (u − u_p) of the last residual
  double iteration_density_ = 0, iteration_factor_ = 0;
  OwnedVec iteration_mass_, iteration_reference_, iteration_force_;
};

}  // namespace detail

SolidModel::SolidModel(const config::Section& root, MPI_Comm comm, const SolidModelOptions& options)
    : impl_(std::make_unique<detail::SolidModelImpl>(root, comm, options)) {}
SolidModel::~SolidModel() = default;

const mesh::Mesh& SolidModel::mesh() const {
  return impl_->mesh();
}
int SolidModel::dim() const {
  return impl_->dim();
}
MPI_Comm SolidModel::comm() const {
  return impl_->comm();
}
const SolidParameters& SolidModel::parameters() const {
  return impl_->parameters();
}
const mesh::QualityReport& SolidModel::quality() const {
  return impl_->quality();
}
void SolidModel::describe() const {
  impl_->describe();
}
const std::vector<int>& SolidModel::body_of_cell() const {
  return impl_->body_of_cell();
}
const std::vector<PetscInt>& SolidModel::dirichlet_dofs() const {
  return impl_->dirichlet_dofs();
}
Vec SolidModel::displacement() const {
  return impl_->displacement();
}
Vec SolidModel::velocity() const {
  return impl_->velocity();
}
Vec SolidModel::acceleration() const {
  return impl_->acceleration();
}
void SolidModel::set_external_force(Vec force) {
  impl_->set_external_force(force);
}
void SolidModel::set_hook(NewtonHook* hook) {
  impl_->set_hook(hook);
}
void SolidModel::set_immersed_pressure(Vec pressure) {
  impl_->set_immersed_pressure(pressure);
}
void SolidModel::set_iteration_density(double density) {
  impl_->set_iteration_density(density);
}
void SolidModel::iteration_force(Vec out) const {
  impl_->iteration_force(out);
}
void SolidModel::set_density_offset(double offset) {
  impl_->set_density_offset(offset);
}
StepReport SolidModel::solve_static(double load_factor, run::RunOutput& output,
                                    const std::string& label, bool verbose) {
  return impl_->solve_static(load_factor, output, label, verbose);
}
void SolidModel::initialize_dynamics(run::RunOutput& output) {
  impl_->initialize_dynamics(output);
}
StepReport SolidModel::step(double time, double time_step, run::RunOutput& output,
                            bool from_current) {
  return impl_->step(time, time_step, output, from_current);
}
void SolidModel::commit() {
  impl_->commit();
}
void SolidModel::restore() {
  impl_->restore();
}
void SolidModel::write_checkpoint(run::CheckpointWriter& writer, const std::string& prefix) const {
  impl_->write_checkpoint(writer, prefix);
}
void SolidModel::read_checkpoint(const run::CheckpointReader& reader, const std::string& prefix) {
  impl_->read_checkpoint(reader, prefix);
}
std::vector<std::vector<double>> SolidModel::probe_values() const {
  return impl_->probe_values();
}
void SolidModel::set_contact_stabilized(bool contact_stabilized) {
  impl_->set_contact_stabilized(contact_stabilized);
}
std::vector<BodyMotion> SolidModel::body_motion() const {
  return impl_->body_motion();
}
double SolidModel::kinetic_energy() const {
  return impl_->kinetic_energy();
}
double SolidModel::strain_energy() const {
  return impl_->strain_energy();
}
double SolidModel::external_work() const {
  return impl_->external_work();
}
double SolidModel::volume() const {
  return impl_->volume();
}
std::array<double, 9> SolidModel::mean_deformation_gradient() const {
  return impl_->mean(detail::SolidModelImpl::Average::deformation_gradient);
}
std::array<double, 9> SolidModel::mean_cauchy_stress() const {
  return impl_->mean(detail::SolidModelImpl::Average::cauchy_stress);
}
std::vector<double> SolidModel::reaction_force(const std::string& boundary) const {
  return impl_->reaction_force(boundary);
}
double SolidModel::surface_swept_volume(const std::string& boundary) const {
  return impl_->surface_swept_volumes(boundary, {}, 1)[0];
}
std::vector<double> SolidModel::surface_swept_volumes(const std::string& boundary,
                                                      std::span<const char> vertex_levels,
                                                      int n_levels) const {
  return impl_->surface_swept_volumes(boundary, vertex_levels, n_levels);
}
std::vector<double> SolidModel::current_coordinates() const {
  return impl_->current_coordinates();
}
void SolidModel::write_vtk(run::RunOutput& output, double time,
                           const std::vector<io::Field>& extra) const {
  impl_->write_vtk(output, time, extra);
}

}  // namespace coapt::solid
