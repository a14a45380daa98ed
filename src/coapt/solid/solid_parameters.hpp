#pragma once
/// @file solid_parameters.hpp
/// The case sections of `problem: solid`, read once into a const struct:
///
///   mesh: {...}                        (mesh_input.hpp)
///   bodies:                            one or more; each cell belongs to one body
///     - name: membrane
///       cell_groups: [domain]          mesh cell groups (omitted: every cell no other body has)
///       density: 1000                  kg/m³ (for gravity; later for inertia)
///       material: {model: neo_hookean, young_modulus: ..., poisson_ratio: ...}
///       fibre_direction: [1, 0, 0]     fibre_reinforced only (second_fibre_direction too),
///       fibres: {rule: circumferential, axis: [0, 0, 1]}   or per rule (fibre_field.hpp)
///   dirichlet:
///     - {boundary: left}                              all components fixed
///     - {boundary: top, components: [y], displacement: [0.001]}   ramped with the load
///     - {boundary: top, components: [x], displacement: [0.002], ramp: [0.5, 1]}
///                                      ramped over that part of the load factor only
///   tractions:                         dead loads on the reference boundary, ramped
///     - {boundary: right, traction: [0, 62500]}       Pa (force per reference area/length)
///     - {boundary: right, total_force: [0, 1]}        N (3D) or N/m (2D): spread uniformly
///   pressures:                         follower loads −p n da on the current boundary, ramped
///     - {boundary: inner, pressure: 1000}             Pa
///   gravity: [0, -2]                   m/s², body force ρ g, ramped
///   formulation: displacement          or mixed (P1-P1 u-p, nearly incompressible laws)
///   steps: 10                          load steps (load factor k/steps; static only)
///   time: {scheme: newmark, step: 0.005, end_time: 10, initial_velocity: [0, 0.1]}
///                                      dynamics (dynamics.hpp); scheme: static (default),
///                                      newmark or contact_stabilized_newmark;
///                                      bodies[].initial_velocity overrides it per body
///   impacts: {body: ball}              dynamics with contact: rebound angles and energy loss
///                                      of each impact of that body (solid_problem.cpp)
///   newton: {relative_tolerance, absolute_tolerance, update_tolerance, max_iterations,
///            predictor: previous | extrapolate, line_search: 0}
///   probes: [{name: tip, point: [0.048, 0.060]}]
///   reactions: [base, top]             boundary groups whose reaction force is reported
///   uniaxial_reference: {axis: [1, 0, 0], reaction_boundary: right, reference_area: 1e-6}
///   lame_reference: {inner_radius: 0.01, outer_radius: 0.02, inner_probe: a, outer_probe: b}
///   output: {vtk: true, vtk_interval: 10, checkpoint_interval: 100}
///                                      (time steps between VTK files / checkpoints)

#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/mesh/mesh_input.hpp"
#include "coapt/solid/fibre_field.hpp"
#include "coapt/solid/materials.hpp"

namespace coapt::solid {

/// One solid body: a set of mesh cells with its material.
struct BodyParameters {
  std::string name;
  std::vector<std::string> cell_groups;  ///< empty: the cells no other body claims
  double density = 0;                    ///< ρ [kg/m³]
  Material material;
  FibreDirections fibres;            ///< fibre_reinforced with a constant rule: the directions
  FibreFieldParameters fibre_field;  ///< fibre_reinforced: how the directions are given
  /// Dynamics: the initial velocity of this body's free dofs [m/s] (empty: time's
  /// initial_velocity). A vertex shared by two bodies takes the first body's.
  std::vector<double> initial_velocity;
  std::string where;  ///< location in the case file, for messages
};

/// Prescribed displacement of some components on a boundary group (ramped with the load).
struct DirichletParameters {
  std::string boundary;
  std::vector<int> components;  ///< 0 = x, 1 = y, 2 = z
  std::vector<double> values;   ///< final displacement per component [m]
  /// The load-factor interval [ramp_start, ramp_end] ⊆ [0, 1] over which the values ramp
  /// linearly from 0 (zero before it, the full values after it): press, then slide.
  double ramp_start = 0.0, ramp_end = 1.0;
  bool ramped = false;  ///< the case gave `ramp`
  std::string where;

