#pragma once
/// @file fluid_model.hpp
/// The fluid of a case as a reusable model: it reads the fluid keys (mesh, material and
/// Newton settings, velocity boundary conditions, outlets with their Windkessels, pressure
/// reference) from a section of the case, loads the mesh, and steps the flow one BDF step at
/// a time through NavierStokes. Drivers build on it: `problem: navier_stokes`
/// (flow_problem.cpp) and the immersed coupling (coupling/), which sets a velocity constraint
/// between Newton solves, reads its reactions and repeats a step from the same history.
///
/// Time stepping. The model keeps the committed history uⁿ, uⁿ⁻¹ (and the Windkessel states
/// at tⁿ); the state vector is the trial uⁿ⁺¹:
///
///   model.start(0.0);                      // writes the boundary values at t = 0
///   for each step:
///     model.begin_step(dt);                // t = tⁿ + dt: boundary values, outlet relations
///     ... model.solve(label) as often as the caller likes (constraint set in between) ...
///     model.commit_step();                 // uⁿ⁻¹ ← uⁿ, uⁿ ← state, Windkessels advanced
///   or model.restore_step();               // state ← uⁿ, time ← tⁿ (nothing committed)
///
/// A steady case calls solve_steady() once instead.

#include <mpi.h>
#include <petscvec.h>

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/core/petsc.hpp"
#include "coapt/fluid/navier_stokes.hpp"
#include "coapt/io/csv_series.hpp"
#include "coapt/io/vtk_writer.hpp"
#include "coapt/lumped/windkessel.hpp"
#include "coapt/mesh/mesh.hpp"
#include "coapt/mesh/mesh_input.hpp"
#include "coapt/mesh/quality.hpp"
#include "coapt/run/checkpoint.hpp"
#include "coapt/run/run_output.hpp"

namespace coapt::fluid {

/// A periodic or tabulated factor in time: none (1), sinusoid 1 + a sin(2πt/T), or a table
/// linear between its points (repeated with `period` when > 0, else holding its ends), given
/// in the case (`table`) or read from a CSV file of time, factor rows (`csv`). Steady solves
/// (t = ∞) take 1.
struct TimeWaveform {
  enum class Kind { none, sinusoid, table };
  Kind kind = Kind::none;
  double amplitude = 0;                ///< sinusoid: a
  double period = 0;                   ///< sinusoid, table: T [s] (table: 0 = not periodic)
  std::vector<double> times, factors;  ///< table: factor(t), linear in between
  /// The factor at time t [s]; 1 when t is not finite (steady).
  double factor(double time) const;
  /// Reads a `waveform:` section (`type`, `amplitude`, `period`, `times`, `values`, `file`).
  static TimeWaveform read(const config::Section& section);
  /// Parses CSV text of `time, factor` rows (`#` comments, blank lines and one header line
  /// allowed) into times and factors; throws InputError naming `name`:line of a bad row.
  static void parse_csv(const std::string& text, const std::string& name,
                        std::vector<double>& times, std::vector<double>& factors);
};

/// One entry of `boundary:`; later entries override earlier ones at shared vertices.
struct BoundaryCondition {
  enum class Type { velocity, no_slip, outflow };
  enum class Profile { constant, parabolic, rectangle, radial };
  std::string group;
  std::string where;  ///< file:line of the entry
  Type type = Type::no_slip;
  Profile profile = Profile::constant;
  std::vector<double> value;     ///< velocity (peak for parabolic) [m/s]
  std::vector<double> from, to;  ///< parabolic: the two ends; rectangle: opposite corners [m]
  double ramp_time = 0;          ///< > 0: value × (1 − cos(π min(t/T, 1)))/2 [s]
  std::vector<double> centre;    ///< radial: the axis point of the inlet plane [m]
  double radius = 0;             ///< radial: value × (1 − r²/radius²) [m]
  TimeWaveform waveform;         ///< value × waveform.factor(t)
};

/// An entry of `outlets:`: the pressure on a facet group, fixed or from a Windkessel.
struct OutletCondition {
  enum class Type { do_nothing, traction, windkessel };
  std::string group;
  std::string where;
  Type type = Type::do_nothing;
  double pressure = 0;    ///< traction: P [Pa], times waveform.factor(t)
  TimeWaveform waveform;  ///< traction: P(t) = pressure × factor(t) (e.g. a pressure-driven inlet)
  lumped::WindkesselParameters windkessel;
  double backflow = 0;  ///< β
};

/// The fluid keys of a case, read once.
struct FluidCase {
  mesh::MeshInput mesh;
  FluidParameters fluid;
  std::vector<BoundaryCondition> boundary;
  std::vector<OutletCondition> outlets;
  bool has_pressure_reference = false;
  std::vector<double> pressure_reference;  ///< the vertex nearest to it gets p = 0

