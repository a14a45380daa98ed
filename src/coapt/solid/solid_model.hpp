#pragma once
/// @file solid_model.hpp
/// The solid as a reusable object: finite-strain P1 elasticity (total Lagrangian, plane strain
/// in 2D) on one distributed mesh with one or more bodies, Dirichlet conditions, dead loads,
/// probes, and two ways to advance it:
///
///  - quasi-static: solve_static(s) solves R(u) = f_int(u) − s f_ext − f_extra = 0 at load
///    factor s (prescribed displacements ramped with s);
///  - dynamic (Newmark β = 1/4, γ = 1/2, dynamics.hpp): initialize_dynamics() computes a₀, then
///    step(t, Δt) solves M a(u) + f_int(u) − f_ext − f_extra = 0 for the *trial* state from the
///    *committed* state (uₙ, vₙ, aₙ). step() may be repeated (coupling iterations: a new
///    extra force, the same step) until commit() accepts the trial state; restore() returns the
///    trial state to the committed one.
///
/// Three ways to act on the solid from outside:
///  - set_external_force(f): an extra nodal force vector f_extra (a vertex vector of this
///    mesh, node-major, dim components) in every residual, not ramped with the load factor
///    (the transferred fluid force of the immersed coupling);
///  - set_immersed_pressure(p): a pressure field over the solid whose load −∫ p div_x w
///    follows its deformation (the fluid's pressure a compressible immersed solid carries);
///  - set_hook(h): a NewtonHook whose terms enter every Newton iteration (contact).
///
/// Immersed solids carry the density ρ_body − ρ_offset in their inertia (set_density_offset;
/// the fluid mesh carries ρ_f over the overlap). Gravity keeps the full body density.
///
/// Every call is collective on comm(). Vectors are ghosted vertex vectors of mesh() with dim()
/// components per vertex (fem::create_vertex_vector); the ghost entries of the state vectors
/// are current after every call that changes them.
///
///   solid::SolidModel solid(root, comm);             // reads `problem: solid` case keys
///   solid.initialize_dynamics(output);
///   for (...) { solid.set_external_force(f); solid.step(t, dt, output); solid.commit(); }

#include <mpi.h>
#include <petscmat.h>
#include <petscvec.h>

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/io/vtk_writer.hpp"
#include "coapt/mesh/mesh.hpp"
#include "coapt/mesh/quality.hpp"
#include "coapt/run/checkpoint.hpp"
#include "coapt/run/run_output.hpp"
#include "coapt/solid/solid_parameters.hpp"

namespace coapt::solid {

/// Extra terms in the solid's Newton iteration (e.g. contact). Every call is collective.
class NewtonHook {
 public:
  virtual ~NewtonHook() = default;
  /// Once per load or time step, before Newton starts from `u` (the predictor).
  virtual void begin_step(Vec u) { (void)u; }
  /// Adds the hook's terms to the residual R(u) (owned entries of `residual`; its Dirichlet
  /// rows are zeroed afterwards).
  virtual void add_residual(Vec u, Vec residual) {
    (void)u;
    (void)residual;
  }
  /// Called each Newton iteration with the assembled tangent K and rhs = −R (Dirichlet rows
  /// and columns already eliminated): may change rhs and returns the matrix to solve with
  /// (K itself, or a matrix the hook owns).
  virtual Mat linear_system(Vec u, Mat K, Vec rhs) {
    (void)u;
    (void)rhs;
    return K;
  }
  /// After each Newton update: false keeps Newton iterating even when the residual is below
  /// tolerance (e.g. the active set changed).
  virtual bool accept(Vec u) {
    (void)u;
    return true;
  }
  /// Contact-stabilized Newmark, once per step before begin_step: projects the predictor
  /// increment δ (owned entries; Δt vₙ on entry) from the committed displacement `u` onto
  /// the admissible set, in place, in the norm of `lumped_mass` (the lumped inertia mass per
  /// dof, same layout).
  virtual void project_predictor(Vec u, Vec increment, Vec lumped_mass) {
    (void)u;
    (void)increment;
    (void)lumped_mass;
  }
};

/// Mass, barycentre and momenta of one body in the current configuration, from the row-sum
/// lumped mass with the body's full density (ρ |c|/(Dim+1) per vertex of each cell c):
/// x̄ = Σ m_a x_a / Σ m_a, p = Σ m_a v_a, L = Σ m_a x_a × v_a about the origin (2D: only the
/// z component is non-zero). Units: kg (kg/m in 2D), m, kg m/s, kg m²/s.
struct BodyMotion {
  std::string name;
  double mass = 0;
  std::array<double, 3> barycentre{}, momentum{}, angular_momentum{};
};

/// What one load step or time step did.
struct StepReport {
  int newton_iterations = 0;
  int linear_iterations = 0;    ///< summed over the Newton iterations
  int factorisations = 0;       ///< new preconditioners (newton.reuse_factorisation: fewer)
  std::vector<double> history;  ///< ‖R‖ over the free dofs, one per iterate
  double norm() const { return history.empty() ? 0.0 : history.back(); }
};

/// What a driver that owns the solid sets when it builds it (the immersed coupling, whose
/// `solids[]` entry has the solid's keys but no `time:` of its own); a `problem: solid` case
/// takes the defaults.
struct SolidModelOptions {
  /// Refinement levels added to the solid's mesh.level (the coupling's global mesh.level).
  int extra_mesh_levels = 0;
  /// The key named when those levels cannot be added (a mesh read from a .msh file).
  std::string extra_levels_key = "mesh.level";
  /// The driver advances the solid by step() with its own time steps: the solid is dynamic
  /// (Newmark, mass, the direct linear solver of `time.scheme: newmark`) without `time:` keys.
  bool driver_dynamic = false;
};

namespace detail {
class SolidModelImpl;
}

/// The solid: see the file comment.
class SolidModel {
 public:
  /// Reads every key of a `problem: solid` case section (SolidParameters), loads and
  /// distributes the mesh, assigns bodies, collects Dirichlet dofs and locates probes.
  /// InputError naming the key, group or point on bad input. `options`: what a driver owning
  /// the solid sets (SolidModelOptions).
  SolidModel(const config::Section& root, MPI_Comm comm, const SolidModelOptions& options = {});
  SolidModel(const SolidModel&) = delete;
  SolidModel& operator=(const SolidModel&) = delete;
  ~SolidModel();

