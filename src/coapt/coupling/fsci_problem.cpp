#include "coapt/coupling/fsci_problem.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <optional>

#include "coapt/contact/solid_contact.hpp"
#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/core/progress.hpp"
#include "coapt/coupling/constraint_group.hpp"
#include "coapt/coupling/immersed_constraint.hpp"
#include "coapt/coupling/quasi_newton.hpp"
#include "coapt/coupling/valve_surface.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fluid/fluid_model.hpp"
#include "coapt/mesh/mesh_input.hpp"
#include "coapt/solid/dynamics.hpp"
#include "coapt/solid/solid_model.hpp"

namespace coapt::coupling {
namespace {

using config::Bounds;

/// A coupling iteration's |df| history for the log: an iteration whose solid solve failed (its
/// entry NaN, `coupled_step`) reads as such, not as a NaN of the iteration.
std::string history_text(const std::vector<double>& history) {
  std::string text;
  for (const double change : history) {
    if (!text.empty()) text += ", ";
    text += std::isnan(change) ? std::string("(solid failed)") : fmt::format("{:.3e}", change);
  }
  return text;
}

/// One entry of `solids:`.
struct SolidEntry {
  std::string name;
  std::string where;  ///< file:line of the entry
  bool rigid = true;
  mesh::MeshInput mesh;          ///< rigid: the mesh (deformable: solid::SolidModel reads it)
  std::vector<double> velocity;  ///< rigid: translation velocity [m/s]
  std::unique_ptr<config::Section> section;  ///< deformable: the entry, for solid::SolidModel
  contact::ContactParameters contact;        ///< deformable: its `contact:` (between its bodies)
  bool contact_stabilized = false;           ///< deformable, transient: the time scheme
};

/// The block Gauss–Seidel iteration of a step with deformable solids.
struct CouplingSettings {
  double absolute_tolerance = 1e-8;  ///< on ‖f^l − f^(l−1)‖ [N/m in 2D, N]
  double relative_tolerance = 1e-6;  ///< on ‖f^l − f^(l−1)‖ / ‖f^1‖
  int max_iterations = 50;
  double relaxation = 0.5;  ///< ω of the first iteration (then Aitken's, if enabled)
  enum class Method { constant, aitken, iqn_ils };
  Method method = Method::aitken;
  int reuse_steps = 8;   ///< iqn_ils: converged steps whose columns are reused
  int max_columns = 60;  ///< iqn_ils: columns at most
  double filter = 1e-8;  ///< iqn_ils: QR filter
  /// iqn_ils: the change of the contact's active set within a step (|A Δ A₀| / |A ∪ A₀|)
  /// above which the past steps' columns are no longer used (1: always used)
  double contact_change = 1.0;
  /// transient: a deformable solid's Newton in a step's later iterations starts from its last
  /// iterate's state (SolidModel::step, from_current)
  bool solid_warm_start = false;
  /// the relative tolerance's reference: the force the step starts from, ‖f⁰‖ (the paper's
  /// ‖λ⁰‖; the first iterate's when it is zero), instead of the first iterate's ‖f¹‖
  bool relative_to_start = false;
  int retries = 2;       ///< stronger relaxation, then (transient) halved steps
  int freeze_after = 0;  ///< keep the constrained sets from this iteration of a step on (0: never)
  double iteration_density = 0;  ///< transient: the solids' iteration inertia [kg/m³] (0: none)
};

/// `benchmark:` of an immersed body in a channel (the DFG cylinder).
struct Benchmark {
  std::string type = "none";  ///< none | cylinder | forces
  std::string body;           ///< cylinder: the solid whose force is reported
  // forces: drag and lift = Σ of these fluid boundary groups' and solids' forces; a probe
  std::vector<std::string> boundaries, solids;
  std::string probe_solid, probe;
  double reference_drag_force = 0, reference_lift_force = 0;
  double reference_displacement_x = 0, reference_displacement_y = 0;
  // forces, transient: last-period statistics of the steps from statistics_from on; reference
  // amplitudes and frequencies (the reference_* above are then the means)
  bool statistics = false;
  double statistics_from = 0;  ///< [s]
  double reference_drag_amplitude = 0, reference_lift_amplitude = 0;
  double reference_displacement_x_amplitude = 0, reference_displacement_y_amplitude = 0;
  double reference_drag_frequency = 0, reference_lift_frequency = 0;
  double reference_displacement_x_frequency = 0, reference_displacement_y_frequency = 0;
  double mean_velocity = 1, diameter = 1;
  std::vector<double> pressure_points;  ///< x_A, y_A, x_B, y_B: Δp = p(A) − p(B)
  // valve: the solid whose contact closes it and the boundary group whose flow is the leak
  std::string valve_solid, flow_boundary;
  /// valve: the solid's boundary groups that face flow_boundary's side of the closed valve;
  /// their swept flux is taken from the flow to give the leak (empty: the flow is the leak)
  std::vector<std::string> upstream_surfaces;
  /// valve: the fluid boundary group on the other side of the closed valve (empty: none); the
  /// leak is measured again there, from the solid's change of volume and that group's flow
  std::string downstream_boundary;
  double reference_drag = 0, reference_lift = 0, reference_pressure_difference = 0;
};

struct Parameters {
  int level = 0;  ///< added to every mesh's level
  fluid::FluidCase fluid;
  std::vector<SolidEntry> solids;
  transfer::TransferOptions transfer;
  double partial_from = 1.0;        ///< coupling.partial_coverage_from (≥ the threshold: none)
  double partial_time_scale = 0.0;  ///< coupling.partial_time_scale [s] (0: the step)
  bool pressure_in_solid = false;   ///< coupling.pressure_in_solid (ImmersedConstraint)
  CouplingSettings coupling;
  fluid::TimeSettings time;
  Benchmark benchmark;
  bool write_vtk = true;
  int vtk_interval = 0;         ///< transient: VTK every this many steps (0: the last step only)
  int checkpoint_interval = 0;  ///< transient: a checkpoint every this many steps (0: none)
};

Parameters read(const config::Section& root) {
  Parameters p;
  p.level = root.section("mesh", "refinement of every mesh of the case")
                .get<int>("level", 0,
                          {"",
                           "added to the refinement level of the fluid mesh and of every "
                           "solid's mesh (each level halves the element sizes)",
                           Bounds::closed(0, 12)});
  const auto fluid = root.section(
      "fluid", "the fluid: mesh, boundary, outlets, pressure_reference and its material keys");
  p.fluid = fluid::FluidCase::read(fluid, fluid);
  for (const auto& entry : root.sections("solids", "the immersed solids, each with its mesh")) {
    SolidEntry solid;
    solid.where = entry.where();
    solid.name = entry.require<std::string>("name", {"", "name of the solid (series columns)"});
    solid.rigid = entry.get<bool>(
        "rigid", true,
        {"",
         "true: a rigid body moving with `velocity`; false: a deformable solid with the keys "
         "of `problem: solid` (mesh, bodies, dirichlet, probes, newton, ...)"});
    if (solid.rigid) {
      solid.mesh =
          mesh::MeshInput::read(entry.section("mesh", "the solid's mesh"), entry.case_directory());
      solid.velocity = entry.get<std::vector<double>>(
          "velocity", {}, {"m/s", "rigid: translation velocity of the body (empty: at rest)"});
    } else {
      solid.section = std::make_unique<config::Section>(entry);
      if (entry.has("output")) {
        const auto output = entry.section("output", "what the run writes");
        if (output.has("checkpoint_interval"))
          output.fail("checkpoint_interval",
                      "a coupled run checkpoints its whole state with the case's "
                      "output.checkpoint_interval, not per solid");
      }
      solid.contact = contact::read_solid_contact(entry);
      solid.contact_stabilized =
          entry.choice("scheme", solid.contact.enabled() ? "contact_stabilized_newmark" : "newmark",
                       {"newmark", "contact_stabilized_newmark"},
                       {"",
                        "transient coupling: the solid's time scheme (default: "
                        "contact_stabilized_newmark with contact, else newmark)"}) ==
          "contact_stabilized_newmark";
    }
    for (const auto& other : p.solids)
      if (other.name == solid.name)
        entry.fail("name", fmt::format("'{}' is already the name of a solid ({})", solid.name,
                                       other.where));
    p.solids.push_back(std::move(solid));
  }
  if (p.solids.empty()) root.fail("solids", "an fsci case needs at least one solid");
  auto coupling = root.section("coupling", "the fluid-solid coupling");
  p.transfer.coverage_threshold = coupling.get<double>(
      "coverage_threshold", 1.0 - 1e-10,
      {"",
       "a fluid node is constrained when this fraction of its support lies in a solid "
       "(covered-node rule; 1 - 1e-10: whole support)",
       Bounds{0.0, 1.0, true, false}});
  p.partial_from = coupling.get<double>(
      "partial_coverage_from", 1.0,
      {"",
       "a fluid node not constrained whose covered fraction lies between this and "
       "coverage_threshold is drawn towards the solid's velocity by a penalty that grows from 0 "
       "here to the constraint at the threshold (continuous in the solid's motion; 1: none)",
       Bounds{0.0, 1.0, true, false}});
  p.partial_time_scale = coupling.get<double>(
      "partial_time_scale", 0.0,
      {"s",
       "transient partial coverage: the penalty's inertial part is rho m_i / tau with this tau, "
       "the same for every step size, a drag of fixed strength (0: rho alpha_0 m_i / dt, the "
       "node's own BDF inertia, which stiffens the penalty as dt falls)",
       Bounds::non_negative()});
  if (p.partial_from < 1.0 && !(p.partial_from < p.transfer.coverage_threshold))
    coupling.fail("partial_coverage_from",
                  fmt::format("must lie below coverage_threshold ({:g}), got {:g}",
                              p.transfer.coverage_threshold, p.partial_from));
  p.pressure_in_solid = coupling.get<bool>(
      "pressure_in_solid", false,
      {"",
       "load each deformable solid also with the fluid's pressure over its region, -int p div w: "
       "the solid then carries sigma_s + p I, as it carries rho_s - rho_f, so that a compressible "
       "solid is squeezed by the pressure's level and not only pushed by its gradient; the "
       "pressure is iterated with the force (relaxed with it, or in the IQN-ILS columns as "
       "pressure times vertex measure) and its change counts in the coupling tolerance (false: "
       "the method as published)"});
  p.transfer.search_margin = coupling.get<double>(
      "search_margin", 0.0,
      {"m", "motion of a solid the transfer's search structure absorbs before a rebuild",
       Bounds::non_negative()});
  auto iteration = coupling.section(
      "iteration", "block Gauss-Seidel iteration of each step with deformable solids");
  auto& c = p.coupling;
  c.absolute_tolerance = iteration.get<double>(
      "absolute_tolerance", 1e-8,
      {"N",
       "stop when the change of the solids' force vectors B^T lambda is below this "
       "(N/m in 2D)",
       Bounds::non_negative()});
  c.relative_tolerance = iteration.get<double>(
      "relative_tolerance", 1e-6,
      {"", "or when that change is below this fraction of the first iteration's force",
       Bounds::non_negative()});
  c.max_iterations = iteration.get<int>("max_iterations", 50,
                                        {"", "iterations per try", Bounds::closed(1, 10000)});
  c.relaxation = iteration.get<double>(
      "relaxation", 0.5,
      {"", "relaxation factor of the force (first iteration)", Bounds{0, 1, true, false}});
  const auto method = iteration.choice(
      "method", "aitken", {"constant", "aitken", "iqn_ils"},
      {"",
       "force update: constant relaxation | aitken (dynamic relaxation) | iqn_ils (interface "
       "quasi-Newton, least squares over this and past steps' iterates)"});
  c.method = method == "constant" ? CouplingSettings::Method::constant
             : method == "aitken" ? CouplingSettings::Method::aitken
                                  : CouplingSettings::Method::iqn_ils;
  c.reuse_steps = iteration.get<int>(
      "reuse_steps", 8,
      {"", "iqn_ils: converged steps whose iterates are reused", Bounds::closed(0, 100)});
  c.max_columns = iteration.get<int>(
      "max_columns", 60, {"", "iqn_ils: least-squares columns at most", Bounds::closed(1, 1000)});
  c.filter = iteration.get<double>(
      "filter", 1e-8,
      {"", "iqn_ils: drop a column whose part orthogonal to the newer ones is below this fraction",
       Bounds{0.0, 1.0, false, false}});
  c.contact_change = iteration.get<double>(
      "drop_reused_above_contact_change", 1.0,
      {"",
       "iqn_ils: stop using the past steps' columns for the rest of a step (and forget them) "
       "once an iterate's contact active set differs from the step's start A0 by more than "
       "this fraction, |A - A0| + |A0 - A| over |A or A0| (the past iterates were taken with "
       "another active set; 1: never)",
       Bounds::closed(0.0, 1.0)});
  c.relative_to_start =
      iteration.choice("relative_to", "first_iterate", {"first_iterate", "start"},
                       {"",
                        "the relative tolerance's reference: first_iterate (the force of "
                        "the step's first coupling iteration) | start (the force the step "
                        "starts from, the last step's: a first iterate far off cannot "
                        "loosen the tolerance; the first iterate's when it is zero)"}) == "start";
  c.solid_warm_start = iteration.get<bool>(
      "solid_warm_start", false,
      {"",
       "transient: from a step's second coupling iteration on, start each deformable solid's "
       "Newton from its last iterate's state instead of the predictor when its residual is "
       "smaller (the tolerance stays relative to the predictor's residual; false: always the "
       "predictor)"});
  c.iteration_density = iteration.get<double>(
      "iteration_density", 0.0,
      {"kg/m^3",
       "transient: an artificial density added to the deformable solids' inertia during a "
       "step's coupling iterations and cancelled at convergence (the solution does not depend "
       "on it): damps the added-mass instability of the iteration when the solids carry little "
       "density of their own (rho_s - rho_f); 0: none",
       Bounds::non_negative()});
  c.freeze_after = iteration.get<int>(
      "freeze_constrained_after", 0,
      {"",
       "from this coupling iteration of a step on, keep each solid's set of constrained fluid "
       "nodes (the covered-node rule makes the iteration map discontinuous; 1: the set the "
       "step's starting configuration covers; 0: never)",
       Bounds::closed(0, 10000)});
  c.retries = iteration.get<int>(
      "retries", 2,
      {"", "failed step: retry with half the relaxation, then (transient) with half the step",
       Bounds::closed(0, 10)});
  p.time = fluid::TimeSettings::read(root);
  if (p.time.steady && c.iteration_density > 0)
    iteration.fail("iteration_density",
                   "acts on the inertia of transient runs only, and time.steady is true");

  auto benchmark = root.section("benchmark", "benchmark quantities written to summary.json");
  auto& b = p.benchmark;
  b.type = benchmark.choice(
      "type", "none", {"none", "cylinder", "forces", "valve"},
      {"",
       "none | cylinder (force coefficients of an immersed body) | forces (drag, lift [N/m] "
       "of boundary groups and solids, a probe's displacement) | valve (opening, penetration "
       "and leak of a solid closing by contact)"});
  if (b.type == "valve") {
    b.valve_solid = benchmark.require<std::string>(
        "solid", {"", "the deformable solid with contact whose closing is measured"});
    b.flow_boundary = benchmark.require<std::string>(
        "flow_boundary", {"", "fluid boundary group whose flow (out of the fluid) is the leak"});
    b.upstream_surfaces = benchmark.get<std::vector<std::string>>(
        "upstream_surfaces", {},
        {"",
         "boundary groups of the solid that face flow_boundary's side of the closed valve: "
         "the rate at which they sweep that side (the volume they sweep over the step, over "
         "dt) is taken from the flow, so that the leak excludes the fluid the moving leaflets "
         "push out; only their part from the solid's clamped base (dirichlet) to the contact "
         "zone counts, the rest bounding the other side (series swept_flow_past_contact), and "
         "of that only the facets with a node in the fluid mesh (series "
         "swept_flow_outside_fluid: the rest); "
         "empty: the leak is the whole flow"});
    b.downstream_boundary = benchmark.get<std::string>(
        "downstream_boundary", "",
        {"",
         "fluid boundary group on the other side of the closed valve: the leak is measured "
         "there too (leak_flow_downstream: the solid's rate of change of volume less the "
         "upstream surfaces' swept flow, less the flow out through this group); the two "
         "measures differ by the fluid's net outflow less the solid's rate of change of volume, "
         "a check of the discrete mass balance; empty: none"});
    const auto found = std::find_if(p.solids.begin(), p.solids.end(),
                                    [&](const SolidEntry& s) { return s.name == b.valve_solid; });
    if (found == p.solids.end() || !found->contact.enabled())
      benchmark.fail("solid", fmt::format("no deformable solid '{}' with a contact section in "
                                          "`solids`",
                                          b.valve_solid));
  }
  if (b.type == "forces") {
    b.boundaries = benchmark.get<std::vector<std::string>>(
        "boundaries", {}, {"", "fluid boundary groups whose force adds to drag and lift"});
    b.solids = benchmark.get<std::vector<std::string>>(
        "solids", {}, {"", "solids whose force B^T lambda adds to drag and lift"});
    b.probe_solid = benchmark.get<std::string>("probe_solid", "", {"", "solid of the probe"});
    b.probe = benchmark.get<std::string>(
        "probe", "", {"", "a probe of that solid: displacement_x, displacement_y (and _z in 3D)"});
    b.statistics = benchmark.has("statistics_from");
    b.statistics_from = benchmark.get<double>(
        "statistics_from", 0.0,
        {"s",
         "transient runs: mean, amplitude and frequency of drag, lift and the probe's "
         "displacement over their last full period among the steps from this time on (not "
         "given: not computed)",
         Bounds::non_negative()});
    if (b.statistics && p.time.steady)
      benchmark.fail("statistics_from", "needs a transient run (time.steady: false)");
    auto reference = benchmark.section("reference", "published values (relative errors)");
    b.reference_drag_force = reference.get<double>(
        "drag", 0.0, {"N/m", "drag (with statistics_from: its mean; 0: none)"});
    b.reference_lift_force = reference.get<double>(
        "lift", 0.0, {"N/m", "lift (with statistics_from: its mean; 0: none)"});
    b.reference_displacement_x = reference.get<double>(
        "displacement_x", 0.0, {"m", "probe u_x (with statistics_from: its mean; 0: none)"});
    b.reference_displacement_y = reference.get<double>(
        "displacement_y", 0.0, {"m", "probe u_y (with statistics_from: its mean; 0: none)"});
    const auto amplitude = [&](const char* key, const char* unit) {
      return reference.get<double>(
          key, 0.0,
          {unit, "with statistics_from: the amplitude (0: none)", Bounds::non_negative()});
    };
    const auto frequency = [&](const char* key) {
      return reference.get<double>(
          key, 0.0,
          {"Hz", "with statistics_from: the frequency (0: none)", Bounds::non_negative()});
    };
    b.reference_drag_amplitude = amplitude("drag_amplitude", "N/m");
    b.reference_lift_amplitude = amplitude("lift_amplitude", "N/m");
    b.reference_displacement_x_amplitude = amplitude("displacement_x_amplitude", "m");
    b.reference_displacement_y_amplitude = amplitude("displacement_y_amplitude", "m");
    b.reference_drag_frequency = frequency("drag_frequency");
    b.reference_lift_frequency = frequency("lift_frequency");
    b.reference_displacement_x_frequency = frequency("displacement_x_frequency");
    b.reference_displacement_y_frequency = frequency("displacement_y_frequency");
    for (const auto& name : b.solids)
      if (std::none_of(p.solids.begin(), p.solids.end(),
                       [&](const SolidEntry& s) { return s.name == name; }))
        benchmark.fail("solids", fmt::format("no solid named '{}' in `solids`", name));
  }
  if (b.type == "cylinder") {
    b.body = benchmark.require<std::string>("body", {"", "name of the solid"});
    b.mean_velocity = benchmark.require<double>("mean_velocity",
                                                {"m/s", "Ū of c = 2F/(ρŪ²D)", Bounds::positive()});
    b.diameter =
        benchmark.require<double>("diameter", {"m", "D of c = 2F/(ρŪ²D)", Bounds::positive()});
    b.pressure_points = benchmark.get<std::vector<double>>(
        "pressure_points", {}, {"m", "x_A, y_A, x_B, y_B: Δp = p(A) − p(B)"});
    if (!b.pressure_points.empty() && b.pressure_points.size() != 4)
      benchmark.fail("pressure_points", "give 4 numbers: x_A, y_A, x_B, y_B (2D)");
    auto reference = benchmark.section("reference", "published values (relative errors)");
    b.reference_drag = reference.get<double>("drag_coefficient", 0.0, {"", "c_D (0: none)"});
    b.reference_lift = reference.get<double>("lift_coefficient", 0.0, {"", "c_L (0: none)"});
    b.reference_pressure_difference =
        reference.get<double>("pressure_difference", 0.0, {"Pa", "Δp (0: none)"});
    if (std::none_of(p.solids.begin(), p.solids.end(),
                     [&](const SolidEntry& s) { return s.name == b.body; }))
      benchmark.fail("body", fmt::format("no solid named '{}' in `solids`", b.body));
  }
  auto output = root.section("output", "what the run writes");
  p.write_vtk = output.get<bool>("vtk", true, {"", "write the fluid and the solids as VTK"});
  p.vtk_interval =
      output.get<int>("vtk_interval", 0,
                      {"", "transient: VTK every this many time steps (0: only at the end)",
                       Bounds::closed(0, 1000000)});
  p.checkpoint_interval =
      output.get<int>("checkpoint_interval", 0,
                      {"", "transient: time steps between checkpoints for --restart (0: none)",
                       Bounds::closed(0, 1000000)});
  return p;
}

/// A solid in the coupling: its mesh and its constraint with the fluid.
struct Solid {
  const SolidEntry* entry = nullptr;
  mesh::QualityReport quality;                    ///< rigid
  std::unique_ptr<solid::SolidModel> model;       ///< deformable
  std::unique_ptr<contact::ContactHook> contact;  ///< deformable with `contact:`
  mesh::Mesh mesh;  ///< the current configuration (rigid: moved in place; deformable: X + u)
  std::unique_ptr<ImmersedConstraint> constraint;
  OwnedVec force;  ///< Bᵀλ of the last fluid solve (solid vertex vector, dim components)
  std::vector<double> total_force;
  // deformable: the force the solid is loaded with (relaxed), its value at the step's start,
  // and the last residual f − f_applied (Aitken)
  OwnedVec applied, applied_start, residual, previous_residual;
  OwnedVec applied_previous;  ///< iqn_ils: the applied force of the last iterate
  /// deformable: the load the last iterate asks for, force + the solid's iteration inertia
  /// (the force alone without coupling.iteration.iteration_density), and that inertia
  OwnedVec target, iteration_force;
  /// deformable, coupling.pressure_in_solid: the fluid's pressure the solid carries (one
  /// component per solid vertex), its value at the step's start and at the last iterate, the
  /// pressure of the last fluid solve, and the difference of the two (updated with the force)
  OwnedVec pressure, pressure_start, pressure_previous, pressure_target, pressure_residual;
  /// The weight of each owned vertex's pressure among the forces of the coupling iteration:
  /// ∫φ_v over the reference configuration [m² or m³], so that w p is a force.
  std::vector<double> pressure_weight;

