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
///
/// Partial coverage (`partial_from` < the threshold t; method/notes.md has no such rule, it is
/// this code's regularisation of the covered-node rule). A fluid node that is not constrained
/// but whose covered fraction c_i lies in [partial_from, t) is drawn towards the solid's
/// velocity by a penalty of weight s_i = (c_i − partial_from)/(t − c_i) (at most 1e6; a node
/// not constrained although c_i ≥ t, e.g. while the set is frozen, gets 1e6), which grows from
/// 0 where the node starts to count to the constraint itself at the threshold
/// (NavierStokes::set_velocity_penalty). Its target and its load on the solid use the standard
/// basis, whose weights are positive on any part of a support (the dual basis's are not):
///
///   w_i = (B^std v_s)_i / ∫_Ω λ_i,     f_s += B^stdᵀ (r_i / ∫_Ω λ_i)   (Σ_j B^std_ij = ∫_Ω λ_i),
///
/// r_i the penalty's force at node i, so Σ_j (f_s)_j gains exactly Σ_i r_i and the load does
/// the work r_i·w_i. The set and the weights change continuously as the solid moves: a node
/// enters the penalty with weight 0 and the constraint with weight ∞, so the fluid sees a
/// motion smaller than its elements, and the coupling's fixed-point map has no jumps.
///
/// The pressure inside a solid (`coupling.pressure_in_solid`; not in method/paper.md, this
/// code's addition). Over the solid's region the fluid is fictitious; at rest it carries the
/// stress −p I, and the solid, loaded by λ, feels only the pressure's gradient, never its
/// level: a body-fitted compressible solid is squeezed by the pressure around it, an immersed
/// one is not. As the solid carries ρ_s − ρ_f so that the two densities add up to the real one,
/// it can carry σ_s + p I so that the two stresses add up to the real σ_s: the load
/// −∫_Ω_s p div w (solid::SolidModel::set_immersed_pressure), with the pressure on the solid's
/// vertices from solid_pressure(): p_j = (B^stdᵀ p_f)_j / Σ_i B^std_ij, the fluid's pressure
/// averaged over the support of φ_j. The load has no resultant (Σ_j ∇φ_j = 0), so drag, lift
/// and the force balance keep their values; under a uniform p it is the surface load −p n.

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
  /// `partial_from`: the covered fraction from which a node is drawn towards the solid by a
  /// penalty (file comment; ≥ the threshold: no partial coverage).
  ImmersedConstraint(const mesh::Mesh& fluid, const mesh::Mesh& solid,
                     const transfer::TransferOptions& options, std::vector<char> fixed = {},
                     double partial_from = 1.0);

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

  /// The partly covered vertices (owned local fluid vertices, ascending; none unless
  /// partial_from is below the threshold) and their penalty weights s_i.
  const std::vector<int>& partial_vertices() const { return partial_; }
  const std::vector<double>& partial_weights() const { return partial_weight_; }
  /// Number of partly covered vertices over all ranks.
  PetscInt n_partial() const { return n_partial_; }
  /// Drops the partly covered vertices that `member` (per owned fluid vertex) marks: a group's
  /// constrained nodes (ConstraintGroup::combine).
  void drop_partial(const std::vector<char>& member);
  /// The penalty's targets w_i at the partly covered vertices (partial_vertices().size() × dim)
  /// from a solid vertex vector with dim components [m/s].
  std::vector<double> partial_velocity(Vec solid_velocity) const;
  /// The same for a velocity that is the same vector at every solid node.
  std::vector<double> partial_uniform_velocity(const std::vector<double>& velocity) const;
  /// Adds B^stdᵀ (r_i / ∫_Ω λ_i) to `solid_force` from the penalty's forces r at the partly
  /// covered vertices (same layout as partial_velocity; ghosts not updated).
  void add_partial_force(const std::vector<double>& reactions, Vec solid_force) const;
  /// Σ over all ranks of a partly-covered-vertex array (e.g. the penalty's total force).
  std::vector<double> sum_partial(const std::vector<double>& values) const;

  /// The fluid's pressure on the solid's vertices, p_j = (B^stdᵀ p_f)_j / Σ_i B^std_ij (0 at
  /// a vertex whose support the fluid mesh does not reach), from the fluid's state (u, p
  /// interleaved, `fluid.dim + 1` components), into `pressure` (a solid vertex vector with one
  /// component, fem::create_vertex_vector; ghosts updated) [Pa]. Needs TransferOptions::primal.
  /// Collective.
  void solid_pressure(Vec fluid_state, Vec pressure) const;

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
  void collect_partial();
  void count_constrained();
  /// (coupling x)_i / divisors[q] at each vertex i = vertices[q], dim components each
  /// (row-major); x a solid vertex vector with dim components. Collective.
  std::vector<double> divided_product(Mat coupling, Vec solid_vector,
                                      const std::vector<int>& vertices,
                                      const std::vector<double>& divisors) const;
  /// couplingᵀ y with y = `values` at `vertices` (dim each, row-major) and 0 elsewhere, into
  /// `solid_vector` (added to it when `add`). Collective.
  void transpose_product(Mat coupling, const std::vector<int>& vertices,
                         const std::vector<double>& values, Vec solid_vector, bool add) const;

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
  double partial_from_ = 1.0;
  OwnedMat partial_coupling_;             ///< B^std ⊗ I_dim (partial coverage only)
  std::vector<int> partial_;              ///< owned local fluid vertices, partly covered
  std::vector<double> partial_weight_;    ///< s_i at partial_
  std::vector<double> partial_integral_;  ///< ∫_Ω λ_i at partial_
  PetscInt n_partial_ = 0;
};

}  // namespace coapt::coupling