  const mesh::Mesh& mesh() const;
  int dim() const;
  MPI_Comm comm() const;
  const SolidParameters& parameters() const;
  const mesh::QualityReport& quality() const;
  /// Logs sizes, bodies, the time scheme and Newton settings.
  void describe() const;
  /// Body index (into parameters().bodies) of each local cell.
  const std::vector<int>& body_of_cell() const;
  /// Owned global dofs with a prescribed displacement (ascending).
  const std::vector<PetscInt>& dirichlet_dofs() const;

  /// The trial state: displacement u, velocity v, acceleration a.
  Vec displacement() const;
  Vec velocity() const;
  Vec acceleration() const;

  /// An extra nodal force in every residual (null: none). The vector must live until it is
  /// replaced; only its owned entries are read.
  void set_external_force(Vec force);
  /// The immersed coupling's fluid pressure over the solid (null: none;
  /// coupling.pressure_in_solid): a ghosted vertex vector of this mesh with one component [Pa], p
  /// at each vertex, which enters every residual as the load −∫ p div_x w over the current
  /// configuration (a follower load with its exact tangent; no resultant; under a uniform p the
  /// surface load −p n). Not owned; it must live until replaced. Not with formulation: mixed
  /// (InputError).
  void set_immersed_pressure(Vec pressure);
  /// The Newton hook (null: none). Not owned.
  void set_hook(NewtonHook* hook);
  /// Inertia uses the density ρ_body − offset [kg/m³] (≥ 0 for every body, else InputError).
  /// Call before initialize_dynamics().
  void set_density_offset(double offset);
  /// Iteration inertia for a driver that repeats step() (the coupling iterations): step()
  /// solves with the extra term 4/Δt² m_a (u − u_p), m_a the row-lumped mass of `density`
  /// over the whole solid and u_p = uₙ + Δt vₙ, fixed within the step. The term is
  /// an artificial mass against the change of the load from one iteration to the next; the
  /// driver loads the solid with f + iteration_force() of the last iterate, so that at its
  /// fixed point the term cancels (0: none, the default).
  void set_iteration_density(double density);
  /// 4/Δt² m_a (u − u_p) of the trial state after step() (0 on Dirichlet dofs; 0 without an
  /// iteration density). `out`: a vertex vector of this mesh. Collective.
  void iteration_force(Vec out) const;
  /// The time scheme of step(): plain Newmark (false) or contact-stabilized Newmark (true),
  /// for drivers that choose it themselves (the immersed coupling). Call before
  /// initialize_dynamics().
  void set_contact_stabilized(bool contact_stabilized);