  /// The fraction of the final values prescribed at load factor s ∈ [0, 1] (s itself
  /// without a `ramp`).
  double ramp_fraction(double s) const {
    if (!ramped) return s;
    if (s <= ramp_start) return 0.0;
    if (s >= ramp_end) return 1.0;
    return (s - ramp_start) / (ramp_end - ramp_start);
  }
};

/// A dead load on a boundary group, in the reference configuration (ramped with the load).
struct TractionParameters {
  std::string boundary;
  std::vector<double> vector;  ///< traction [Pa] or, if `total`, total force [N, or N/m in 2D]
  bool total = false;
  std::string where;
};

/// A follower pressure on a boundary group: the load −p n da on the current boundary
/// (n outward), ramped with the load factor in static solves, constant in dynamics.
struct PressureParameters {
  std::string boundary;
  double pressure = 0;  ///< p [Pa]
  std::string where;
};

/// A point where the displacement is reported (series.csv, summary.json benchmark).
struct ProbeParameters {
  std::string name;
  std::vector<double> point;  ///< reference coordinates [m]
  std::string where;
};

/// Newton's method for each load step: stop when ‖R‖ ≤ max(rtol ‖R₀‖, atol) over the free
/// dofs (R₀: residual at the start of the step) or when the last update ‖δu‖ ≤ dtol ‖u‖.
struct NewtonParameters {
  double relative_tolerance = 1e-9;
  double absolute_tolerance = 0;
  double update_tolerance = 1e-12;
  int max_iterations = 25;
  /// `predictor: extrapolate`: a static load step starts from the linear extrapolation of the
  /// last two converged steps, uₙ + (s − sₙ)/(sₙ − sₙ₋₁) (uₙ − uₙ₋₁) (u₀ = 0 at s₀ = 0), not
  /// from uₙ: a prescribed sliding becomes a near-exact first iterate instead of a sheared
  /// boundary layer that Newton has to damp. Where the prescribed values still differ from the
  /// extrapolation (a new loading phase), one linearised step carries the difference into the
  /// body first (counted as a Newton iteration).
  bool extrapolate = false;
  /// `line_search: N` (0: off): when an update raises ‖R‖, it is halved up to N times while
  /// ‖R‖ stays above the last iterate's, and the trial with the smallest ‖R‖ is kept (each
  /// trial re-evaluates R, contact terms and active set included).
  int line_search = 0;
  /// `reuse_factorisation: N` (0: off; dynamics only): the factorisation of a time step's
  /// first Newton solve preconditions GMRES in the step's later Newton iterations, coupling
  /// iterations included, until a solve on it needs more than N iterations (then the next
  /// solve factors its matrix afresh) or fails within 4 N (then that solve does). Each step
  /// starts with a new factorisation, so a step's result does not depend on the steps before
  /// it (a restart continues bit for bit).
  int reuse_factorisation = 0;
  std::string reuse_where;  ///< where the key is, for the error on a static solid
};

/// Time integration: `static` (load stepping, the default), `newmark` (β = 1/4, γ = 1/2) or
/// `contact_stabilized_newmark` (Deuflhard, Krause and Ertel 2008: lumped mass, the predictor
/// projected onto the admissible set by the contact hook, the contact force of step n left
/// out of step n+1; dynamics.hpp), from u = 0 (Dirichlet values from t = 0), the initial
/// velocities on the free dofs and the loads applied in full at t = 0.
struct TimeParameters {
  bool dynamic = false;
  bool contact_stabilized = false;       ///< scheme contact_stabilized_newmark (dynamic too)
  double step = 0;                       ///< Δt [s]
  double end_time = 0;                   ///< [s]
  int n_steps = 0;                       ///< round(end_time/Δt)
  std::vector<double> initial_velocity;  ///< [m/s], empty: at rest
  std::string where;
};

/// A check of a homogeneous uniaxial stretch against the closed form (uniaxial_state): the
/// case stretches a block of one nearly incompressible or fibre-reinforced body (constant
/// fibres) along `axis` with free lateral faces; the benchmark gets the mean stretch, lateral
/// stretch and axial Cauchy stress next to the closed form, and the reaction on a boundary.
struct UniaxialReference {
  bool enabled = false;
  Vector3 axis = Vector3::UnitX();
  std::string reaction_boundary;  ///< "" : no reaction reported
  double reference_area = 0;      ///< reference area of that boundary [m²]
  std::string where;
};

/// Lamé's thick-walled cylinder (closed_form.hpp): radii and the probes at r = a and r = b.
struct LameReference {
  bool enabled = false;
  double inner_radius = 0;  ///< a [m]
  double outer_radius = 0;  ///< b [m]
  std::string inner_probe, outer_probe;
  std::string where;
};

/// Everything `problem: solid` reads.
struct SolidParameters {
  mesh::MeshInput mesh;
  std::vector<BodyParameters> bodies;
  std::vector<DirichletParameters> dirichlet;
  std::vector<TractionParameters> tractions;
  std::vector<PressureParameters> pressures;
  std::vector<double> gravity;  ///< [m/s²], empty: none
  std::string gravity_where;
  int steps = 1;
  NewtonParameters newton;
  TimeParameters time;
  std::vector<ProbeParameters> probes;
  /// Boundary groups whose reaction force (Σ f_int over their vertices) is written per load
  /// step to series.csv and at the end to summary.json (static scheme only).
  std::vector<std::string> reaction_boundaries;
  UniaxialReference uniaxial;
  /// `formulation: mixed`: P1–P1 displacement–pressure with pressure stabilisation
  /// (mixed_elements.hpp) instead of the displacement formulation; static only.
  bool mixed = false;
  LameReference lame;
  bool write_vtk = true;
  int vtk_interval = 1;         ///< dynamics: VTK every this many time steps
  int checkpoint_interval = 0;  ///< dynamics: a checkpoint every this many steps (0: none)

  /// Reads and checks every key (InputError located at the key). Vector lengths are checked
  /// against the mesh dimension later (check_dimension).
  static SolidParameters read(const config::Section& root);
  /// Throws InputError naming the key when a vector does not have `dim` entries.
  void check_dimension(int dim) const;
};

/// Reads a `material:` section: model and its parameters (E, ν or μ with ν, λ or κ).
Material read_material(const config::Section& section);

}  // namespace coapt::solid
