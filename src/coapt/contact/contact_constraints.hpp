#pragma once
/// @file contact_constraints.hpp
/// Frictionless mortar contact as a transformation of the solid's Newton system: the
/// primal–dual active set (semi-smooth Newton) of Hüeber and Wohlmuth (2005) with the dual
/// multipliers condensed out node by node (Popp et al. 2009).
///
/// Residual R(u) = f_int − f_ext (+ inertia) of the solid without contact; for a slave node j
/// with averaged normal n_j and the mortar operators of mortar.hpp (D_jj, D̂_jk, M_jl, g̃_j)
/// at the current configuration x = X + u, the contact force is B_jᵀ λ_j with
///   B_j = [D̂_jk on slave nodes k, −M_jl on master nodes l],  λ_j = p_j n_j,
/// so equilibrium reads R + Σ_j B_jᵀ λ_j = 0, and frictionless contact
///   p_j ≥ 0,  g_j = g̃_j / D_jj ≥ 0,  p_j g_j = 0  ⇔  C_j = p_j − max(0, p_j − c g_j) = 0.
/// Because D̂_jk = δ_jk D_jj on a constrained node, its own equation gives its multiplier:
///   p_j = −n_j · R_j / D_jj   (R_j: the residual of node j, no contact force in it).
/// Active set A = {j constrained : p_j − c (g_j − tol) > 0}, where a node already in A counts
/// only a negative g_j − tol (its open gap is the round-off of the unlinearised geometry, see
/// update()); before c is known (the first update of a run, before any stiffness was seen)
/// A = {g_j ≤ tol}: away from equilibrium p_j is the out-of-balance force, whose sign says
/// nothing about an open node. On A, the node's normal equation
/// is replaced by the linearised gap condition g̃_j(u + Δu) ≈ g̃_j − n_jᵀ B_j Δu = 0, its
/// tangential equations stay (frictionless: λ_t = 0), and its multiplier is eliminated from
/// the other rows: with the row operator
///   P = I − Σ_{j∈A} E_j n_j n_jᵀ E_jᵀ + Σ_{j∈A} Σ_{k≠j} (−B_jk / D_jj) S_k E_k n_j n_jᵀ E_jᵀ
/// (E_j picks node j's block, S_k = I − n_k n_kᵀ if k is itself active, else I) the Newton
/// system K Δu = −R becomes
///   (P K + G) Δu = −(P R − c Σ_{j∈A} E_j n_j g̃_j),   G = c Σ_{j∈A} E_j n_j n_jᵀ B_j,
/// whose residual vanishes exactly when equilibrium with contact forces, the gap
/// conditions on A and λ = 0 off A hold. c scales the gap rows to forces (Pa/m × m^dim).
/// The mortar operators, normals and the search are recomputed at every residual, so the
/// search follows the bodies as they move; their derivatives are not linearised (the
/// Newton iteration is then inexact in the geometry and converges linearly where the
/// contact zone deforms strongly).
///
/// Dirichlet dofs keep their identity rows (P and G leave them alone) and are not read as
/// equilibrium equations; a slave node should not have a Dirichlet component along its
/// normal. Parallel: every rank holds all contact surfaces (surface.hpp) and the same
/// multipliers and active set, and fills its own rows of P and G.

#include <mpi.h>
#include <petscmat.h>
#include <petscvec.h>

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "coapt/contact/contact_parameters.hpp"
#include "coapt/contact/mortar.hpp"
#include "coapt/contact/surface.hpp"
#include "coapt/core/petsc.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::contact {

/// The contact state after the last update (the same on every rank).
struct ContactStatus {
  int constrained = 0;               ///< slave nodes that may come into contact
  int active = 0;                    ///< slave nodes in the active set
  int changes = 0;                   ///< nodes that entered or left the active set at the update
  double max_penetration = 0.0;      ///< max(0, −g_j) over constrained nodes [m]
  double max_pressure = 0.0;         ///< max p_j over active nodes [Pa]
  double min_active_pressure = 0.0;  ///< min p_j over active nodes [Pa] (0 if none)
  double max_open_pressure = 0.0;    ///< max |p_j| over inactive constrained nodes [Pa]
  double max_complementarity = 0.0;  ///< max |p_j g_j| over constrained nodes [Pa m]
  double total_force = 0.0;          ///< Σ_j p_j ∫_Γc Φ̃_j over active nodes [N, N/m in 2D]
  double contact_measure = 0.0;      ///< Σ_j ∫_Γc Φ̃_j over active nodes [m², m in 2D]
  /// Σ_j p_j n_j ∫_Γc Φ̃_j over active nodes: the force the slave surfaces exert on the masters
  /// [N, N/m in 2D] (dim entries used; with frictionless contact its magnitude is total_force
  /// when all normals are parallel).
  std::array<double, 3> force_vector{};
  double complementarity_constant = 0.0;  ///< c in use [Pa/m] (0: not yet known)
  double gap_tolerance = 0.0;             ///< [m]
  /// The first nodes that changed at the update: "pair:node in|out (p, g)", for the log.
  std::string changed_nodes;
};

/// One pair's surfaces and state, for output and benchmarks (the same on every rank).
struct PairState {
  Surface slave, master;
  std::vector<double> slave_x, master_x;  ///< current coordinates (n × dim)
  MortarOperators mortar;
  std::vector<double> pressure;  ///< p_j [Pa] (0 off the constrained nodes)
  std::vector<char> active;
  std::vector<char> dirichlet;         ///< per slave dof (n × dim): prescribed
  std::vector<char> master_dirichlet;  ///< per master dof (n × dim): prescribed
  std::vector<double> slave_residual;  ///< R at the slave dofs at the last update (n × dim)
};