  /// One quasi-static load step at load factor s (0 < s ≤ 1). Throws ConvergenceError with
  /// the residual history when Newton fails. `verbose` logs every Newton iteration.
  StepReport solve_static(double load_factor, run::RunOutput& output, const std::string& label,
                          bool verbose = true);

  /// u₀ (Dirichlet values, else 0), v₀ (the case's initial velocity on free dofs), a₀ from
  /// M a₀ = f_ext − f_int(u₀) (0 where there is no mass); commits that state.
  void initialize_dynamics(run::RunOutput& output);
  /// One Newmark step of size Δt from the committed state into the trial state (time = the
  /// new time, for messages). Throws ConvergenceError with the history when Newton fails.
  /// `from_current`: Newton starts from the trial state the last call left (a coupling
  /// iteration's previous solve of the same step, near this one's solution) when its residual
  /// is below the predictor's; the tolerance stays relative to the predictor's residual, so the
  /// start changes the path, not the accuracy.
  StepReport step(double time, double time_step, run::RunOutput& output, bool from_current = false);
  /// The trial state becomes the committed state.
  void commit();
  /// The trial state is reset to the committed state.
  void restore();

  /// Adds the committed state (fields `prefix`u, `prefix`v, `prefix`a) to a checkpoint.
  void write_checkpoint(run::CheckpointWriter& writer, const std::string& prefix = "solid_") const;
  /// Reads the committed state back (after initialize_dynamics()); the trial state equals it.
  void read_checkpoint(const run::CheckpointReader& reader, const std::string& prefix = "solid_");

  /// Displacement at each probe of the case (every rank gets every value).
  std::vector<std::vector<double>> probe_values() const;
  /// ½ vᵀ M v with the inertia density (0 before initialize_dynamics) [J, or J/m in 2D].
  double kinetic_energy() const;
  /// ∫ ψ(F) dX [J, or J/m in 2D].
  double strain_energy() const;
  /// f_extᵀ u at load factor 1 (the work of the dead loads).
  double external_work() const;
  /// Current volume ∫ det F dX [m³, or m² in 2D].
  double volume() const;
  /// Mass, barycentre and momenta of every body (BodyMotion; the same on every rank).
  /// Collective.
  std::vector<BodyMotion> body_motion() const;
  /// Volume averages over the bodies: ∫ F dX / ∫ dX and ∫ σ dx / ∫ dx (current volume),
  /// 3×3 row-major (F₃₃ = 1 and σ₃₃ included in plane strain).
  std::array<double, 9> mean_deformation_gradient() const;
  std::array<double, 9> mean_cauchy_stress() const;
  /// Reaction on a boundary group: Σ over its vertices of the internal force f_int(u) (the
  /// force the supports exert on the body, per unit thickness in 2D) [N], dim() components.
  /// InputError when the group does not exist. Collective.
  std::vector<double> reaction_force(const std::string& boundary) const;
  /// The volume a boundary group sweeps as each of its points moves on a straight line from
  /// the committed configuration X + uₙ to the trial one X + u, counted positive where it moves
  /// along n, the outward normal of the body [m³, or m² in 2D]. Exact for P1 facets; over the
  /// whole boundary it is the change of volume(). Divided by Δt it is the rate at which that
  /// surface sweeps the space outside the body over the step, in step with the displacement
  /// (the trial velocity's flux ∫ v·n da need not be: contact-stabilized Newmark corrects u
  /// without v). InputError when the group does not exist. Collective.
  double surface_swept_volume(const std::string& boundary) const;
  /// The same volume split by level, in one pass: `vertex_levels` gives each local vertex
  /// (owned and ghost) a level in [0, n_levels), a facet takes the largest level of its
  /// vertices, and entry l is the volume the group's facets of level l sweep (n_levels
  /// entries). Collective.
  std::vector<double> surface_swept_volumes(const std::string& boundary,
                                            std::span<const char> vertex_levels,
                                            int n_levels) const;
  /// The current coordinates X + u of the local vertices (owned and ghost), row-major.
  std::vector<double> current_coordinates() const;

  /// Displacement, velocity, Cauchy and von Mises stress, det F and body index into the
  /// output's "solid" series at `time`, plus `extra` fields (vertex or owned-cell fields of
  /// this mesh, e.g. a contact pressure).
  void write_vtk(run::RunOutput& output, double time,
                 const std::vector<io::Field>& extra = {}) const;

 private:
  std::unique_ptr<detail::SolidModelImpl> impl_;
};

}  // namespace coapt::solid
