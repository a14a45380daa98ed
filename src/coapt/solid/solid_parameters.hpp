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
///       fibre_direction: [1, 0, 0]     fibre_reinforced only (second_fibre_direction too)
///   dirichlet:
///     - {boundary: left}                              all components fixed
///     - {boundary: top, components: [y], displacement: [0.001]}   ramped with the load
///   tractions:                         dead loads on the reference boundary, ramped
///     - {boundary: right, traction: [0, 62500]}       Pa (force per reference area/length)
///     - {boundary: right, total_force: [0, 1]}        N (3D) or N/m (2D): spread uniformly
///   gravity: [0, -2]                   m/s², body force ρ g, ramped
///   steps: 10                          load steps (load factor k/steps; static only)
///   time: {scheme: newmark, step: 0.005, end_time: 10, initial_velocity: [0, 0.1]}
///                                      dynamics (dynamics.hpp); scheme: static (default)
///   newton: {relative_tolerance, absolute_tolerance, update_tolerance, max_iterations}
///   probes: [{name: tip, point: [0.048, 0.060]}]
///   output: {vtk: true, vtk_interval: 10, checkpoint_interval: 100}
///                                      (time steps between VTK files / checkpoints)

#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/mesh/mesh_input.hpp"
#include "coapt/solid/materials.hpp"

namespace coapt::solid {

/// One solid body: a set of mesh cells with its material.
struct BodyParameters {
  std::string name;
  std::vector<std::string> cell_groups;  ///< empty: the cells no other body claims
  double density = 0;                    ///< ρ [kg/m³]
  Material material;
  FibreDirections fibres;  ///< constant over the body (fibre_reinforced only)
  std::string where;       ///< location in the case file, for messages
};

/// Prescribed displacement of some components on a boundary group (ramped with the load).
struct DirichletParameters {
  std::string boundary;
  std::vector<int> components;  ///< 0 = x, 1 = y, 2 = z
  std::vector<double> values;   ///< final displacement per component [m]
  std::string where;
};

/// A dead load on a boundary group, in the reference configuration (ramped with the load).
struct TractionParameters {
  std::string boundary;
  std::vector<double> vector;  ///< traction [Pa] or, if `total`, total force [N, or N/m in 2D]
  bool total = false;
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
};

/// Time integration: `static` (load stepping, the default) or `newmark` (β = 1/4, γ = 1/2)
/// from u = 0 (Dirichlet values from t = 0), a uniform initial velocity on the free dofs and
/// the loads applied in full at t = 0.
struct TimeParameters {
  bool dynamic = false;
  double step = 0;                       ///< Δt [s]
  double end_time = 0;                   ///< [s]
  int n_steps = 0;                       ///< round(end_time/Δt)
  std::vector<double> initial_velocity;  ///< [m/s], empty: at rest
  std::string where;
};

/// Everything `problem: solid` reads.
struct SolidParameters {
  mesh::MeshInput mesh;
  std::vector<BodyParameters> bodies;
  std::vector<DirichletParameters> dirichlet;
  std::vector<TractionParameters> tractions;
  std::vector<double> gravity;  ///< [m/s²], empty: none
  std::string gravity_where;
  int steps = 1;
  NewtonParameters newton;
  TimeParameters time;
  std::vector<ProbeParameters> probes;
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
