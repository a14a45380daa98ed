#pragma once
/// @file immersed_constraint.hpp
/// The velocity constraint between the fluid (slave) and one immersed solid (master) over
/// their overlap, discretised with the dual mortar operators of transfer::VariationalTransfer
/// (method/paper.md §2–3, method/notes.md "The velocity constraint in the fluid solve",
/// "Action and reaction in the coupling"):
///
///   D v_f = B v_s          on the constrained fluid nodes C (D diagonal there), i.e.
///   v_f,i = (T v_s)_i = (B v_s)_i / D_i      for i ∈ C, a Dirichlet value of the fluid solve;
///   λ_i   = r_i / D_i                         the multiplier from the constraint reaction r_i
///                                             (the force the fluid exerts on the constraint
///                                             at node i, NavierStokes::constraint_reactions);
///   f_s   = Bᵀ λ                              the nodal force of the fluid on the solid.
///
/// Balance: Σ_j B_ij = D_i (Σ_j φ_j = 1 on the solid), so Σ_j (f_s)_j = Σ_i λ_i D_i = Σ_i r_i
/// component by component: the total force on the solid is minus the total constraint force
/// on the fluid to round-off (checked by force_balance()).
///
/// Which fluid nodes are constrained is the transfer's covered-node rule
/// (TransferOptions::coverage_threshold): by default those whose whole support lies in the
/// solid, where biorthogonality makes T exact for linear fields. Vectors are interleaved
/// vertex vectors (vertex v, component i at v·dim + i) in the PETSc layouts of the meshes.
///
/// With several solids a fluid node may be covered by more than one (leaflets in contact, a
/// leaflet sewn to a stent): coupling::ConstraintGroup then replaces D_i by the solids' sum
/// D_i = Σ_k D_k,i in the formulas above (assign()), so that each solid's transfer_velocity()
/// is its share (B_k v_k)_i / D_i of the node's velocity and multiplier() the node's λ_i.

#include <petscmat.h>
#include <petscvec.h>

#include <array>
#include <memory>
#include <vector>

#include "coapt/core/petsc.hpp"
#include "coapt/mesh/mesh.hpp"
#include "coapt/transfer/operators.hpp"

namespace coapt::coupling {

/// The constraint between a fluid mesh and one solid mesh. Every call is collective on the
/// meshes' communicator. Both meshes must outlive the object.
class ImmersedConstraint {
 public:
  /// `fixed`: per owned fluid vertex, nonzero where the fluid has a velocity condition of its
  /// own (a wall, an inlet; FluidModel::velocity_condition_vertices). Such a vertex is never
  /// constrained: its boundary condition holds there, and its reaction is that boundary's
  /// force. Were it constrained too, its reaction would also be the solid's load and be counted
  /// twice in the body's force (a bar clamped to a body-fitted cylinder: the pressure inside the
  /// bar on the cylinder's arc). Empty: no such vertex.
  ImmersedConstraint(const mesh::Mesh& fluid, const mesh::Mesh& solid,
                     const transfer::TransferOptions& options, std::vector<char> fixed = {});

  /// The solid moved (same mesh, new coordinates): re-assembles B, D and the constrained set
  /// (while frozen: B and D only).
  void update_solid(const mesh::Mesh& moved);
  /// Frozen: update_solid() keeps the constrained set it has (less the nodes whose D_i is no
  /// longer positive) instead of applying the covered-node rule again. The coupling freezes
  /// it after some iterations of a step: the rule makes the fixed-point map discontinuous
  /// (a node enters or leaves the set as the solid moves by round-off), which can trap the
  /// iteration in a limit cycle.
  void set_frozen(bool frozen) { frozen_ = frozen; }
  bool frozen() const { return frozen_; }
  /// A checkpoint's state: the solid at `moved` with the constrained set it had
  /// (`constrained`: owned local fluid vertices, ascending; the covered-node rule is not
  /// applied again) and the frozen flag it had.
  void restore(const mesh::Mesh& moved, std::vector<int> constrained, bool frozen);

  /// Part of a ConstraintGroup of several solids: a frozen set keeps its nodes whatever this
  /// solid's own D_k,i (the group drops a node whose summed D_i is not positive).
  void set_shared(bool shared) { shared_ = shared; }
  /// The group's decision (ConstraintGroup::combine): this solid's constrained vertices (owned
  /// local fluid vertices, ascending) and the summed D_i = Σ_k D_k,i of each. Collective.
  void assign(std::vector<int> vertices, std::vector<double> total_dual);

  /// Owned local fluid vertices of the constrained set, ascending.
  const std::vector<int>& constrained_vertices() const { return constrained_; }
  /// Number of constrained fluid vertices over all ranks.
  PetscInt n_constrained() const { return n_constrained_; }

  /// T v_s at the constrained vertices (constrained_vertices().size() × dim, row-major) from a
  /// solid vertex vector with dim components [m/s].
  std::vector<double> transfer_velocity(Vec solid_velocity) const;
  /// The same for a velocity that is the same vector at every solid node (a translating body).
  std::vector<double> transfer_uniform_velocity(const std::vector<double>& velocity) const;

  /// λ = r / D at the constrained vertices from their reactions r (same layout) [N/m³ in 3D,
  /// N/m² in 2D].
  std::vector<double> multiplier(const std::vector<double>& reactions) const;
  /// f_s = Bᵀ λ into `solid_force` (a solid vertex vector with dim components, overwritten;
  /// ghosts not updated) [N, N/m in 2D].
  void solid_force(const std::vector<double>& multiplier, Vec solid_force) const;
  /// A new solid vertex vector with dim components (ghosted, fem::create_vertex_vector).
  OwnedVec create_solid_vector() const;

  /// Σ over all nodes of a solid vertex vector with dim components (e.g. the total force).
  std::vector<double> sum_components(Vec solid_vector) const;
  /// Σ over all ranks of a constrained-vertex array (e.g. the total reaction), each vertex's
  /// entries weighted by this solid's share D_k,i / D_i (1 unless the node is shared): for the
  /// reactions, what Σ Bᵀλ of this solid balances.
  std::vector<double> sum_constrained(const std::vector<double>& values) const;

  const transfer::VariationalTransfer& transfer() const { return *transfer_; }

 private:
  void collect();
  void count_constrained();

  const mesh::Mesh& fluid_;
  const mesh::Mesh* solid_;
  std::unique_ptr<transfer::VariationalTransfer> transfer_;
  OwnedMat coupling_;             ///< B ⊗ I_dim (MAIJ view of the transfer's B)
  OwnedVec fluid_work_;           ///< fluid layout, dim components
  std::vector<char> fixed_;       ///< per owned fluid vertex: a velocity condition of its own
  std::vector<int> constrained_;  ///< owned local fluid vertices
  std::vector<double> dual_;      ///< D_i at constrained_ (summed over a group's solids)
  std::vector<double> own_dual_;  ///< this solid's D_k,i at constrained_
  PetscInt n_constrained_ = 0;    ///< constrained_ summed over the ranks
  bool frozen_ = false;
  bool shared_ = false;
};

}  // namespace coapt::coupling