  /// What a coupled step's tries change besides the solid model's own state (which
  /// SolidModel::restore puts back): the constrained set and its frozen flag, Bᵀλ and the
  /// contact state, as the last committed step left them. A failed step puts them back
  /// (restore_committed), so that its retry, the output written after the failure and the
  /// checkpoint are the last good state's, not the failed try's.
  struct Committed {
    std::vector<int> constrained;
    bool frozen = false;
    OwnedVec force;
    std::vector<double> total_force;
    std::optional<contact::ContactHook::Snapshot> contact;
  } committed;

  /// Deformable: the model's current configuration into the mesh and the transfer (the
  /// constrained set is recomputed unless frozen). Collective.
  void update_configuration() {
    const auto coordinates = model->current_coordinates();
    std::copy(coordinates.begin(), coordinates.end(), mesh.coordinates.begin());
    constraint->update_solid(mesh);
  }

  /// Takes `committed` from the current (committed) state.
  void save_committed() {
    committed.constrained = constraint->constrained_vertices();
    committed.frozen = constraint->frozen();
    if (!committed.force) COAPT_PETSC_CHECK(VecDuplicate(force, committed.force.out()));
    COAPT_PETSC_CHECK(VecCopy(force, committed.force));
    committed.total_force = total_force;
    if (contact) committed.contact = contact->snapshot();
  }

  /// Puts `committed` back after a failed try, the solid already at its committed
  /// configuration (a deformable one by SolidModel::restore, a rigid one by its coordinates):
  /// the transfer re-assembled there with the committed set, as read_checkpoint does.
  /// Collective.
  void restore_committed() {
    if (model) {
      const auto coordinates = model->current_coordinates();
      std::copy(coordinates.begin(), coordinates.end(), mesh.coordinates.begin());
    }
    constraint->restore(mesh, committed.constrained, committed.frozen);
    COAPT_PETSC_CHECK(VecCopy(committed.force, force));
    total_force = committed.total_force;
    if (contact && committed.contact) contact->restore(*committed.contact);
  }
};

/// Adds the contact hook's time over its own lifetime (one solid solve, also one that throws)
/// to the stage "contact".
class ContactTime {
 public:
  ContactTime(StageTimers& timers, const contact::ContactHook* hook)
      : timers_(timers), hook_(hook), start_(hook ? hook->seconds() : 0.0) {}
  ContactTime(const ContactTime&) = delete;
  ContactTime& operator=(const ContactTime&) = delete;
  ~ContactTime() {
    if (hook_) timers_.add("contact", hook_->seconds() - start_);
  }