  /// Reads `mesh`, `boundary`, `outlets`, `pressure_reference` from `section` and the
  /// material and Newton keys (density, viscosity, convection, c_inverse, newton) from
  /// `properties` (the same section, or a sub-section such as `fluid` of the root).
  static FluidCase read(const config::Section& section, const config::Section& properties);
};

/// The `time` section: steady, or BDF steps of a fixed size up to end_time.
struct TimeSettings {
  bool steady = true;
  double end_time = 0;   ///< [s]
  double time_step = 0;  ///< [s]
  /// Reads `time` (steady, end_time, step) from `root`.
  static TimeSettings read(const config::Section& root);
  /// Number of steps to reach end_time (the last one may be shorter).
  int n_steps() const;
  /// The step from `time`: time_step, or what is left to end_time when that is shorter by
  /// more than round-off. A run that ends at a multiple of the step thus takes the same steps
  /// as a longer run, so that a restart from its last checkpoint continues bit for bit.
  double step_from(double time) const;
};

/// Values of component `component` of a vertex vector with `n_components` per vertex at
/// `points` (n × dim, row-major), each from the owned cell that contains it (NaN where none
/// does; the lowest rank's value on partition boundaries). Collective.
std::vector<double> values_at(const mesh::Mesh& mesh, Vec vector, int n_components, int component,
                              const std::vector<double>& points);

/// The fluid of a case. Every call is collective on the mesh's communicator unless noted.
class FluidModel {
 public:
  /// Loads and distributes the mesh and checks the groups the case names (InputError naming
  /// the entry). `level_offset` is added to the mesh's refinement level.
  FluidModel(FluidCase parameters, MPI_Comm comm, int level_offset = 0);
  FluidModel(const FluidModel&) = delete;
  FluidModel& operator=(const FluidModel&) = delete;
  ~FluidModel();

  const FluidCase& parameters() const { return parameters_; }
  const mesh::Mesh& mesh() const { return mesh_; }
  MPI_Comm comm() const { return comm_; }
  /// Logs the mesh, its quality and the material. Not collective (rank 0 logs).
  void describe(const std::string& title) const;

  /// Per owned vertex, 1 where a velocity condition of `boundary` (velocity, no_slip) holds,
  /// else 0 (after start()). Not collective.
  std::vector<char> velocity_condition_vertices() const;
  /// Facet tag of the boundary group `name`; InputError naming `key` and the groups there are.
  int boundary_tag(const std::string& name, const std::string& key) const;

  /// Creates the operator, Dirichlet dofs and outlets, and writes the boundary values at
  /// `time` into the state (the initial condition uⁿ = u⁰; transient runs).
  void start(double time = 0.0);
  /// The operator (after start()).
  NavierStokes& navier_stokes() { return *fluid_; }
  /// The state (u, p interleaved, ghosted; the trial uⁿ⁺¹ during a step).
  Vec state() const { return fluid_->state(); }
  /// The time level of the current solve (steady: time_step 0).
  const TimeLevel& level() const { return level_; }
  /// Time of the trial state [s] (tⁿ⁺¹ during a step, tⁿ after commit/restore).
  double time() const { return time_; }
  /// Steps committed so far.
  int steps() const { return steps_; }

  /// Steady problem: boundary values at t = ∞, steady outlet resistances, Newton solve.
  NewtonReport solve_steady(const std::string& label);
  /// Starts a step of size dt from the committed state: time tⁿ + dt, BDF1 on the first step
  /// and BDF2 after, boundary values and outlet relations at the new time.
  void begin_step(double dt);
  /// Newton solve of the current step (or steady problem); throws ConvergenceError.
  NewtonReport solve(const std::string& label);
  /// Accepts the trial state: history shift, Windkessels advanced with the outlet flows.
  void commit_step();
  /// Drops the trial state: state ← uⁿ, time ← tⁿ, Windkessels untouched.
  void restore_step();

  /// Adds the committed history to a checkpoint: fields fluid_u (uⁿ) and fluid_u_before
  /// (uⁿ⁻¹), and under state["fluid"] the steps, tⁿ, the last step size (the variable-step
  /// BDF2 weights) and each Windkessel's state by outlet group.
  void write_checkpoint(run::CheckpointWriter& writer) const;
  /// After start(): takes that history back (state ← uⁿ), so that the next begin_step
  /// continues as the run that wrote it did. InputError naming the checkpoint folder when it
  /// is of another mesh or its Windkessels are not this case's outlets.
  void read_checkpoint(const run::CheckpointReader& reader);

