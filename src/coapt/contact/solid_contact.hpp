#pragma once
/// @file solid_contact.hpp
/// Contact in the solid's Newton iteration: a solid::NewtonHook over ContactConstraints
/// (contact_constraints.hpp), its output (VTU fields, series columns, summary figures), and
/// the Hertz comparison of the `hertz:` case section.
///
///   hertz:                       analytic reference (Johnson 1985, refs §5), optional
///     geometry: cylinder         cylinder (2D line contact) or sphere (3D point contact)
///     radius: 1.0                R [m] of the elastic body pressed on a rigid flat
///     load: 2.0e5                the whole body's load P [N/m for a cylinder, N for a sphere]
///     young_modulus: 1e8         E [Pa] and ν of the body: E* = E / (1 − ν²)
///     poisson_ratio: 0.3
///
///   patch_test: {force: 1.0e5}      the total normal load [N/m, N] a patch test transmits
///
/// The model may be a symmetric part of the body: the contact zone is measured from the
/// symmetry axis x = 0 (2D; the contact normal along y) or x = y = 0 (3D; normal along z).

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "coapt/contact/contact_constraints.hpp"
#include "coapt/contact/contact_parameters.hpp"
#include "coapt/core/config.hpp"
#include "coapt/io/json.hpp"
#include "coapt/io/vtk_writer.hpp"
#include "coapt/run/run_output.hpp"
#include "coapt/solid/solid_model.hpp"

namespace coapt::contact {

/// Reads the `contact:` section of a solid's case section (ContactParameters::read); with
/// contact, the solid's linear solver defaults to a direct one (MUMPS LU: the contact rows
/// make the system non-symmetric with a coupling AMG does not expect) unless -solid_ksp_type
/// or -solid_pc_type is given. Collective (PETSc options).
ContactParameters read_solid_contact(const config::Section& root);

/// The smallest distance between the slave and the master surface of a pair in its current
/// configuration (PairState::slave_x, master_x): min over slave nodes of the distance to the
/// master's facets (segments in 2D, triangles in 3D) [m]. +∞ for an empty surface. Serial.
double surface_distance(const PairState& pair);

/// The `hertz:` section (see the file comment); absent: `enabled` false.
struct HertzParameters {
  bool enabled = false;
  bool sphere = false;
  double radius = 0.0;
  double load = 0.0;
  double young_modulus = 0.0;
  double poisson_ratio = 0.0;
  static HertzParameters read(const config::Section& root);
  /// E* = E / (1 − ν²) [Pa].
  double effective_modulus() const { return young_modulus / (1.0 - poisson_ratio * poisson_ratio); }
  /// Peak pressure p₀ [Pa]: line √(P E*/(π R)), point (6 P E*²/(π³ R²))^(1/3).
  double max_pressure() const;
  /// Contact half-width b = √(4 P R/(π E*)) (line) or radius a = (3 P R/(4 E*))^(1/3) [m].
  double contact_size() const;
};

/// The `patch_test:` section: the total normal load a contact patch test must transmit.
struct PatchTestParameters {
  bool enabled = false;
  double force = 0.0;  ///< [N/m in 2D, N in 3D]
  static PatchTestParameters read(const config::Section& root);
};

/// Max |p_j − p| / p over the active nodes of every pair, p = force / contact measure (the
/// uniform Cauchy pressure that carries the load over the current contact surface).
double pressure_error(const ContactConstraints& constraints, double force);

/// The nominal contact pressure of each slave node of `pair`: its contact force p_j D_jj (the
/// mortar operators are integrated on the current surface, so p_j is a force per current
/// area) divided by its reference lumped area ∫_Γs(X) N_j (the node's share of the areas, or
/// lengths in 2D, of its facets at the reference coordinates). The force per undeformed area
/// (a first Piola–Kirchhoff traction) is the pressure of geometrically linear theory, which
/// does not tell the two configurations apart; p_j itself is the Cauchy pressure. 0 where
/// p_j is 0 or the node has no facet. Serial.
std::vector<double> nominal_pressures(const PairState& pair);

/// Measured Hertz figures from the slave pressures.
struct HertzMeasurement {
  double max_pressure = 0.0;          ///< largest nodal pressure p_j [Pa]
  double max_nominal_pressure = 0.0;  ///< largest nominal pressure (nominal_pressures) [Pa]
  double contact_size = 0.0;  ///< b or a from the fit p² = p₀² (1 − r²/b²) over the active nodes
  double fitted_pressure = 0.0;   ///< p₀ of that fit [Pa]
  double outermost_active = 0.0;  ///< largest r of an active node [m]
  int active_nodes = 0;
};

/// Fits the Hertz profile to the active nodes of every pair (r from the axis, file comment).
HertzMeasurement measure_hertz(const ContactConstraints& constraints, bool sphere);

/// The Newton hook: the contact transformation at every residual and linear system, and the
/// active-set test for convergence.
class ContactHook final : public solid::NewtonHook {
 public:
  /// Gathers the contact surfaces of the solid's mesh. Collective.
  ContactHook(const ContactParameters& parameters, const solid::SolidModel& solid);