 private:
  StageTimers& timers_;
  const contact::ContactHook* hook_;
  double start_;
};

/// What the coupling iterations of one step did.
struct CouplingReport {
  int iterations = 0;
  int tries = 1;
  std::vector<double> history;     ///< ‖f^l − f_applied^l‖ per iteration
  std::vector<double> relaxation;  ///< ω per iteration
  fluid::NewtonReport fluid;       ///< the last fluid solve
  int newton_iterations = 0;       ///< fluid Newton iterations over the coupling iterations
  int linear_iterations = 0;       ///< and their Krylov iterations
};

class FsciProblem final : public run::Problem {
 public:
  FsciProblem(const config::Section& root, MPI_Comm comm)
      : parameters_(read(root)), comm_(comm), fluid_(parameters_.fluid, comm, parameters_.level) {
    const int dim = fluid_.mesh().dim;
    for (const auto& entry : parameters_.solids) {
      auto solid = std::make_unique<Solid>();
      solid->entry = &entry;
      if (entry.rigid) {
        auto input = entry.mesh;
        mesh::add_refinement_levels(input, parameters_.level, "mesh.level");
        solid->mesh = mesh::load_mesh(input, comm, &solid->quality);
        if (!entry.velocity.empty() && static_cast<int>(entry.velocity.size()) != dim)
          throw InputError(fmt::format("{}: velocity: needs {} components", entry.where, dim));
      } else {
        const bool transient = !parameters_.time.steady;
        solid->model = std::make_unique<solid::SolidModel>(
            *entry.section, comm,
            solid::SolidModelOptions{parameters_.level, "mesh.level", transient});
        if (transient) {  // the fluid mesh carries ρ_f over the overlap
          solid->model->set_density_offset(parameters_.fluid.fluid.density);
          solid->model->set_contact_stabilized(entry.contact_stabilized);
          solid->model->set_iteration_density(parameters_.coupling.iteration_density);
        }
        if (entry.contact.enabled()) {
          solid->contact = std::make_unique<contact::ContactHook>(entry.contact, *solid->model);
          solid->model->set_hook(solid->contact.get());
        }
        solid->mesh = solid->model->mesh();
        solid->quality = solid->model->quality();
        deformable_ = true;
      }
      if (solid->mesh.dim != dim)
        throw InputError(fmt::format("{}: mesh: the solid's mesh is {}D, the fluid's {}D",
                                     entry.where, solid->mesh.dim, dim));
      solids_.push_back(std::move(solid));
    }
    const auto& c = parameters_.coupling;
    if (deformable_ && c.method == CouplingSettings::Method::iqn_ils)
      quasi_newton_ =
          std::make_unique<InterfaceQuasiNewton>(comm, c.reuse_steps, c.max_columns, c.filter);
    const auto& b = parameters_.benchmark;
    if (!b.pressure_points.empty() && dim != 2)
      throw InputError("benchmark.pressure_points: the pressure probes are a 2D quantity");
    for (const auto& group : b.boundaries)
      boundary_tags_.push_back(fluid_.boundary_tag(group, "benchmark.boundaries"));
    if (b.type == "valve") {
      flow_tag_ = fluid_.boundary_tag(b.flow_boundary, "benchmark.flow_boundary");
      if (!b.downstream_boundary.empty())
        downstream_tag_ =
            fluid_.boundary_tag(b.downstream_boundary, "benchmark.downstream_boundary");
      const auto& solid_mesh = find_solid(b.valve_solid)->mesh;
      std::vector<int> upstream_tags;
      for (const auto& group : b.upstream_surfaces) {
        const auto* found = solid_mesh.find_group(group);
        if (found && found->dim == solid_mesh.dim - 1) {
          upstream_tags.push_back(found->tag);
          continue;
        }
        std::string names;
        for (const auto& g : solid_mesh.groups)
          if (g.dim == solid_mesh.dim - 1) names += (names.empty() ? "" : ", ") + g.name;
        throw InputError(fmt::format(
            "benchmark.upstream_surfaces: solid '{}' has no boundary group '{}' (it has: {})",
            b.valve_solid, group, names.empty() ? "none" : names));
      }
      if (!b.upstream_surfaces.empty()) {
        const auto& model = *find_solid(b.valve_solid)->model;
        upstream_ = std::make_unique<UpstreamSurface>(
            model.mesh(), upstream_tags, fmt::format("{}", fmt::join(b.upstream_surfaces, ", ")),
            model.dirichlet_dofs(), fluid_.mesh(), "benchmark.upstream_surfaces", b.valve_solid);
      }
    }
    if (!b.probe.empty()) {
      const Solid* owner = find_solid(b.probe_solid);
      if (!owner || !owner->model)
        throw InputError(fmt::format(
            "benchmark.probe_solid: '{}' is not a deformable solid of `solids`", b.probe_solid));
      const auto& probes = owner->model->parameters().probes;
      for (std::size_t k = 0; k < probes.size(); ++k)
        if (probes[k].name == b.probe) probe_index_ = static_cast<int>(k);
      if (probe_index_ < 0)
        throw InputError(
            fmt::format("benchmark.probe: solid '{}' has no probe '{}'", b.probe_solid, b.probe));
    }
    if (b.type == "forces") {
      forces_.names = {"drag", "lift"};
      static constexpr const char* components[] = {"displacement_x", "displacement_y",
                                                   "displacement_z"};
      if (probe_index_ >= 0)
        for (int i = 0; i < dim; ++i) forces_.names.emplace_back(components[i]);
      forces_.values.resize(forces_.names.size());
    }
  }

  void describe() const override {
    fluid_.describe(
        fmt::format("fsci: {} fluid", parameters_.time.steady ? "steady" : "transient"));
    for (const auto& solid : solids_) {
      const auto& entry = *solid->entry;
      if (solid->model) {
        log::info("solid '{}' (deformable{}):", entry.name,
                  parameters_.time.steady    ? ""
                  : entry.contact_stabilized ? ", contact-stabilized Newmark"
                                             : ", Newmark");
        solid->model->describe();
        if (solid->contact)
          log::info("solid '{}': contact (frictionless mortar, semi-smooth Newton): {}", entry.name,
                    solid->contact->constraints().describe());
        continue;
      }
      log::info("solid '{}': {}, {} cells, {} vertices, shape quality in [{:.3f}, {:.3f}]; {}",
                entry.name, entry.mesh.describe(), solid->mesh.n_global_cells,
                solid->mesh.n_global_vertices, solid->quality.min_shape, solid->quality.max_shape,
                entry.velocity.empty()
                    ? std::string("rigid, at rest")
                    : fmt::format("rigid, velocity ({}) m/s", fmt::join(entry.velocity, ", ")));
    }
    const auto& c = parameters_.coupling;
    log::info("coupling: a fluid node is constrained when {:.10g} of its support is covered",
              parameters_.transfer.coverage_threshold);
    if (partial_coverage())
      log::info("coupling: a node covered from {:g} on is drawn towards the solid by a penalty",
                parameters_.partial_from);
    if (parameters_.pressure_in_solid && deformable_)
      log::info(
          "coupling: the deformable solids also carry the fluid's pressure over their region");
    if (deformable_) {
      std::string update;  // after the first iteration's relaxation
      if (c.method == CouplingSettings::Method::aitken) update = " then Aitken";
      if (c.method == CouplingSettings::Method::iqn_ils) {
        update = fmt::format(" then IQN-ILS (reuse {} steps", c.reuse_steps);
        if (c.contact_change < 1)
          update += fmt::format(", not past an active-set change of {:g}", c.contact_change);
        update += ")";
      }
      log::info(
          "coupling: block Gauss-Seidel, |df| < {:g} or |df|/|f^{}| < {:g}, at most {} "
          "iterations, relaxation {:g}{}{}",
          c.absolute_tolerance, c.relative_to_start ? "0" : "1", c.relative_tolerance,
          c.max_iterations, c.relaxation, update,
          c.solid_warm_start ? "; the solids' Newton from the last iterate" : "");
    }
  }

  /// Transient runs continue from a checkpoint of an earlier run (written every
  /// output.checkpoint_interval steps): the whole coupled state (write_checkpoint). The reader
  /// must live until run() returns.
  void restart_from(const run::CheckpointReader& checkpoint) override {
    const auto folder = checkpoint.directory().string();
    if (parameters_.time.steady)
      throw InputError(fmt::format("--restart {}: a steady fsci run has no checkpoints", folder));
    const auto& state = checkpoint.state();
    const std::string kind = state.contains("problem") ? state.at("problem").as_string() : "solid";
    if (kind != "fsci")
      throw InputError(
          fmt::format("--restart {}: a checkpoint of a '{}' run, this case is fsci", folder, kind));
    std::vector<std::string> written, ours;
    for (const auto& name : state.at("solids").as_array()) written.push_back(name.as_string());
    for (const auto& solid : solids_) ours.push_back(solid->entry->name);
    if (written != ours)
      throw InputError(
          fmt::format("--restart {}: the checkpoint's solids ({}) are not the case's ({})", folder,
                      fmt::join(written, ", "), fmt::join(ours, ", ")));
    restart_ = &checkpoint;
  }

  void run(run::RunOutput& output) override {
    describe();
    fluid_.start(0.0);
    {
      ScopedTimer timer(output.timers(), "transfer");
      const auto fixed = fluid_.velocity_condition_vertices();
      std::vector<ImmersedConstraint*> constraints;
      for (auto& solid : solids_) {
        auto options = parameters_.transfer;
        options.primal = options.primal || (parameters_.pressure_in_solid && solid->model);
        solid->constraint = std::make_unique<ImmersedConstraint>(
            fluid_.mesh(), solid->mesh, options, fixed, parameters_.partial_from);
        constraints.push_back(solid->constraint.get());
        solid->force = solid->constraint->create_solid_vector();
        if (!solid->model) continue;
        for (auto* v :
             {&solid->applied, &solid->applied_start, &solid->residual, &solid->previous_residual,
              &solid->applied_previous, &solid->target, &solid->iteration_force}) {
          *v = solid->constraint->create_solid_vector();
          COAPT_PETSC_CHECK(VecSet(*v, 0.0));
        }
        solid->model->set_external_force(solid->applied);
        if (parameters_.pressure_in_solid) {
          for (auto* v : {&solid->pressure, &solid->pressure_start, &solid->pressure_previous,
                          &solid->pressure_target, &solid->pressure_residual}) {
            *v = fem::create_vertex_vector(solid->mesh, 1);
            COAPT_PETSC_CHECK(VecSet(*v, 0.0));
          }
          solid->pressure_weight = vertex_measures(solid->mesh);
          try {
            solid->model->set_immersed_pressure(solid->pressure);
          } catch (const InputError& error) {
            throw InputError(fmt::format("{}: solid '{}': {}", solid->entry->where,
                                         solid->entry->name, error.what()));
          }
        }
      }
      group_ = std::make_unique<ConstraintGroup>(fluid_.mesh(), constraints,
                                                 parameters_.transfer.coverage_threshold, fixed);
      group_->combine();
    }
    const auto& p = parameters_;
    if (!p.time.steady)
      for (auto& solid : solids_)
        if (solid->model) solid->model->initialize_dynamics(output);
    int newton_total = 0, linear_total = 0, coupling_total = 0;
    int last_vtk_step = -1, n_steps_done = 0;  // transient VTK: the last step written
    if (p.time.steady) {
      const auto report = coupled_step(output, 0.0, 0.0, p.coupling.relaxation);
      if (!report.converged) {
        // the last iterate's quantities stay in the summary next to the failure
        record_step(output, 0.0, report.coupling);
        benchmark(output);
        output.summary()["coupling_history"] = io::Json::array_of(report.coupling.history);
      }
      if (!report.converged)
        throw ConvergenceError(
            fmt::format("fsci: the steady coupling did not converge in {} iterations; |df| "
                        "history {}",
                        report.coupling.iterations, history_text(report.coupling.history)));
      newton_total = report.coupling.newton_iterations;
      linear_total = report.coupling.linear_iterations;
      coupling_total = report.coupling.iterations;
      record_step(output, 0.0, report.coupling);
    } else {
      int step = 0;
      if (restart_) {
        step = n_steps_done = read_checkpoint(*restart_);
        log::info("continuing after step {} (t = {:g} s)", step, fluid_.time());
      }
      start_valve_volume();
      Progress progress(p.time.n_steps(), p.time.end_time, fluid_.time());
      while (fluid_.time() < p.time.end_time * (1 - 1e-12)) {
        const double dt = p.time.step_from(fluid_.time());
        CouplingReport report;
        try {
          report = step_with_retries(output, dt);
        } catch (const ConvergenceError&) {
          // step_with_retries restored the last committed state: its figures, fields and a
          // checkpoint (to --restart from with other settings) stay in the run folder next to
          // the failure
          benchmark(output);
          if (p.write_vtk && last_vtk_step != step) write_vtk(output, fluid_.time());
          write_checkpoint(output, step);
          output.keep_last_good_state(step, fluid_.time());
          throw;
        }
        ++step;
        n_steps_done = step;
        newton_total += report.newton_iterations;
        linear_total += report.linear_iterations;
        coupling_total += report.iterations;
        record_step(output, fluid_.time(), report);
        if (p.write_vtk && p.vtk_interval > 0 && step % p.vtk_interval == 0) {
          ScopedTimer timer(output.timers(), "output");
          write_vtk(output, fluid_.time());
          last_vtk_step = step;
        }
        if (p.checkpoint_interval > 0 && step % p.checkpoint_interval == 0) {
          ScopedTimer timer(output.timers(), "checkpoint");
          write_checkpoint(output, step);
        }
        progress.step(
            step, fluid_.time(),
            fmt::format("coupling {}, newton {}", report.iterations, report.newton_iterations));
      }
    }
    fluid_.write_windkessel_states(output);
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = newton_total;
    iterations["linear"] = linear_total;
    iterations["coupling"] = coupling_total;
    {
      ScopedTimer timer(output.timers(), "benchmark");
      benchmark(output);
    }
    if (p.write_vtk && (p.time.steady || last_vtk_step != n_steps_done)) {
      ScopedTimer timer(output.timers(), "output");
      write_vtk(output, p.time.steady ? 0.0 : p.time.end_time);
    }
  }

