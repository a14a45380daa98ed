#pragma once
/// @file constraint_group.hpp
/// The fluid's velocity constraint with all the immersed solids at once: the rule for fluid
/// nodes that several solids cover (method/notes.md "Thin solids": two leaflets in contact, a
/// leaflet sewn to a stent, the stent in the aortic root).
///
/// The solids' projections are **summed**: with B_k, D_k the mortar operators of solid k
/// (ImmersedConstraint), a fluid node i is constrained when the solids together cover the
/// threshold of its support, Σ_k c_k,i ≥ t (and D_i > 0, and it has no velocity condition of
/// its own), and then
///
///   D_i = Σ_k D_k,i,     v_f,i = Σ_k (B_k v_k)_i / D_i,     λ_i = r_i / D_i,     f_k = B_kᵀ λ,
///
/// the sums over the solids that overlap the node's support. Since B and D are integrals over
/// the overlap, this is the projection from the union of the solids: a body cut into several
/// solids is constrained exactly as the whole body (same nodes, same velocities, same total
/// force), and the gap between two solids in contact is closed where one solid alone would
/// cover too little of a node's support. The balance holds per solid, Σ_j (f_k)_j =
/// Σ_i r_i D_k,i / D_i, and over all, Σ_k Σ_j (f_k)_j = Σ_i r_i. A node that one solid alone
/// covers keeps that solid's D_k,i and T = D_k⁻¹B_k exactly (a group of solids that share no
/// node is constrained as each solid alone, bit for bit).
///
/// While the constraints are frozen (ImmersedConstraint::set_frozen) the constrained set is
/// the union of their sets; a solid joins a node of it while it overlaps the node's support.
///
/// Partial coverage (ImmersedConstraint's partial_from): each solid keeps its own partly
/// covered nodes and penalty weights, less the nodes the group constrains; a node partly
/// covered by several solids receives each one's penalty (their forces add).
///
///   ConstraintGroup group(fluid_mesh, {&constraint_a, &constraint_b}, threshold, fixed);
///   group.combine();                            // after the solids moved
///   const auto merged = group.merge({a.transfer_velocity(va), b.transfer_velocity(vb)});
///   fluid.set_velocity_constraint(merged.vertices, merged.velocities);
///   const auto reactions = fluid.constraint_reactions();       // per merged vertex
///   a.solid_force(a.multiplier(group.reactions_of(0, reactions)), force_a);

#include <vector>

#include "coapt/coupling/immersed_constraint.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::coupling {

/// The fluid's constrained vertices with one velocity each (the solids' shares summed).
struct MergedConstraint {
  std::vector<int> vertices;       ///< owned local fluid vertices, ascending, each once
  std::vector<double> velocities;  ///< vertices.size() × dim, row-major [m/s]
};

/// The constraints of all solids with the fluid. Every call is collective on the fluid mesh's
/// communicator. The mesh and the constraints must outlive the group.
class ConstraintGroup {
 public:
  /// `threshold`: the covered-node rule's fraction (TransferOptions::coverage_threshold);
  /// `fixed`: per owned fluid vertex, nonzero where the fluid has a velocity condition of its
  /// own (never constrained; empty: none).
  ConstraintGroup(const mesh::Mesh& fluid, std::vector<ImmersedConstraint*> constraints,
                  double threshold, std::vector<char> fixed = {});

  /// Applies the rule above to the constraints' current operators and sets each solid's
  /// constrained vertices with their summed D_i (ImmersedConstraint::assign). With one solid
  /// it does nothing: that constraint's own rule is the rule. Call it after the solids moved
  /// and before their sets are used; it is idempotent.
  void combine();

  /// The fluid's constrained vertices and velocities from each solid's transfer_velocity()
  /// (shares[k]: solid k's, in the order of its constrained_vertices()).
  MergedConstraint merge(const std::vector<std::vector<double>>& shares);
  /// From the reactions at the merged vertices of the last merge(): those at solid k's
  /// constrained vertices, in their order (each shared node's whole reaction r_i).
  std::vector<double> reactions_of(std::size_t k, const std::vector<double>& reactions) const;
  /// Per owned fluid cell: the fraction of it the solids cover, Σ_k |T ∩ M_k| / |T| (above 1
  /// where solids overlap; transfer::VariationalTransfer::cell_coverage).
  std::vector<double> cell_coverage() const;

 private:
  const mesh::Mesh& fluid_;
  std::vector<ImmersedConstraint*> constraints_;
  double threshold_;
  std::vector<char> fixed_;
  std::vector<std::vector<std::size_t>> slots_;  ///< per solid: its vertices' merged index
};

}  // namespace coapt::coupling