  /// Constrains the velocity at owned local vertices (vertices.size() × dim velocities, row
  /// major) [m/s] for the following solves; `cell_coverage` per owned cell, the fraction the
  /// solids cover (NavierStokes::set_velocity_constraint).
  void set_velocity_constraint(std::span<const int> vertices, std::span<const double> velocities,
                               std::span<const double> cell_coverage = {});
  /// The force the fluid exerts on the constraint at each constrained vertex (same layout)
  /// at the current state [N/m in 2D, N in 3D].
  std::vector<double> constraint_reactions();
  /// Draws the velocity at owned local vertices towards targets by a penalty of the given
  /// weights and inertial time scale (NavierStokes::set_velocity_penalty) for the following
  /// solves.
  void set_velocity_penalty(std::span<const int> vertices, std::span<const double> weights,
                            std::span<const double> targets, double time_scale = 0.0);
  /// The force the fluid exerts on each penalty entry (same layout) at the current state.
  std::vector<double> penalty_reactions();
  /// Force of the fluid on the boundary group with facet tag `tag` at the current state: the
  /// residual of the step being solved, or, after commit_step() (and after restore_step()),
  /// that of the committed step with its own BDF history. A state read from a checkpoint and
  /// not stepped since is evaluated without its time derivative (uⁿ⁻² is not stored).
  std::vector<double> boundary_force(int tag);

  /// Outlet k's flow Q and pressure P at the current state.
  double outlet_flow(std::size_t k) const { return fluid_->outlet_flow(k); }
  double outlet_pressure(std::size_t k) const { return fluid_->outlet_pressure(k); }
  /// The Windkessel state of outlet k (null when it has none) for a summary or a restart.
  const lumped::Windkessel* windkessel(std::size_t k) const { return windkessels_[k].get(); }
  /// Series columns: flow_<group> of each velocity group, outlet_flow_<group> and
  /// outlet_pressure_<group> of each outlet.
  void record_flows(io::CsvSeries& series) const;
  /// Writes `windkessel_state` (per outlet group) into the summary.
  void write_windkessel_states(run::RunOutput& output) const;
  /// Kinetic energy ½ ∫ ρ |u|² of the current state (lumped P1 mass) [J/m in 2D, J].
  double kinetic_energy() const;
  /// Velocity, pressure and `reaction` (the force of the fluid at each vertex whose velocity
  /// is prescribed, NavierStokes::vertex_reactions, of the same step as boundary_force) and
  /// `extra` fields of this mesh as VTK (series `name`) at `time`. Collective.
  void write_vtk(run::RunOutput& output, double time, const std::vector<io::Field>& extra = {},
                 const std::string& name = "solution");

 private:
  void setup_dirichlet();
  void setup_outlets();
  void set_outlet_pressures(double dt);
  void write_boundary_values(double time);
  std::string boundary_group_names() const;
  /// The time level of the current state's residual: the committed step's after a commit.
  const TimeLevel& force_level() const {
    return committed_level_valid_ ? committed_level_ : level_;
  }

  const FluidCase parameters_;
  MPI_Comm comm_;
  mesh::QualityReport quality_;
  mesh::Mesh mesh_;
  std::vector<int> tags_;                 ///< facet tag of each boundary entry
  std::vector<int> outlet_tags_;          ///< facet tag of each outlet entry
  std::vector<int> condition_of_vertex_;  ///< per owned vertex: the boundary entry, or −1
  std::unique_ptr<NavierStokes> fluid_;
  std::vector<std::unique_ptr<lumped::Windkessel>> windkessels_;  ///< per outlet, or null
  OwnedVec previous_, before_;                                    ///< committed uⁿ, uⁿ⁻¹
  OwnedVec oldest_;  ///< uⁿ⁻² after a commit: the committed step's own history
  TimeLevel level_;
  /// The time level with which the committed state uⁿ was solved (its history before_ and
  /// oldest_): forces read after commit_step() are residuals of that step, not of a step whose
  /// history already holds uⁿ. Valid while committed_level_valid_.
  TimeLevel committed_level_;
  bool committed_level_valid_ = false;
  double time_ = 0, committed_time_ = 0, last_step_ = 0;
  int steps_ = 0;
};

}  // namespace coapt::fluid