 private:
  struct StepResult {
    bool converged = false;
    CouplingReport coupling;
  };

  /// The coupled state after `step` committed steps into output/checkpoint: the fluid's BDF
  /// history and Windkessels (FluidModel::write_checkpoint); per solid k (fields solid<k>_...)
  /// its constrained fluid nodes and frozen flag, its force Bᵀλ, and for a deformable solid
  /// the committed Newmark state, the applied (relaxed) force that starts the next step, the
  /// fluid's pressure it carries (coupling.pressure_in_solid) and the contact state, for a rigid
  /// one its coordinates; the IQN-ILS columns kept for reuse; the valve history.
  void write_checkpoint(run::RunOutput& output, int step) const {
    run::CheckpointWriter writer(comm_, output.directory() / "checkpoint");
    auto& state = writer.state();
    state["problem"] = "fsci";
    state["step"] = step;
    state["force_balance"] = force_balance_;
    fluid_.write_checkpoint(writer);
    const auto& fluid_mesh = fluid_.mesh();
    auto marker = fem::create_vertex_vector(fluid_mesh, 1);
    auto& names = state["solids"] = io::Json::array();
    for (std::size_t k = 0; k < solids_.size(); ++k) {
      const auto& solid = *solids_[k];
      const auto prefix = fmt::format("solid{}_", k);
      const int dim = solid.mesh.dim;
      names.push_back(solid.entry->name);
      state[prefix + "frozen"] = solid.constraint->frozen();
      COAPT_PETSC_CHECK(VecSet(marker, 0.0));
      {
        PetscScalar* values = nullptr;
        COAPT_PETSC_CHECK(VecGetArray(marker, &values));
        for (const int v : solid.constraint->constrained_vertices()) values[v] = 1.0;
        COAPT_PETSC_CHECK(VecRestoreArray(marker, &values));
      }
      writer.add_vertex_field(prefix + "constrained", fluid_mesh, marker, 1);
      writer.add_vertex_field(prefix + "force", solid.mesh, solid.force, dim);
      if (solid.model) {
        solid.model->write_checkpoint(writer, prefix);
        writer.add_vertex_field(prefix + "applied", solid.mesh, solid.applied, dim);
        if (solid.pressure)
          writer.add_vertex_field(prefix + "pressure", solid.mesh, solid.pressure, 1);
        if (solid.contact) solid.contact->write_checkpoint(writer, prefix);
      } else {
        auto coordinates = fem::create_vertex_vector(solid.mesh, dim);
        PetscScalar* values = nullptr;
        COAPT_PETSC_CHECK(VecGetArray(coordinates, &values));
        std::copy_n(solid.mesh.coordinates.begin(),
                    static_cast<std::size_t>(solid.mesh.n_owned_vertices) * dim, values);
        COAPT_PETSC_CHECK(VecRestoreArray(coordinates, &values));
        writer.add_vertex_field(prefix + "x", solid.mesh, coordinates, dim);
      }
    }
    if (quasi_newton_) write_quasi_newton(writer);
    auto& valve = state["valve"];
    valve["times"] = io::Json::array_of(valve_.times);
    valve["opening"] = io::Json::array_of(valve_.opening);
    valve["flow"] = io::Json::array_of(valve_.flow);
    valve["swept"] = io::Json::array_of(valve_.swept);
    valve["downstream_flow"] = io::Json::array_of(valve_.downstream_flow);
    valve["volume_rate"] = io::Json::array_of(valve_.volume_rate);
    valve["closed"] =
        io::Json::array_of(std::vector<int>(valve_.closed.begin(), valve_.closed.end()));
    valve["max_penetration"] = valve_.max_penetration;
    auto& forces = state["forces_history"];
    forces["times"] = io::Json::array_of(forces_.times);
    auto& columns = forces["values"] = io::Json::array();
    for (const auto& values : forces_.values) columns.push_back(io::Json::array_of(values));
    writer.commit();
  }

  /// Takes the state of write_checkpoint back (after the constraints are built and the solids'
  /// dynamics initialised); returns the steps done. InputError naming the folder when the
  /// checkpoint is of other meshes.
  int read_checkpoint(const run::CheckpointReader& reader) {
    const auto& state = reader.state();
    fluid_.read_checkpoint(reader);
    const auto& fluid_mesh = fluid_.mesh();
    auto marker = fem::create_vertex_vector(fluid_mesh, 1);
    for (std::size_t k = 0; k < solids_.size(); ++k) {
      auto& solid = *solids_[k];
      const auto prefix = fmt::format("solid{}_", k);
      const int dim = solid.mesh.dim;
      reader.read_vertex_field(prefix + "constrained", fluid_mesh, marker, 1);
      std::vector<int> constrained;
      {
        const PetscScalar* values = nullptr;
        COAPT_PETSC_CHECK(VecGetArrayRead(marker, &values));
        for (int v = 0; v < fluid_mesh.n_owned_vertices; ++v)
          if (values[v] > 0.5) constrained.push_back(v);
        COAPT_PETSC_CHECK(VecRestoreArrayRead(marker, &values));
      }
      reader.read_vertex_field(prefix + "force", solid.mesh, solid.force, dim);
      solid.total_force = solid.constraint->sum_components(solid.force);
      if (solid.model) {
        // the applied force first: the contact-stabilized scheme's committed residual uses it
        reader.read_vertex_field(prefix + "applied", solid.mesh, solid.applied, dim);
        if (solid.pressure) {
          reader.read_vertex_field(prefix + "pressure", solid.mesh, solid.pressure, 1);
          fem::update_ghosts(solid.pressure);
        }
        solid.model->read_checkpoint(reader, prefix);
        if (solid.contact) solid.contact->read_checkpoint(reader, prefix);
        solid.mesh.coordinates = solid.model->current_coordinates();
      } else {
        auto coordinates = fem::create_vertex_vector(solid.mesh, dim);
        reader.read_vertex_field(prefix + "x", solid.mesh, coordinates, dim);
        fem::LocalValues values(coordinates);
        for (std::size_t i = 0; i < solid.mesh.coordinates.size(); ++i)
          solid.mesh.coordinates[i] = values[i];
      }
      solid.constraint->restore(solid.mesh, std::move(constrained),
                                state.at(prefix + "frozen").as_bool());
    }
    force_balance_ = state.at("force_balance").as_double();
    if (quasi_newton_) read_quasi_newton(reader);
    const auto& valve = state.at("valve");
    const auto doubles = [](const io::Json& array) {
      std::vector<double> values;
      for (const auto& value : array.as_array()) values.push_back(value.as_double());
      return values;
    };
    valve_.times = doubles(valve.at("times"));
    valve_.opening = doubles(valve.at("opening"));
    valve_.flow = doubles(valve.at("flow"));
    // absent from checkpoints written before it: no swept flow
    valve_.swept = valve.contains("swept") ? doubles(valve.at("swept"))
                                           : std::vector<double>(valve_.flow.size(), 0.0);
    if (valve.contains("volume_rate")) {
      valve_.downstream_flow = doubles(valve.at("downstream_flow"));
      valve_.volume_rate = doubles(valve.at("volume_rate"));
    } else {
      // written before the downstream measure: its steps add nothing to it
      valve_.downstream_flow.assign(valve_.flow.size(), 0.0);
      valve_.volume_rate = valve_.swept;
      if (downstream_tag_ >= 0 && !valve_.flow.empty())
        log::warn(
            "--restart: the checkpoint predates benchmark.downstream_boundary: the leak "
            "measured downstream counts the steps after the restart only");
    }
    for (const auto& value : valve.at("closed").as_array())
      valve_.closed.push_back(value.as_int() != 0 ? 1 : 0);
    valve_.max_penetration = valve.at("max_penetration").as_double();
    if (state.contains("forces_history")) {  // absent from checkpoints written before it
      const auto& forces = state.at("forces_history");
      const auto& columns = forces.at("values").as_array();
      if (columns.size() != forces_.values.size())
        throw InputError(fmt::format(
            "--restart {}: the checkpoint's force statistics have {} quantities, this case {}",
            reader.directory().string(), columns.size(), forces_.values.size()));
      forces_.times = doubles(forces.at("times"));
      for (std::size_t q = 0; q < columns.size(); ++q) forces_.values[q] = doubles(columns[q]);
    }
    return static_cast<int>(state.at("step").as_int());
  }

  /// The IQN-ILS columns kept for reuse, per deformable solid one field solid<k>_iqn with
  /// 2 m values per column and vertex (V's, then W's entries of the vertex; m = dim, or dim + 1
  /// with the weighted pressure), the columns of the kept steps newest first;
  /// state["iqn_columns"]: the columns per kept step.
  void write_quasi_newton(run::CheckpointWriter& writer) const {
    const auto& steps = quasi_newton_->reused();
    std::vector<std::int64_t> counts;
    std::vector<const std::vector<double>*> columns;  // v₀, w₀, v₁, w₁, ...
    for (const auto& step : steps) {
      counts.push_back(static_cast<std::int64_t>(step.v.size()));
      for (std::size_t j = 0; j < step.v.size(); ++j) {
        columns.push_back(&step.v[j]);
        columns.push_back(&step.w[j]);
      }
    }
    writer.state()["iqn_columns"] = io::Json::array_of(counts);
    if (columns.empty()) return;
    for_each_quasi_newton_field(
        columns.size(), [&](std::size_t k, const Solid& solid, Vec packed, std::size_t offset) {
          PetscScalar* values = nullptr;
          COAPT_PETSC_CHECK(VecGetArray(packed, &values));
          const int m = quasi_newton_components(solid);
          for (int v = 0; v < solid.mesh.n_owned_vertices; ++v)
            for (std::size_t c = 0; c < columns.size(); ++c)
              for (int i = 0; i < m; ++i)
                values[packed_index(v, c, i, m, columns.size())] =
                    (*columns[c])[offset + column_index(solid, v, i)];
          COAPT_PETSC_CHECK(VecRestoreArray(packed, &values));
          writer.add_vertex_field(fmt::format("solid{}_iqn", k), solid.mesh, packed,
                                  static_cast<int>(columns.size()) * m);
        });
  }

  /// Entry (vertex v, column c, component i) of a packed IQN field with n_columns columns.
  static std::size_t packed_index(int v, std::size_t c, int i, int dim, std::size_t n_columns) {
    return (static_cast<std::size_t>(v) * n_columns + c) * static_cast<std::size_t>(dim) +
           static_cast<std::size_t>(i);
  }

  /// The IQN-ILS entries per owned vertex of a solid: dim forces, and its weighted pressure
  /// with coupling.pressure_in_solid.
  static int quasi_newton_components(const Solid& solid) {
    return solid.mesh.dim + (solid.pressure ? 1 : 0);
  }

  /// Where entry i of owned vertex v lies in the solid's part of an IQN-ILS column: its forces
  /// (dim per vertex), then its weighted pressures (quasi_newton_update).
  static std::size_t column_index(const Solid& solid, int v, int i) {
    const auto dim = static_cast<std::size_t>(solid.mesh.dim);
    const auto vertex = static_cast<std::size_t>(v);
    return i < solid.mesh.dim
               ? vertex * dim + static_cast<std::size_t>(i)
               : static_cast<std::size_t>(solid.mesh.n_owned_vertices) * dim + vertex;
  }

  /// visit(k, solid, packed, offset) for each deformable solid k: `packed` a vector of its
  /// owned vertices with n_columns × quasi_newton_components values each, `offset` where the
  /// solid's entries start in a column (the solids' parts one after the other, as in
  /// quasi_newton_update).
  template <class Visit>
  void for_each_quasi_newton_field(std::size_t n_columns, Visit&& visit) const {
    std::size_t offset = 0;
    for (std::size_t k = 0; k < solids_.size(); ++k) {
      const auto& solid = *solids_[k];
      if (!solid.model) continue;
      const int m = quasi_newton_components(solid), owned = solid.mesh.n_owned_vertices;
      OwnedVec packed;
      COAPT_PETSC_CHECK(
          VecCreateMPI(comm_, static_cast<PetscInt>(owned) * static_cast<PetscInt>(n_columns) * m,
                       PETSC_DETERMINE, packed.out()));
      visit(k, solid, packed.get(), offset);
      offset += static_cast<std::size_t>(owned) * static_cast<std::size_t>(m);
    }
  }