/// The contact constraints of a solid (see the file comment).
class ContactConstraints {
 public:
  /// Gathers the surfaces of every pair. `dirichlet_dofs`: this rank's prescribed dofs
  /// (global numbers, owned); `layout`: a displacement vector (fem::create_vertex_vector).
  /// Collective.
  ContactConstraints(const ContactParameters& parameters, const mesh::Mesh& mesh,
                     std::span<const PetscInt> dirichlet_dofs, Vec layout);
  ContactConstraints(const ContactConstraints&) = delete;
  ContactConstraints& operator=(const ContactConstraints&) = delete;
  ~ContactConstraints();

  /// At displacement u with the solid's residual R(u) (assembled, before its Dirichlet rows
  /// are zeroed): mortar operators, multipliers and active set; then R ← P R − c n g̃ on A.
  /// Collective.
  void update(Vec u, Vec residual);
  /// The contact Newton matrix P K + G (owned here, valid until the next call) and
  /// rhs ← P rhs + c n g̃ on A, for K Δu = rhs = −R after the solid's Dirichlet treatment.
  /// Collective.
  Mat transform(Mat K, Vec rhs);
  /// Contact-stabilized Newmark predictor: projects the increment δ (a displacement-layout
  /// vector, owned entries) so that uₙ + δ does not penetrate, in the norm of the lumped mass
  /// `lumped_mass` (same layout; mortar operators at the displacement u = uₙ): a node-wise clip
  /// against a held master, a small quadratic program between two deformable bodies (see the
  /// definition). Returns the number of slave nodes whose constraint is active. Collective.
  int project_predictor(Vec u, Vec increment, Vec lumped_mass);

  /// Pair p's active set into `marker` (a vector with the layout given at construction): 1 in
  /// every component of its active slave nodes, 0 elsewhere (owned entries; for a
  /// checkpoint). Collective.
  void active_marker(std::size_t p, Vec marker) const;
  /// Takes pair p's active set back from such a marker: the next update counts its changes
  /// against it. Collective.
  void restore_active(std::size_t p, Vec marker);
  /// c [Pa/m] in use (0: computed from the stiffness at the next transform that finds a
  /// constrained node).
  double complementarity_constant() const { return complementarity_constant_; }
  void set_complementarity_constant(double c) {
    complementarity_constant_ = c;
    status_.complementarity_constant = c;
  }

  const ContactStatus& status() const { return status_; }
  const std::vector<PairState>& pairs() const { return pairs_; }

  /// What an update changes: each pair's current coordinates, mortar operators, pressures,
  /// active set and slave residual, the status and c. Taken before a coupled step and put
  /// back after it fails, so that the next try, the output and the checkpoint start from the
  /// last good state's contact, not the failed try's.
  struct Snapshot {
    std::vector<PairState> pairs;  ///< the surfaces left empty
    ContactStatus status;
    double complementarity_constant = 0.0;
  };
  Snapshot snapshot() const;
  /// Puts a snapshot of these pairs back. Not collective (the pair states are the same on
  /// every rank).
  void restore(const Snapshot& snapshot);
  /// Vertex fields over the local vertices of the mesh (owned and ghost): contact pressure
  /// [Pa], gap [m] and active flag (1/0) at slave nodes, 0 elsewhere.
  void vertex_fields(std::vector<double>& pressure, std::vector<double>& gap,
                     std::vector<double>& active) const;
  /// One line for the log.
  std::string describe() const;

 private:
  void build_row_operator();
  /// Whether owned dof `dof` (global number) is prescribed.
  bool prescribed(PetscInt dof) const;
  /// v ← v + sign c n_j g̃_j at the free dofs of the active slave nodes (owned). Collective.
  void add_gap_terms(Vec v, double sign);
  /// The geometry-dependent part of pair p's transformed residual, P R − R − c n g̃ (R the
  /// residual at the last update, the active set frozen), at surface coordinates slave_x,
  /// master_x: per slave and master dof (n × dim). Serial.
  void contact_terms(std::size_t p, std::span<const double> slave_x,
                     std::span<const double> master_x, std::vector<double>& slave_terms,
                     std::vector<double>& master_terms) const;
  /// Its derivative by central differences of the surface coordinates that enter it, as
  /// matrix triplets on this rank's free rows (the finite_difference linearisation). Serial.
  void add_geometric_tangent(std::size_t p, std::vector<PetscInt>& rows,
                             std::vector<PetscInt>& columns, std::vector<double>& values) const;
  /// The current coordinates X + u of pair p's slave and master nodes (n × dim). Collective.
  void current_positions(std::size_t p, Vec u, std::vector<double>& slave_x,
                         std::vector<double>& master_x) const;
  /// The mortar search and integration options of pair p.
  MortarOptions mortar_options(std::size_t p) const;

  ContactParameters parameters_;
  const mesh::Mesh& mesh_;
  int dim_;
  PetscInt first_dof_ = 0, end_dof_ = 0;  ///< owned dof range
  std::vector<PetscInt> dirichlet_;       ///< sorted owned prescribed dofs
  OwnedVec dirichlet_marker_;             ///< 1 on prescribed dofs
  std::vector<PairState> pairs_;
  std::vector<std::unique_ptr<SurfaceGather>> slave_gathers_, master_gathers_;
  std::vector<double> reference_sizes_;  ///< mean slave facet size per pair [m]
  double complementarity_constant_ = 0.0;
  ContactStatus status_;
  OwnedMat row_operator_;  ///< P
  OwnedMat gap_rows_;      ///< G
  OwnedMat contact_matrix_;
  OwnedVec work_;
};

}  // namespace coapt::contact