  void begin_step(Vec u) override;
  void add_residual(Vec u, Vec residual) override;
  Mat linear_system(Vec u, Mat K, Vec rhs) override;
  bool accept(Vec u) override;
  void project_predictor(Vec u, Vec increment, Vec lumped_mass) override;

  const ContactConstraints& constraints() const { return constraints_; }
  /// Newton iterations of the current step after which the active set changed (the step
  /// cannot end at those).
  int active_set_change_iterations() const { return changing_iterations_; }
  /// Nodes that entered or left the active set, summed over those iterations of the step.
  int active_set_node_changes() const { return changed_nodes_; }
  /// The contact fields for SolidModel::write_vtk (pressure, gap, active set).
  std::vector<io::Field> fields();
  /// Adds the contact columns of the current state to the series row being built, each name
  /// followed by `suffix` (e.g. "_leaflets" when several solids have contact).
  void add_series(run::RunOutput& output, const std::string& suffix = "") const;
  /// Writes every slave node of every pair as a CSV row (pair, reference coordinates,
  /// pressure [Pa], gap [m], active, constrained, nominal pressure [Pa] of nominal_pressures)
  /// to `file`, on rank 0 only. Collective.
  void write_nodes(const std::filesystem::path& file, MPI_Comm comm) const;
  /// Logs the contact state after a step.
  void log_status(const std::string& label) const;
  /// Wall time spent in the contact update, the Newton matrix transformation and the
  /// predictor projection since construction [s] (this rank).
  double seconds() const { return seconds_; }
  /// Adds the contact state that carries over to the next step to a checkpoint: each pair's
  /// active set (field `prefix`active<p>, 1 at active slave nodes) and the complementarity
  /// constant (state[`prefix`contact]). Collective.
  void write_checkpoint(run::CheckpointWriter& writer, const std::string& prefix) const;
  /// Takes it back; InputError naming the checkpoint folder when its pairs are not these.
  void read_checkpoint(const run::CheckpointReader& reader, const std::string& prefix);

  /// The contact state and the step's counts of active-set changes (ContactConstraints::
  /// Snapshot): taken before a coupled step, put back after it fails.
  struct Snapshot {
    ContactConstraints::Snapshot constraints;
    int changing_iterations = 0, changed_nodes = 0;
  };
  Snapshot snapshot() const {
    return {constraints_.snapshot(), changing_iterations_, changed_nodes_};
  }
  void restore(const Snapshot& snapshot) {
    constraints_.restore(snapshot.constraints);
    changing_iterations_ = snapshot.changing_iterations;
    changed_nodes_ = snapshot.changed_nodes;
  }

 private:
  ContactParameters parameters_;
  const mesh::Mesh& mesh_;
  ContactConstraints constraints_;
  int changing_iterations_ = 0;
  int changed_nodes_ = 0;
  double seconds_ = 0;
  std::vector<double> pressure_, gap_, active_;
};

}  // namespace coapt::contact