  void read_quasi_newton(const run::CheckpointReader& reader) {
    std::deque<InterfaceQuasiNewton::Columns> steps;
    std::size_t n_columns = 0, length = 0;
    for (const auto& count : reader.state().at("iqn_columns").as_array()) {
      const auto n = static_cast<std::size_t>(count.as_int());
      n_columns += n;
      steps.emplace_back();
      steps.back().v.resize(n);
      steps.back().w.resize(n);
    }
    for (const auto& solid : solids_)
      if (solid->model)
        length += static_cast<std::size_t>(solid->mesh.n_owned_vertices) *
                  static_cast<std::size_t>(quasi_newton_components(*solid));
    std::vector<std::vector<double>*> columns;
    for (auto& step : steps)
      for (std::size_t j = 0; j < step.v.size(); ++j) {
        step.v[j].resize(length);
        step.w[j].resize(length);
        columns.push_back(&step.v[j]);
        columns.push_back(&step.w[j]);
      }
    if (n_columns > 0)
      for_each_quasi_newton_field(
          columns.size(), [&](std::size_t k, const Solid& solid, Vec packed, std::size_t offset) {
            const int m = quasi_newton_components(solid);
            reader.read_vertex_field(fmt::format("solid{}_iqn", k), solid.mesh, packed,
                                     static_cast<int>(columns.size()) * m);
            const PetscScalar* values = nullptr;
            COAPT_PETSC_CHECK(VecGetArrayRead(packed, &values));
            for (int v = 0; v < solid.mesh.n_owned_vertices; ++v)
              for (std::size_t c = 0; c < columns.size(); ++c)
                for (int i = 0; i < m; ++i)
                  (*columns[c])[offset + column_index(solid, v, i)] =
                      values[packed_index(v, c, i, m, columns.size())];
            COAPT_PETSC_CHECK(VecRestoreArrayRead(packed, &values));
          });
    quasi_newton_->restore_reused(std::move(steps));
  }

  Solid* find_solid(const std::string& name) const {
    for (const auto& solid : solids_)
      if (solid->entry->name == name) return solid.get();
    return nullptr;
  }

  /// One transient step of size dt, committed; a step whose coupling fails is retried with half
  /// the relaxation, then with half the step (the remaining time is covered by later steps);
  /// after `retries` failures the run fails with the history. The added-mass effect can make a
  /// smaller step worse, which is why the relaxation is tried first — unless a solid's solve
  /// failed in the first coupling iteration: its load there is the last step's force, which
  /// the relaxation does not change, so that try would repeat exactly; the step is halved. With
  /// rigid solids alone (one pass, no relaxation) every retry halves the step.
  CouplingReport step_with_retries(run::RunOutput& output, double dt) {
    const auto& c = parameters_.coupling;
    double relaxation = c.relaxation, step = dt;
    std::string failures;
    bool relaxation_tried = false;
    // a try moves the translating rigid solids (coupled_step): a failed one puts them back
    std::vector<std::vector<double>> committed_coordinates;
    for (const auto& solid : solids_)
      committed_coordinates.push_back(solid->model ? std::vector<double>{}
                                                   : solid->mesh.coordinates);
    for (auto& solid : solids_) solid->save_committed();
    const double committed_balance = force_balance_;
    // The IQN-ILS columns of the past steps, kept from the first failed try (which forgets
    // them) for the checkpoint of a step that fails altogether.
    std::optional<std::deque<InterfaceQuasiNewton::Columns>> committed_columns;
    for (int attempt = 0; attempt <= c.retries; ++attempt) {
      if (attempt > 0) {
        if (deformable_ && !relaxation_tried && !first_solve_failed_) {
          relaxation *= 0.5;
          relaxation_tried = true;
        } else {
          step *= 0.5;
        }
        log::info("fsci: retrying the step to t = {:g} s with relaxation {:g} and step {:g} s",
                  fluid_.time() + step, relaxation, step);
      }
      fluid_.begin_step(step);
      StepResult result;
      first_solve_failed_ = false;
      try {
        result = coupled_step(output, fluid_.time(), step, relaxation);
      } catch (const ConvergenceError& error) {
        result.converged = false;
        failures += fmt::format("\n  try {}: {}", attempt + 1, error.what());
        log::warn("fsci: try {} of the step to t = {:g} s failed: {}", attempt + 1, fluid_.time(),
                  error.what());
      }
      if (result.converged) {
        if (quasi_newton_) quasi_newton_->end_step();
        fluid_.commit_step();
        measure_swept_flow(step);
        for (auto& solid : solids_)
          if (solid->model) solid->model->commit();
        result.coupling.tries = attempt + 1;
        return result.coupling;
      }
      if (!result.coupling.history.empty())
        failures += fmt::format("\n  try {} (step {:g} s, relaxation {:g}): |df| {}", attempt + 1,
                                step, relaxation, history_text(result.coupling.history));
      fluid_.restore_step();
      if (quasi_newton_) {
        if (!committed_columns) committed_columns = quasi_newton_->reused();
        quasi_newton_->reset();
      }
      for (std::size_t k = 0; k < solids_.size(); ++k) {
        auto& solid = *solids_[k];
        if (solid.model) {
          solid.model->restore();
          COAPT_PETSC_CHECK(VecCopy(solid.applied_start, solid.applied));
          if (solid.pressure) {
            COAPT_PETSC_CHECK(VecCopy(solid.pressure_start, solid.pressure));
            fem::update_ghosts(solid.pressure);
          }
        } else {
          solid.mesh.coordinates = committed_coordinates[k];
        }
        solid.restore_committed();
      }
      group_->combine();
      force_balance_ = committed_balance;
    }
    if (committed_columns) quasi_newton_->restore_reused(std::move(*committed_columns));
    throw ConvergenceError(fmt::format("fsci: the step from t = {:g} s failed after {} tries:{}",
                                       fluid_.time(), c.retries + 1, failures));
  }

  /// The coupling iterations of one step (steady: dt = 0): (1) the deformable solids loaded by
  /// the relaxed force, (2) their current configuration into the transfer, (3) the fluid with
  /// v_f = T v_s, (4) f = Bᵀλ and the relaxed update f_applied += ω (f − f_applied), until the
  /// change ‖f − f_applied‖ meets the tolerances. Rigid solids alone need one pass.
  StepResult coupled_step(run::RunOutput& output, double time, double dt, double relaxation) {
    const auto& c = parameters_.coupling;
    const bool steady = dt <= 0;
    StepResult result;
    auto& report = result.coupling;
    if (!steady) {
      ScopedTimer timer(output.timers(), "transfer");
      move_rigid_solids(dt);
    }
    for (auto& solid : solids_) {
      if (solid->model) COAPT_PETSC_CHECK(VecCopy(solid->applied, solid->applied_start));
      if (solid->pressure) COAPT_PETSC_CHECK(VecCopy(solid->pressure, solid->pressure_start));
    }
    if (quasi_newton_) quasi_newton_->begin_step();
    for (auto& solid : solids_) {
      solid->constraint->set_frozen(false);
      if (c.freeze_after == 1 && solid->model) {
        // Frozen from the first iteration: the set the committed configuration covers (the
        // 0th iterate), so that it follows the solid from step to step.
        ScopedTimer timer(output.timers(), "transfer");
        solid->update_configuration();
      }
    }
    if (c.freeze_after == 1) group_->combine();  // the set frozen below is the group's
    double omega = relaxation, first_norm = 0;
    bool fell_back = false;  // the last update was the relaxed fallback of a failed solid solve
    for (int iteration = 1; iteration <= (deformable_ ? c.max_iterations : 1); ++iteration) {
      report.iterations = iteration;
      if (c.freeze_after > 0 && iteration == c.freeze_after)
        for (auto& solid : solids_) solid->constraint->set_frozen(true);
      bool solid_failed = false;
      for (auto& solid : solids_) {  // (1) and (2)
        if (!solid->model) continue;
        {
          // "solid" includes the contact hook's share, reported again as "contact"
          ScopedTimer timer(output.timers(), "solid");
          const ContactTime contact_time(output.timers(), solid->contact.get());
          try {
            if (steady)
              solid->model->solve_static(
                  1.0, output,
                  fmt::format("solid '{}', coupling iteration {}", solid->entry->name, iteration),
                  false);
            else
              solid->model->step(time, dt, output,
                                 c.solid_warm_start && iteration > 1 && !fell_back);
          } catch (const ConvergenceError& error) {
            // A quasi-Newton force can overshoot where the map is not smooth (the set of
            // constrained fluid nodes changes as the solid moves): fall back once to the
            // relaxed update of the last iterate, x + ω r, without the columns.
            first_solve_failed_ = iteration == 1;
            if (!quasi_newton_ || steady || iteration == 1 || fell_back) throw;
            log::warn("fsci: coupling iteration {}: {}; back to the relaxed update", iteration,
                      error.what());
            solid_failed = true;
            break;
          }
        }
        ScopedTimer timer(output.timers(), "transfer");
        solid->update_configuration();
      }
      if (solid_failed) {
        quasi_newton_->reset();
        for (auto& s : solids_)
          if (s->model)
            COAPT_PETSC_CHECK(VecWAXPY(s->applied, omega, s->residual, s->applied_previous));
        for (auto& s : solids_)
          if (s->pressure) {
            COAPT_PETSC_CHECK(
                VecWAXPY(s->pressure, omega, s->pressure_residual, s->pressure_previous));
            fem::update_ghosts(s->pressure);
          }
        report.history.push_back(std::numeric_limits<double>::quiet_NaN());
        report.relaxation.push_back(omega);
        fell_back = true;
        continue;
      }
      fell_back = false;
      if (quasi_newton_ && !quasi_newton_->reused_dropped() && c.contact_change < 1) {
        const double change = contact_change();
        if (change > c.contact_change) {
          log::debug(
              "fsci: coupling iteration {}: the contact's active set changed by {:.2f} "
              "since the step's start; the past steps' IQN-ILS columns are dropped",
              iteration, change);
          quasi_newton_->drop_reused();
        }
      }
      apply_constraint(steady);  // (3)
      {
        ScopedTimer timer(output.timers(), "fluid");
        report.fluid =
            steady ? fluid_.solve_steady(fmt::format("fluid, coupling iteration {}", iteration))
                   : fluid_.solve(fmt::format("fluid to t = {:g} s, coupling "
                                              "iteration {}",
                                              time, iteration));
        report.newton_iterations += report.fluid.iterations;
        report.linear_iterations += report.fluid.linear_iterations;
      }
      ScopedTimer timer(output.timers(), "coupling");
      compute_forces();  // (4)
      if (!deformable_) {
        result.converged = true;
        return result;
      }
      // r = f − f_applied over the deformable solids; Aitken's ω from the last two.
      double norm2 = 0, force2 = 0, dot = 0, difference2 = 0;
      for (auto& solid : solids_) {
        if (!solid->model) continue;
        COAPT_PETSC_CHECK(VecCopy(solid->force, solid->target));
        if (c.iteration_density > 0 && !steady) {
          solid->model->iteration_force(solid->iteration_force);
          COAPT_PETSC_CHECK(VecAXPY(solid->target, 1.0, solid->iteration_force));
        }
        COAPT_PETSC_CHECK(VecWAXPY(solid->residual, -1.0, solid->applied, solid->target));
        double n = 0, f = 0;
        COAPT_PETSC_CHECK(VecNorm(solid->residual, NORM_2, &n));
        COAPT_PETSC_CHECK(VecNorm(solid->force, NORM_2, &f));
        norm2 += n * n;
        force2 += f * f;
        if (iteration > 1) {
          // dot = r_{l−1}·(r_l − r_{l−1}), difference2 = ‖r_l − r_{l−1}‖²
          PetscScalar a = 0, b = 0;
          COAPT_PETSC_CHECK(VecDot(solid->previous_residual, solid->residual, &a));
          COAPT_PETSC_CHECK(VecDot(solid->previous_residual, solid->previous_residual, &b));
          double m = 0;
          COAPT_PETSC_CHECK(VecAYPX(solid->previous_residual, -1.0, solid->residual));
          COAPT_PETSC_CHECK(VecNorm(solid->previous_residual, NORM_2, &m));
          dot += a - b;
          difference2 += m * m;
        }
        COAPT_PETSC_CHECK(VecCopy(solid->residual, solid->previous_residual));
      }
      // coupling.pressure_in_solid: the pressure is iterated with the force, weighted as one
      // (its change counts in the norm, and IQN-ILS takes it into its columns)
      for (auto& solid : solids_) {
        if (!solid->pressure) continue;
        COAPT_PETSC_CHECK(
            VecWAXPY(solid->pressure_residual, -1.0, solid->pressure, solid->pressure_target));
        norm2 += weighted_square(*solid, solid->pressure_residual);
        force2 += weighted_square(*solid, solid->pressure_target);
      }
      const double norm = std::sqrt(norm2);
      if (iteration == 1) {
        first_norm = std::sqrt(force2);
        if (c.relative_to_start) {
          const double start = start_norm();
          if (start > 0) first_norm = start;
        }
      }
      report.history.push_back(norm);
      // One line per coupling iteration: a step of a large case can take many minutes. A
      // steady run has no per-step progress line, so there it is the progress (info).
      const auto line = fmt::format(
          "coupling iteration {}{}: |f - f_applied| {:.3e} (tolerance {:.3e}), fluid Newton {}, "
          "{} constrained fluid vertices",
          iteration, steady ? std::string() : fmt::format(" to t = {:g} s", time), norm,
          std::max(c.absolute_tolerance, c.relative_tolerance * first_norm),
          report.fluid.iterations, n_constrained_);
      if (steady)
        log::info("{}", line);
      else
        log::debug("{}", line);
      if (iteration > 1 && c.method == CouplingSettings::Method::aitken && difference2 > 0)
        omega = std::clamp(-omega * dot / difference2, 0.01, 1.0);
      report.relaxation.push_back(quasi_newton_ ? std::numeric_limits<double>::quiet_NaN() : omega);
      if (norm <= c.absolute_tolerance || norm <= c.relative_tolerance * first_norm) {
        // The solids are committed with the load their last state balances, f_applied less
        // the iteration inertia: the force the next step starts from.
        if (c.iteration_density > 0 && !steady)
          for (auto& solid : solids_)
            if (solid->model)
              COAPT_PETSC_CHECK(VecAXPY(solid->applied, -1.0, solid->iteration_force));
        result.converged = true;
        break;
      }
      if (quasi_newton_) {
        for (auto& solid : solids_) {
          if (solid->model) COAPT_PETSC_CHECK(VecCopy(solid->applied, solid->applied_previous));
          if (solid->pressure)
            COAPT_PETSC_CHECK(VecCopy(solid->pressure, solid->pressure_previous));
        }
        quasi_newton_update(omega);
        continue;
      }
      for (auto& solid : solids_) {
        if (solid->model) COAPT_PETSC_CHECK(VecAXPY(solid->applied, omega, solid->residual));
        if (solid->pressure) {
          COAPT_PETSC_CHECK(VecAXPY(solid->pressure, omega, solid->pressure_residual));
          fem::update_ghosts(solid->pressure);
        }
      }
    }
    log::info("{}: {} coupling iteration(s){}, |f - f_applied| {}; {}",
              steady ? std::string("steady") : fmt::format("t = {:g} s", time), report.iterations,
              result.converged ? "" : " (not converged)", history_text(report.history),
              quasi_newton_ ? fmt::format("IQN-ILS, {} column(s) in the last update", last_columns_)
                            : fmt::format("omega {:.3f}", fmt::join(report.relaxation, ", ")));
    return result;
  }

  /// ‖f⁰‖: the deformable solids' forces at the step's start (with coupling.pressure_in_solid
  /// their weighted pressures too), the norm the iteration's change is measured against in
  /// first_norm. Collective.
  double start_norm() const {
    double sum = 0;
    for (const auto& solid : solids_) {
      if (solid->model) {
        double n = 0;
        COAPT_PETSC_CHECK(VecNorm(solid->applied_start, NORM_2, &n));
        sum += n * n;
      }
      if (solid->pressure) sum += weighted_square(*solid, solid->pressure_start);
    }
    return std::sqrt(sum);
  }

  /// How far the solids' contact active sets A moved from their committed A₀ (the step's
  /// start): |A Δ A₀| / |A ∪ A₀| over every pair (0 when both are empty). The pair states are
  /// the same on every rank.
  double contact_change() const {
    std::size_t changed = 0, either = 0;
    for (const auto& solid : solids_) {
      if (!solid->contact || !solid->committed.contact) continue;
      const auto& now = solid->contact->constraints().pairs();
      const auto& start = solid->committed.contact->constraints.pairs;
      for (std::size_t p = 0; p < now.size() && p < start.size(); ++p) {
        const auto& a = now[p].active;
        const auto& a0 = start[p].active;
        for (std::size_t j = 0; j < std::max(a.size(), a0.size()); ++j) {
          const bool in = j < a.size() && a[j], in0 = j < a0.size() && a0[j];
          changed += in != in0 ? 1 : 0;
          either += in || in0 ? 1 : 0;
        }
      }
    }
    return either > 0 ? static_cast<double>(changed) / static_cast<double>(either) : 0.0;
  }

  /// Σ_v (w_v x_v)² over the solid's vertices (w = pressure_weight), for a one-component
  /// vertex vector x. Collective.
  double weighted_square(const Solid& solid, Vec x) const {
    const PetscScalar* values = nullptr;
    COAPT_PETSC_CHECK(VecGetArrayRead(x, &values));
    double sum = 0;
    for (std::size_t v = 0; v < solid.pressure_weight.size(); ++v) {
      const double weighted = solid.pressure_weight[v] * values[v];
      sum += weighted * weighted;
    }
    COAPT_PETSC_CHECK(VecRestoreArrayRead(x, &values));
    MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm_);
    return sum;
  }

  /// ∫φ_v over the mesh's cells for each owned vertex v (the lumped measure).
  static std::vector<double> vertex_measures(const mesh::Mesh& mesh) {
    std::vector<double> measures(static_cast<std::size_t>(mesh.n_owned_vertices), 0.0);
    const auto add = [&]<int Dim>() {
      constexpr int k = Dim + 1;
      for (int c = 0; c < mesh.n_cells(); ++c) {
        const auto cell = mesh.cell(c);
        const double* points[k];
        for (int a = 0; a < k; ++a) points[a] = mesh.point(cell[a]).data();
        const double share = fem::p1_geometry<Dim>(points).measure / k;
        for (int a = 0; a < k; ++a)
          if (cell[a] < mesh.n_owned_vertices) measures[static_cast<std::size_t>(cell[a])] += share;
      }
    };
    if (mesh.dim == 2)
      add.template operator()<2>();
    else
      add.template operator()<3>();
    return measures;
  }

  /// The IQN-ILS update of the applied forces: x = the applied forces, x̃ = the forces of the
  /// last fluid solve, over the owned entries of every deformable solid (quasi_newton.hpp);
  /// with coupling.pressure_in_solid each solid's w p follow its forces (x: the pressure it
  /// carries, x̃: the last fluid solve's).
  void quasi_newton_update(double omega) {
    std::vector<double> x, x_tilde;
    const auto append = [](Vec vector, std::vector<double>& values) {
      PetscInt n = 0;
      const PetscScalar* data = nullptr;
      COAPT_PETSC_CHECK(VecGetLocalSize(vector, &n));
      COAPT_PETSC_CHECK(VecGetArrayRead(vector, &data));
      values.insert(values.end(), data, data + n);
      COAPT_PETSC_CHECK(VecRestoreArrayRead(vector, &data));
    };
    const auto append_weighted = [](const Solid& solid, Vec vector, std::vector<double>& values) {
      const PetscScalar* data = nullptr;
      COAPT_PETSC_CHECK(VecGetArrayRead(vector, &data));
      for (std::size_t v = 0; v < solid.pressure_weight.size(); ++v)
        values.push_back(solid.pressure_weight[v] * data[v]);
      COAPT_PETSC_CHECK(VecRestoreArrayRead(vector, &data));
    };
    for (auto& solid : solids_)
      if (solid->model) {
        append(solid->applied, x);
        append(solid->target, x_tilde);
        if (solid->pressure) {
          append_weighted(*solid, solid->pressure, x);
          append_weighted(*solid, solid->pressure_target, x_tilde);
        }
      }
    std::vector<double> next(x.size());
    last_columns_ = quasi_newton_->next(x, x_tilde, omega, next);
    std::size_t offset = 0;
    for (auto& solid : solids_) {
      if (!solid->model) continue;
      PetscInt n = 0;
      PetscScalar* data = nullptr;
      COAPT_PETSC_CHECK(VecGetLocalSize(solid->applied, &n));
      COAPT_PETSC_CHECK(VecGetArray(solid->applied, &data));
      std::copy(next.begin() + static_cast<std::ptrdiff_t>(offset),
                next.begin() + static_cast<std::ptrdiff_t>(offset) + n, data);
      COAPT_PETSC_CHECK(VecRestoreArray(solid->applied, &data));
      offset += static_cast<std::size_t>(n);
      if (!solid->pressure) continue;
      COAPT_PETSC_CHECK(VecGetArray(solid->pressure, &data));
      for (std::size_t v = 0; v < solid->pressure_weight.size(); ++v)
        data[v] = next[offset + v] / solid->pressure_weight[v];
      COAPT_PETSC_CHECK(VecRestoreArray(solid->pressure, &data));
      fem::update_ghosts(solid->pressure);
      offset += solid->pressure_weight.size();
    }
  }

  /// Rigid solids with a velocity translate by dt·velocity; their operators are re-assembled.
  void move_rigid_solids(double dt) {
    for (auto& solid : solids_) {
      if (solid->model) continue;
      const auto& velocity = solid->entry->velocity;
      if (velocity.empty() ||
          std::all_of(velocity.begin(), velocity.end(), [](double v) { return v == 0.0; }))
        continue;
      const int dim = solid->mesh.dim;
      for (std::size_t k = 0; k < solid->mesh.coordinates.size(); ++k)
        solid->mesh.coordinates[k] += dt * velocity[k % dim];
      solid->constraint->update_solid(solid->mesh);
    }
  }

  /// coupling.partial_coverage_from is in use (below the covered-node threshold).
  bool partial_coverage() const {
    return parameters_.partial_from < parameters_.transfer.coverage_threshold;
  }

  /// v_f = T v_s at every solid's constrained fluid nodes (steady deformable solids: v_s = 0);
  /// at a node several solids cover, the sum of their shares (ConstraintGroup: the projection
  /// from the union of the solids).
  void apply_constraint(bool steady) {
    const int dim = fluid_.mesh().dim;
    group_->combine();
    std::vector<std::vector<double>> shares;
    for (auto& solid : solids_) {
      if (solid->model && !steady) {
        shares.push_back(solid->constraint->transfer_velocity(solid->model->velocity()));
      } else {
        const auto& velocity = solid->entry->velocity;
        shares.push_back(solid->constraint->transfer_uniform_velocity(
            velocity.empty() ? std::vector<double>(static_cast<std::size_t>(dim), 0.0) : velocity));
      }
    }
    const auto merged = group_->merge(shares);
    // the cells' covered fractions only matter where the covered cells' continuity is scaled
    const bool scaled = fluid_.parameters().fluid.covered_continuity_factor != 1.0;
    fluid_.set_velocity_constraint(merged.vertices, merged.velocities,
                                   scaled ? group_->cell_coverage() : std::vector<double>());
    // partial coverage: each solid's penalty entries, one after the other
    std::vector<int> vertices;
    std::vector<double> weights, targets;
    for (auto& solid : solids_) {
      const auto& own = solid->constraint->partial_vertices();
      vertices.insert(vertices.end(), own.begin(), own.end());
      const auto& w = solid->constraint->partial_weights();
      weights.insert(weights.end(), w.begin(), w.end());
      std::vector<double> velocity;
      if (solid->model && !steady) {
        velocity = solid->constraint->partial_velocity(solid->model->velocity());
      } else {
        const auto& given = solid->entry->velocity;
        velocity = solid->constraint->partial_uniform_velocity(
            given.empty() ? std::vector<double>(static_cast<std::size_t>(dim), 0.0) : given);
      }
      targets.insert(targets.end(), velocity.begin(), velocity.end());
    }
    fluid_.set_velocity_penalty(vertices, weights, targets, parameters_.partial_time_scale);
    auto count = static_cast<long long>(merged.vertices.size());
    MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    n_constrained_ = count;
  }

  /// λ = r/D and Bᵀλ of every solid from the fluid's constraint reactions; the balance
  /// Σ Bᵀλ = Σ r per solid is recorded.
  void compute_forces() {
    const int dim = fluid_.mesh().dim;
    const auto reactions = fluid_.constraint_reactions();
    const auto penalty = fluid_.penalty_reactions();  // apply_constraint's order
    force_balance_ = 0;
    std::size_t first = 0;
    for (std::size_t k = 0; k < solids_.size(); ++k) {
      auto& solid = solids_[k];
      const auto own = group_->reactions_of(k, reactions);
      const auto lambda = solid->constraint->multiplier(own);
      solid->constraint->solid_force(lambda, solid->force);
      const std::size_t count = solid->constraint->partial_vertices().size() * dim;
      const std::vector<double> partial(
          penalty.begin() + static_cast<std::ptrdiff_t>(first),
          penalty.begin() + static_cast<std::ptrdiff_t>(first + count));
      first += count;
      solid->constraint->add_partial_force(partial, solid->force);
      fem::update_ghosts(solid->force);
      if (solid->pressure)
        solid->constraint->solid_pressure(fluid_.state(), solid->pressure_target);
      solid->total_force = solid->constraint->sum_components(solid->force);
      auto total_reaction = solid->constraint->sum_constrained(own);
      const auto partial_total = solid->constraint->sum_partial(partial);
      for (int i = 0; i < dim; ++i) total_reaction[i] += partial_total[i];
      double difference = 0, size = 0;
      for (int i = 0; i < dim; ++i) {
        difference = std::max(difference, std::abs(solid->total_force[i] - total_reaction[i]));
        size = std::max(size, std::abs(total_reaction[i]));
      }
      force_balance_ = std::max(force_balance_, difference / std::max(size, 1e-300));
    }
  }

  /// Per body of a deformable solid with several bodies: the part of Bᵀλ (solid.force) on its
  /// vertices, per component; a vertex that several bodies share gives each an equal part, so
  /// the parts sum to total_force. Empty for a solid of one body. Collective.
  std::vector<std::vector<double>> body_forces(const Solid& solid) const {
    if (!solid.model || solid.model->parameters().bodies.size() < 2) return {};
    const auto& mesh = solid.model->mesh();
    const auto& body_of_cell = solid.model->body_of_cell();
    const auto n_bodies = solid.model->parameters().bodies.size();
    const auto dim = static_cast<std::size_t>(mesh.dim);
    // the bodies of each owned vertex's cells: the ghost layer holds every cell of an owned
    // vertex, so every rank count finds the same
    std::vector<std::vector<int>> bodies(static_cast<std::size_t>(mesh.n_owned_vertices));
    for (int c = 0; c < mesh.n_cells(); ++c)
      for (const int vertex : mesh.cell(c)) {
        if (vertex >= mesh.n_owned_vertices) continue;
        auto& list = bodies[static_cast<std::size_t>(vertex)];
        const int body = body_of_cell[static_cast<std::size_t>(c)];
        if (std::find(list.begin(), list.end(), body) == list.end()) list.push_back(body);
      }
    std::vector<double> sums(n_bodies * dim, 0.0);
    const PetscScalar* values = nullptr;
    COAPT_PETSC_CHECK(VecGetArrayRead(solid.force, &values));
    for (std::size_t v = 0; v < bodies.size(); ++v)
      for (const int body : bodies[v])
        for (std::size_t i = 0; i < dim; ++i)
          sums[static_cast<std::size_t>(body) * dim + i] +=
              values[v * dim + i] / static_cast<double>(bodies[v].size());
    COAPT_PETSC_CHECK(VecRestoreArrayRead(solid.force, &values));
    MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM,
                  mesh.comm);
    std::vector<std::vector<double>> forces(n_bodies);
    for (std::size_t b = 0; b < n_bodies; ++b)
      forces[b].assign(sums.begin() + static_cast<std::ptrdiff_t>(b * dim),
                       sums.begin() + static_cast<std::ptrdiff_t>((b + 1) * dim));
    return forces;
  }

  /// The valve benchmark's history: per recorded step the opening (the distance between the
  /// surfaces of the solid's first contact pair), whether it is closed (active contact nodes),
  /// the flow out through benchmark.flow_boundary and the largest penetration.
  void record_valve(double time, double opening, const Solid& solid) {
    const auto& status = solid.contact->constraints().status();
    valve_.times.push_back(time);
    valve_.opening.push_back(opening);
    valve_.closed.push_back(status.active > 0 ? 1 : 0);
    valve_.flow.push_back(fluid_.navier_stokes().boundary_flow(flow_tag_));
    valve_.swept.push_back(swept_flow_);
    valve_.downstream_flow.push_back(
        downstream_tag_ >= 0 ? fluid_.navier_stokes().boundary_flow(downstream_tag_) : 0.0);
    valve_.volume_rate.push_back(volume_rate_);
    valve_.max_penetration = std::max(valve_.max_penetration, status.max_penetration);
  }

  /// The rate at which benchmark.upstream_surfaces of the valve's solid swept the fluid on the
  /// flow boundary's side over the step just converged, before the solids' commit: the volume
  /// they sweep from uₙ to uₙ₊₁ (n out of the solid) over Δt, counting only their part between
  /// the clamped base and the contact zone at the step's end, in the fluid mesh
  /// (valve_surface.hpp; the part past the contact zone bounds the other side, the part in a
  /// wall no fluid). Summed over a phase it is the change of the volume they bound, whatever
  /// the leaflets' velocities do from step to step.
  /// Collective.
  void measure_swept_flow(double step) {
    swept_flow_ = 0;
    swept_past_contact_ = 0;
    swept_outside_fluid_ = 0;
    volume_rate_ = 0;
    const auto& b = parameters_.benchmark;
    if (b.type != "valve") return;
    const auto* solid = find_solid(b.valve_solid);  // deformable: it has contact
    const auto& model = *solid->model;
    if (upstream_) {
      const auto levels = upstream_->vertex_levels(solid->contact->constraints().pairs());
      for (const auto& group : b.upstream_surfaces) {
        const auto swept = model.surface_swept_volumes(group, levels, UpstreamSurface::kLevels);
        swept_flow_ += swept[UpstreamSurface::kCounted] / step;
        swept_outside_fluid_ += swept[UpstreamSurface::kOutsideFluid] / step;
        swept_past_contact_ += swept[UpstreamSurface::kPastContact] / step;
      }
    }
    const double volume = model.volume();
    volume_rate_ = (volume - valve_volume_) / step;
    valve_volume_ = volume;
  }

  /// The valve's solid's volume at the committed state (at the start of a run or restart).
  /// Collective.
  void start_valve_volume() {
    const auto& b = parameters_.benchmark;
    if (b.type == "valve") valve_volume_ = find_solid(b.valve_solid)->model->volume();
  }

  /// Closed phases (runs of steps with contact), in each the volume through flow_boundary
  /// (Σ Q̄ Δt over its steps, Q̄ the step's mean flow: ValveHistory::step_mean) and the leak
  /// (Σ (Q̄ − swept) Δt), the extremes of the opening and the largest penetration.
  void valve_benchmark(io::Json& json) const {
    std::vector<double> leak, leak_downstream, outflow, phase_start, phase_end;
    double largest = 0, smallest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < valve_.times.size(); ++k) {
      if (std::isfinite(valve_.opening[k])) {
        largest = std::max(largest, valve_.opening[k]);
        smallest = std::min(smallest, valve_.opening[k]);
      }
      if (!valve_.closed[k]) continue;
      // the run starts at t = 0 (fluid_.start): the first record ends the step from there
      const double dt = valve_.times[k] - (k > 0 ? valve_.times[k - 1] : 0.0);
      if (k == 0 || !valve_.closed[k - 1]) {
        leak.push_back(0.0);
        leak_downstream.push_back(0.0);
        outflow.push_back(0.0);
        phase_start.push_back(valve_.times[k]);
        phase_end.push_back(valve_.times[k]);
      }
      leak.back() += valve_.leak(k) * dt;
      leak_downstream.back() += valve_.downstream_leak(k) * dt;
      outflow.back() += ValveHistory::step_mean(valve_.flow, k) * dt;
      phase_end.back() = valve_.times[k];
    }
    json["closed_phases"] = static_cast<std::int64_t>(leak.size());
    json["closed_phase_start"] = io::Json::array_of(phase_start);
    json["closed_phase_end"] = io::Json::array_of(phase_end);
    json["leak_volume"] = io::Json::array_of(leak);
    json["outflow_volume"] = io::Json::array_of(outflow);
    if (downstream_tag_ >= 0) json["leak_volume_downstream"] = io::Json::array_of(leak_downstream);
    json["max_penetration"] = valve_.max_penetration;
    json["max_opening"] = largest;
    json["min_opening"] = std::isfinite(smallest) ? smallest : 0.0;
    const std::string phases =
        leak.empty() ? std::string("no closed phase")
                     : fmt::format("{} closed phase(s), leak volume {} (outflow {}) m^2 (2D) / m^3",
                                   leak.size(), fmt::join(leak, ", "), fmt::join(outflow, ", "));
    log::info("valve: {}, opening in [{:.4e}, {:.4e}] m, max penetration {:.3e} m", phases,
              json["min_opening"].as_double(), largest, valve_.max_penetration);
    if (downstream_tag_ >= 0 && !leak.empty())
      log::info("valve: leak volume measured downstream {} m^2 (2D) / m^3",
                fmt::join(leak_downstream, ", "));
  }

  /// c = 2F/(ρŪ²D) of the benchmark body.
  double coefficient_scale() const {
    const auto& b = parameters_.benchmark;
    return 2.0 / (parameters_.fluid.fluid.density * b.mean_velocity * b.mean_velocity * b.diameter);
  }

  /// Drag and lift of the `forces` benchmark: the fluid's force on its boundary groups plus
  /// the solids' Bᵀλ totals. Collective.
  std::vector<double> benchmark_force() {
    std::vector<double> force(static_cast<std::size_t>(fluid_.mesh().dim), 0.0);
    for (const int tag : boundary_tags_) {
      const auto f = fluid_.boundary_force(tag);
      for (std::size_t i = 0; i < force.size(); ++i) force[i] += f[i];
    }
    for (const auto& name : parameters_.benchmark.solids) {
      const auto& f = find_solid(name)->total_force;
      for (std::size_t i = 0; i < force.size(); ++i) force[i] += f[i];
    }
    return force;
  }

  const Solid* benchmark_body() const {
    for (const auto& solid : solids_)
      if (solid->entry->name == parameters_.benchmark.body) return solid.get();
    return nullptr;
  }

  void record_step(run::RunOutput& output, double time, const CouplingReport& coupling) {
    const auto& report = coupling.fluid;
    auto& series = output.series();
    const int dim = fluid_.mesh().dim;
    series.add("time", time);
    series.add("newton_iterations", report.iterations);
    series.add("linear_iterations", report.linear_iterations);
    series.add("coupling_iterations", coupling.iterations);
    series.add("coupling_tries", coupling.tries);
    series.add("coupling_change", coupling.history.empty() ? 0.0 : coupling.history.back());
    series.add("residual", report.residual_history.back());
    for (const auto& solid : solids_) {
      const auto& name = solid->entry->name;
      static constexpr const char* axes[] = {"x", "y", "z"};
      for (int i = 0; i < dim; ++i)
        series.add(fmt::format("force_{}_{}", axes[i], name), solid->total_force[i]);
      const auto per_body = body_forces(*solid);
      for (std::size_t b = 0; b < per_body.size(); ++b)
        for (int i = 0; i < dim; ++i)
          series.add(fmt::format("force_{}_{}_{}", axes[i], name,
                                 solid->model->parameters().bodies[b].name),
                     per_body[b][static_cast<std::size_t>(i)]);
      series.add("constrained_" + name, static_cast<double>(solid->constraint->n_constrained()));
      if (partial_coverage())
        series.add("partial_" + name, static_cast<double>(solid->constraint->n_partial()));
      if (!solid->model) continue;
      const auto probes = solid->model->probe_values();
      const auto& names = solid->model->parameters().probes;
      for (std::size_t k = 0; k < probes.size(); ++k)
        for (int i = 0; i < dim; ++i)
          series.add(fmt::format("{}_{}_u{}", name, names[k].name, axes[i]), probes[k][i]);
      series.add("kinetic_energy_" + name, solid->model->kinetic_energy());
      // a transient valve's solid: its volume at this commit, which measure_swept_flow took
      const bool valve_volume = parameters_.benchmark.type == "valve" && !parameters_.time.steady &&
                                name == parameters_.benchmark.valve_solid;
      series.add("volume_" + name, valve_volume ? valve_volume_ : solid->model->volume());
      if (!solid->contact) continue;
      solid->contact->add_series(output, "_" + name);
      const auto& pairs = solid->contact->constraints().pairs();
      const double opening = pairs.empty() || pairs[0].slave_x.empty()
                                 ? std::numeric_limits<double>::quiet_NaN()
                                 : contact::surface_distance(pairs[0]);
      series.add("opening_" + name, opening);
      if (name != parameters_.benchmark.valve_solid) continue;
      record_valve(time, opening, *solid);
      series.add("swept_flow", valve_.swept.back());
      series.add("swept_flow_past_contact", swept_past_contact_);
      series.add("swept_flow_outside_fluid", swept_outside_fluid_);
      series.add("leak_flow", valve_.leak(valve_.times.size() - 1));
      if (downstream_tag_ >= 0)
        series.add("leak_flow_downstream", valve_.downstream_leak(valve_.times.size() - 1));
    }
    if (parameters_.benchmark.type == "forces") {
      const auto force = benchmark_force();
      series.add("drag", force[0]);
      series.add("lift", force[1]);
      const auto& b = parameters_.benchmark;
      if (b.statistics && time >= b.statistics_from) {
        forces_.times.push_back(time);
        forces_.values[0].push_back(force[0]);
        forces_.values[1].push_back(force[1]);
        if (probe_index_ >= 0) {
          const auto u = find_solid(b.probe_solid)->model->probe_values()[probe_index_];
          for (std::size_t i = 0; i < u.size(); ++i) forces_.values[2 + i].push_back(u[i]);
        }
      }
    }
    if (const auto* body = benchmark_body()) {
      series.add("drag_coefficient", coefficient_scale() * body->total_force[0]);
      series.add("lift_coefficient", coefficient_scale() * body->total_force[1]);
    }
    series.add("force_balance", force_balance_);
    series.add("kinetic_energy_fluid", fluid_.kinetic_energy());
    fluid_.record_flows(series);
    series.end_row();
  }

  void benchmark(run::RunOutput& output) {
    const auto& b = parameters_.benchmark;
    const auto& mesh = fluid_.mesh();
    auto& json = output.summary()["benchmark"];
    json["cells"] = static_cast<std::int64_t>(mesh.n_global_cells);
    json["vertices"] = static_cast<std::int64_t>(mesh.n_global_vertices);
    json["force_balance_error"] = force_balance_;
    // each constrained fluid vertex once (a vertex several solids share counts in each of
    // their entries below)
    json["constrained_fluid_vertices"] = static_cast<std::int64_t>(n_constrained_);
    const char* force_unit = mesh.dim == 2 ? "N/m" : "N";
    for (const auto& solid : solids_) {
      auto& entry = json["solids"][solid->entry->name];
      entry["cells"] = static_cast<std::int64_t>(solid->mesh.n_global_cells);
      entry["constrained_fluid_vertices"] =
          static_cast<std::int64_t>(solid->constraint->n_constrained());
      if (partial_coverage())
        entry["partial_fluid_vertices"] = static_cast<std::int64_t>(solid->constraint->n_partial());
      entry["force"] = io::Json::array_of(solid->total_force);
      log::info("solid '{}': {} constrained fluid vertices, force ({:.8e}) {}", solid->entry->name,
                solid->constraint->n_constrained(), fmt::join(solid->total_force, ", "),
                force_unit);
      const auto per_body = body_forces(*solid);
      for (std::size_t b = 0; b < per_body.size(); ++b) {
        const auto& body = solid->model->parameters().bodies[b].name;
        entry["body_forces"][body] = io::Json::array_of(per_body[b]);
        log::info("  body '{}': force ({:.8e}) {}", body, fmt::join(per_body[b], ", "), force_unit);
      }
    }
    log::info("force balance: max |sum B^T lambda - sum reactions| / |sum reactions| = {:.3e}",
              force_balance_);
    if (b.type == "valve") valve_benchmark(json);
    if (b.type == "forces" && b.statistics) {
      forces_statistics(json);
      return;
    }
    if (b.type == "forces") {
      const auto force = benchmark_force();
      json["drag"] = force[0];
      json["lift"] = force[1];
      log::info("drag = {:.8g} {}, lift = {:.8g} {}", force[0], force_unit, force[1], force_unit);
      if (b.reference_drag_force != 0)
        json["drag_error"] = std::abs(force[0] / b.reference_drag_force - 1);
      if (b.reference_lift_force != 0)
        json["lift_error"] = std::abs(force[1] / b.reference_lift_force - 1);
      if (probe_index_ >= 0) {
        const auto u = find_solid(b.probe_solid)->model->probe_values()[probe_index_];
        json["displacement_x"] = u[0];
        json["displacement_y"] = u[1];
        if (u.size() == 3) json["displacement_z"] = u[2];
        log::info("probe '{}': u = ({:.8g}) m", b.probe, fmt::join(u, ", "));
        if (b.reference_displacement_x != 0)
          json["displacement_x_error"] = std::abs(u[0] / b.reference_displacement_x - 1);
        if (b.reference_displacement_y != 0)
          json["displacement_y_error"] = std::abs(u[1] / b.reference_displacement_y - 1);
      }
      return;
    }
    if (b.type != "cylinder") return;
    const auto* body = benchmark_body();
    const double drag = coefficient_scale() * body->total_force[0],
                 lift = coefficient_scale() * body->total_force[1];
    json["drag_force"] = body->total_force[0];
    json["lift_force"] = body->total_force[1];
    json["drag_coefficient"] = drag;
    json["lift_coefficient"] = lift;
    log::info("c_D = {:.8f}, c_L = {:.8f}", drag, lift);
    if (b.reference_drag != 0) json["drag_error"] = std::abs(drag / b.reference_drag - 1);
    if (b.reference_lift != 0) json["lift_error"] = std::abs(lift / b.reference_lift - 1);
    if (!b.pressure_points.empty()) {
      const auto pressure =
          fluid::values_at(mesh, fluid_.state(), mesh.dim + 1, mesh.dim, b.pressure_points);
      const double difference = pressure[0] - pressure[1];
      json["pressure_difference"] = difference;
      log::info("Delta p = {:.8f} Pa", difference);
      if (b.reference_pressure_difference != 0)
        json["pressure_difference_error"] =
            std::abs(difference / b.reference_pressure_difference - 1);
    }
  }

  /// The `forces` benchmark of a transient run with statistics_from: drag, lift and the probe's
  /// displacement_x, displacement_y (, _z) over their last full period among the recorded
  /// steps (solid::last_period: mean = (max + min)/2, amplitude = (max − min)/2, frequency
  /// from successive upward mid-level crossings), each as {mean, amplitude, frequency,
  /// periods, final} with mean_error, amplitude_error, frequency_error = |value/reference − 1|
  /// where the case gives the reference. null where fewer than two crossings were seen.
  void forces_statistics(io::Json& json) const {
    const auto& b = parameters_.benchmark;
    struct Reference {
      double mean, amplitude, frequency;
    };
    const std::vector<Reference> references = {
        {b.reference_drag_force, b.reference_drag_amplitude, b.reference_drag_frequency},
        {b.reference_lift_force, b.reference_lift_amplitude, b.reference_lift_frequency},
        {b.reference_displacement_x, b.reference_displacement_x_amplitude,
         b.reference_displacement_x_frequency},
        {b.reference_displacement_y, b.reference_displacement_y_amplitude,
         b.reference_displacement_y_frequency},
        {0, 0, 0}};
    const auto number = [](double x) { return std::isfinite(x) ? io::Json(x) : io::Json(); };
    for (std::size_t q = 0; q < forces_.values.size(); ++q) {
      const auto& values = forces_.values[q];
      const auto summary = solid::last_period(forces_.times, values);
      auto& entry = json[forces_.names[q]];
      entry["mean"] = number(summary.mean);
      entry["amplitude"] = number(summary.amplitude);
      entry["frequency"] = number(summary.frequency);
      entry["periods"] = summary.periods;
      entry["final"] = values.empty() ? io::Json() : io::Json(values.back());
      const auto& reference = references[q];
      const auto error = [&](const char* key, double value, double published) {
        if (published != 0 && std::isfinite(value)) entry[key] = std::abs(value / published - 1);
      };
      error("mean_error", summary.mean, reference.mean);
      error("amplitude_error", summary.amplitude, reference.amplitude);
      error("frequency_error", summary.frequency, reference.frequency);
      log::info(
          "{}: mean {:.6g}, amplitude {:.6g}, frequency {:.6g} Hz ({} full period(s) after "
          "t = {:g} s)",
          forces_.names[q], summary.mean, summary.amplitude, summary.frequency, summary.periods,
          b.statistics_from);
    }
    json["statistics_from"] = b.statistics_from;
  }

  /// The fluid (with a `constrained` marker) and each solid with its force Bᵀλ.
  void write_vtk(run::RunOutput& output, double time) {
    const auto& mesh = fluid_.mesh();
    auto marker_vector = fem::create_vertex_vector(mesh, 1);
    COAPT_PETSC_CHECK(VecSet(marker_vector, 0.0));
    {
      PetscScalar* values = nullptr;
      COAPT_PETSC_CHECK(VecGetArray(marker_vector, &values));
      for (std::size_t k = 0; k < solids_.size(); ++k)
        for (const int v : solids_[k]->constraint->constrained_vertices())
          values[v] = static_cast<double>(k + 1);
      COAPT_PETSC_CHECK(VecRestoreArray(marker_vector, &values));
    }
    fem::update_ghosts(marker_vector);
    std::vector<double> marker(static_cast<std::size_t>(mesh.n_vertices()));
    {
      fem::LocalValues local(marker_vector);
      for (int v = 0; v < mesh.n_vertices(); ++v) marker[v] = local[static_cast<std::size_t>(v)];
    }
    std::vector<io::Field> fields = {
        {"constrained_by_solid", 1, io::Field::Location::vertex, marker}};
    if (partial_coverage()) {
      // how firmly each node is held: 1 constrained, s/(1 + s) under the penalty, 0 free
      COAPT_PETSC_CHECK(VecSet(marker_vector, 0.0));
      PetscScalar* values = nullptr;
      COAPT_PETSC_CHECK(VecGetArray(marker_vector, &values));
      for (const auto& solid : solids_) {
        for (const int v : solid->constraint->constrained_vertices()) values[v] = 1.0;
        const auto& partial = solid->constraint->partial_vertices();
        for (std::size_t q = 0; q < partial.size(); ++q) {
          const double weight = solid->constraint->partial_weights()[q];
          values[partial[q]] = std::min(1.0, values[partial[q]] + weight / (1.0 + weight));
        }
      }
      COAPT_PETSC_CHECK(VecRestoreArray(marker_vector, &values));
      fem::update_ghosts(marker_vector);
      std::vector<double> held(static_cast<std::size_t>(mesh.n_vertices()));
      fem::LocalValues local(marker_vector);
      for (int v = 0; v < mesh.n_vertices(); ++v) held[v] = local[static_cast<std::size_t>(v)];
      fields.push_back({"coupling_weight", 1, io::Field::Location::vertex, held});
    }
    fluid_.write_vtk(output, time, fields);
    for (const auto& solid : solids_) {
      const int dim = solid->mesh.dim;
      std::vector<double> force(static_cast<std::size_t>(solid->mesh.n_vertices()) * dim);
      {
        fem::LocalValues local(solid->force);
        for (std::size_t k = 0; k < force.size(); ++k) force[k] = local[k];
      }
      if (solid->model) {  // the solid's own series "solid", with the coupling force
        std::vector<io::Field> fields = {
            {"coupling_force", dim, io::Field::Location::vertex, force}};
        if (solid->contact) {
          const auto contact_fields = solid->contact->fields();
          fields.insert(fields.end(), contact_fields.begin(), contact_fields.end());
        }
        solid->model->write_vtk(output, time, fields);
        continue;
      }
      const std::vector<io::Field> fields = {{"force", dim, io::Field::Location::vertex, force}};
      output.vtk("solid_" + solid->entry->name).write(solid->mesh, time, fields);
    }
  }

  const Parameters parameters_;
  MPI_Comm comm_;
  fluid::FluidModel fluid_;
  std::vector<std::unique_ptr<Solid>> solids_;
  std::unique_ptr<ConstraintGroup> group_;  ///< the solids' constraints together (after start)
  long long n_constrained_ = 0;  ///< distinct constrained fluid vertices of the last solve
  double force_balance_ = 0;     ///< max over solids of the relative force balance error
  double swept_flow_ = 0;  ///< the valve's swept flow over the last committed step (0: steady)
  /// the upstream surfaces' swept flow past the contact zone over that step (not in swept_flow_)
  double swept_past_contact_ = 0;
  /// the sweep over that step of their part upstream of the contact zone outside the fluid mesh
  double swept_outside_fluid_ = 0;
  std::unique_ptr<UpstreamSurface> upstream_;  ///< benchmark.upstream_surfaces (valve; or null)
  double volume_rate_ = 0;   ///< the valve solid's change of volume over that step, over Δt
  double valve_volume_ = 0;  ///< the valve solid's volume at the last commit
  bool deformable_ = false;  ///< some solid is deformable: coupling iterations
  bool first_solve_failed_ = false;  ///< the last try failed in a solid's first solve of the step
  std::unique_ptr<InterfaceQuasiNewton> quasi_newton_;  ///< coupling.iteration.method iqn_ils
  int last_columns_ = 0;                                ///< columns of the last IQN-ILS update
  std::vector<int> boundary_tags_;                      ///< benchmark.boundaries
  int flow_tag_ = -1;                                   ///< benchmark.flow_boundary (valve)
  int downstream_tag_ = -1;  ///< benchmark.downstream_boundary (valve; -1: none)
  struct ValveHistory {
    std::vector<double> times, opening, flow;
    std::vector<double> swept;  ///< the upstream surfaces' swept flow (0 without them)
    /// the flow out through the downstream boundary (0 without it) and the solid's rate of
    /// change of volume: the leak measured downstream is volume_rate − swept − downstream_flow
    std::vector<double> downstream_flow, volume_rate;
    /// The mean over the step to record k of a flow sampled at the records' ends of steps,
    /// by the trapezoidal rule (record 0: its own value). The swept volume and the change of
    /// volume are the solid's displacement over the step, which Newmark's scheme (β = 1/4,
    /// γ = 1/2) makes the trapezoidal rule of its velocity, Δu = Δt (vₙ + vₙ₊₁)/2, and the
    /// fluid follows that velocity: a flow set against them must be integrated by the same
    /// rule. Its value at the step's end alone (the rectangle rule) is off by Δt/2 times its
    /// change over the step, which summed over a closed phase is Δt/2 times the change of the
    /// flow from the phase's start to its end (docs/verification/fsci.md).
    static double step_mean(const std::vector<double>& values, std::size_t k) {
      return k > 0 ? 0.5 * (values[k - 1] + values[k]) : values[k];
    }
    /// The leak across the valve towards flow_boundary over the step to record k, as a rate:
    /// the step's mean flow out through flow_boundary less the swept flow.
    double leak(std::size_t k) const { return step_mean(flow, k) - swept[k]; }
    /// The same leak measured on the other side: the fluid there loses the volume the
    /// solid's boundary less its upstream surfaces sweeps into it, and what flows out through
    /// the downstream boundary (the step's mean).
    double downstream_leak(std::size_t k) const {
      return volume_rate[k] - swept[k] - step_mean(downstream_flow, k);
    }
    std::vector<char> closed;
    double max_penetration = 0;
  } valve_;
  int probe_index_ = -1;  ///< benchmark.probe in its solid's probes
  /// The `forces` benchmark's steps from statistics_from on: times and per quantity (drag,
  /// lift, then the probe's displacement components) its values.
  struct ForcesHistory {
    std::vector<std::string> names;
    std::vector<double> times;
    std::vector<std::vector<double>> values;
  } forces_;
  const run::CheckpointReader* restart_ = nullptr;
};

}  // namespace

std::unique_ptr<run::Problem> create_fsci_problem(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<FsciProblem>(root, comm);
}

}  // namespace coapt::coupling
