#pragma once
/// @file mortar.hpp
/// Mortar integration for contact with dual Lagrange multipliers (Wohlmuth 2000; Popp, Gee,
/// Wall 2009; Puso and Laursen 2004 for the projection plane).
///
/// A slave surface Γs (segments in 2D, triangles in 3D) and a master surface Γm, both at
/// their current coordinates. N_k are the P1 functions of the slave facets, N^m_l those of
/// the master, Φ_j the slave dual functions, biorthogonal on each slave facet:
///   ∫_s Φ_j N_k = δ_jk ∫_s N_k,   Φ_a = Σ_b A_ab N_b,  A_ab = (n + 1) δ_ab − 1
/// (n = dim vertices of a facet: Φ = 3N − 1 on segments, 4N − 1 on triangles).
///
/// Boundary modification (Popp et al. 2012, the crosspoint/edge-node modification of
/// Wohlmuth): nodes on the boundary of the slave surface carry no multiplier; on each facet
/// their dual functions are shared out equally to the facet's multiplier nodes,
///   Φ̃_j = Φ_j + Σ_{b on ∂Γs} Φ_b / |I_facet|,
/// which keeps biorthogonality to the multiplier nodes' N_k and the partition of unity
/// Σ_j Φ̃_j = 1 (so constant pressures are represented). A boundary node's displacement then
/// enters the constraints through off-diagonal entries, like a master node. The same
/// treatment is given to nodes without a meaningful normal.
///
/// Integration: each slave facet s and each master facet m facing it (n_s · n_m < 0) within
/// the search distance are projected along n_s onto the plane (line) of s, where the
/// projection of m is clipped against s. The projection is affine, so N_k and N^m_l are
/// affine on the clipped polygon and the degree-2 rules used (2 Gauss points on a segment,
/// 3 points per triangle of the polygon's fan) integrate every product Φ_j N exactly.
///
/// Partly covered slave facets (Popp, Seitz, Gee, Wall 2013, the dual functions of slave
/// facets that project onto the master only in part): on a facet s whose overlap Γc ∩ s with
/// the projected master is not the whole facet, the dual functions are made biorthogonal on
/// the overlap instead of the whole facet,
///   Φ_a = Σ_b A⁰_ab N_b,  A⁰ = diag(d) M⁻¹,  M_ab = ∫_Γc∩s N_a N_b,  d_a = Σ_b M_ab = ∫_Γc∩s N_a,
/// then modified at the surface boundary as above. Σ_a Φ_a = 1 still holds (Mᵀ 1 = d), and
/// on a wholly covered facet A⁰ is the standard (n + 1) I − 1. Every slave node's D̂ row is
/// then diagonal on its multiplier nodes whatever the coverage, D_jj = ∫_Γc N_j, and a gap
/// affine on each facet is reproduced at the node: g̃_j / D_jj = g(x_j), the overlap's gap
/// extended to the node. With the standard functions on such a facet the part of Φ_j
/// (3N_j − 1 < 0 near the far vertex) that the master covers can give g̃_j either sign
/// whatever the gap, and D̂ is not diagonal: a node at a master's edge had no consistent
/// normal force. Facets covered by less than 1e-3 of their measure add nothing, not even to
/// the coverage ∫_Γc N_j (their covered mass matrix is too near singular).
///
/// The operators of the slave surface against one master surface:
///   D_jj  = ∫_Γc Φ̃_j N_j = ∫_Γc N_j (diagonal)                      dual_mass
///   D̂_jk = ∫_Γc Φ̃_j N_k   (overlap Γc = Γs ∩ projected Γm)       slave_coupling
///   M_jl  = ∫_Γc Φ̃_j N^m_l                                        master_coupling
///   g̃_j  = n_j · (Σ_l M_jl x^m_l − Σ_k D̂_jk x^s_k) = ∫_Γc Φ̃_j n_j·(x^m − x^s)   weighted gap
/// with n_j the averaged nodal normal (surface.hpp). On a multiplier node D̂_jk = δ_jk D_jj
/// for multiplier nodes k, and Σ_l M_jl = D_jj (the master's partition of unity): constants
/// are reproduced and the multiplier condenses out node by node. Only nodes whose covered
/// fraction ∫_Γc N_j / ∫_Γs N_j reaches coverage_threshold are constrained (contact.hpp).

#include <array>
#include <span>
#include <vector>

#include "coapt/contact/surface.hpp"

namespace coapt::contact {

/// A quadrature point of a slave–master facet pair: barycentric coordinates in both facets
/// (dim entries used) and the weight [m^(dim−1)] (measured on the slave facet).
struct MortarPoint {
  std::array<double, 3> slave{};
  std::array<double, 3> master{};
  double weight = 0.0;
};

/// Most points integrate_triangles writes (3 per triangle of a clipped polygon's fan).
inline constexpr int kMaxMortarPoints = 21;

/// Segment-to-segment integration (2D), `slave` and `master` as (x, y) pairs: the master
/// projected orthogonally onto the slave's line, 2 Gauss points on the overlap. Returns the
/// number of points (0 when the projections do not overlap).
int integrate_segments(const std::array<std::array<double, 2>, 2>& slave,
                       const std::array<std::array<double, 2>, 2>& master, MortarPoint* points);

/// Triangle-to-triangle integration (3D) in the plane of the slave triangle: the master
/// projected orthogonally onto it, clipped against the slave triangle, and a degree-2 rule
/// on the fan of the clipped polygon. Returns the number of points (≤ kMaxMortarPoints).
int integrate_triangles(const std::array<std::array<double, 3>, 3>& slave,
                        const std::array<std::array<double, 3>, 3>& master, MortarPoint* points);

/// A facet's mass matrix ∫ N_a N_b over a part of it (n_vertices × n_vertices used).
using FacetMass = std::array<std::array<double, 3>, 3>;

/// Dual basis coefficients of a slave facet with `n_vertices` (2 or 3) vertices:
/// Φ̃_a = Σ_b A[a][b] N_b. `multiplier[a]` says whether vertex a carries a multiplier;
/// the dual functions of the other vertices are shared out equally to those that do (all
/// zero when none does). With every vertex a multiplier node this is A = (n+1) I − 1, the
/// functions biorthogonal on the whole facet; with `covered_mass` (M over the covered part,
/// regular) they are biorthogonal on that part: A⁰ = diag(M 1) M⁻¹ (file comment).
std::array<std::array<double, 3>, 3> dual_coefficients(int n_vertices,
                                                       const std::array<bool, 3>& multiplier,
                                                       const FacetMass* covered_mass = nullptr);

/// Options of the mortar search and integration.
struct MortarOptions {
  /// Master facets whose vertices all lie farther than this from the slave facet's plane
  /// (on either side, along its normal) are ignored [m]. Must exceed the largest expected
  /// gap of a node that may come into contact within one Newton iteration, and stay below the
  /// thickness of the master body.
  double search_distance = 0.0;
  /// A slave node is constrained when ∫_Γc N_j ≥ this · ∫_Γs N_j (the default: its whole
  /// support is covered; lower values let contact follow a slave node past a master's edge).
  double coverage_threshold = 1.0 - 1e-8;
  /// Boundary nodes of the slave surface carry no multiplier (see the file comment).
  bool boundary_modification = true;
  /// Optional, n_slave × dim: components removed from a node's averaged normal before it is
  /// normalised again (prescribed displacement components, e.g. a symmetry plane: the
  /// normal of the mirrored surface is the one-sided average without its normal part).
  std::vector<char> fixed_components;
};

/// One entry of a sparse coupling (row: slave node, column: slave or master node).
struct MortarEntry {
  int row = 0;
  int column = 0;
  double value = 0.0;
};

/// The mortar operators of a slave surface against a master surface (file comment).
struct MortarOperators {
  std::vector<double> normals;              ///< n_slave × dim averaged nodal normals
  std::vector<char> multiplier;             ///< node carries a multiplier
  std::vector<double> dual_mass;            ///< D_jj = ∫_Γc N_j [m^(dim−1)] (0: no multiplier)
  std::vector<double> support;              ///< ∫_Γs N_j [m^(dim−1)]
  std::vector<double> covered;              ///< ∫_Γc N_j [m^(dim−1)]
  std::vector<double> weighted_gap;         ///< g̃_j [m^dim] (0 where no multiplier)
  std::vector<MortarEntry> slave_coupling;  ///< D̂_jk, sorted by (row, column), summed
  std::vector<MortarEntry> master_coupling;  ///< M_jl, sorted by (row, column), summed
  long facet_pairs = 0;  ///< slave–master facet pairs with a non-empty overlap
  double coverage_threshold = 1.0;

  /// Whether slave node j carries a multiplier and enough of its support is covered
  /// (constrained).
  bool constrained(int j) const {
    return multiplier[j] && support[j] > 0.0 && dual_mass[j] > 0.0 &&
           covered[j] >= coverage_threshold * support[j];
  }
  /// The gap g̃_j / D_jj of a multiplier node [m].
  double gap(int j) const { return dual_mass[j] > 0.0 ? weighted_gap[j] / dual_mass[j] : 0.0; }
};

/// Searches and integrates: `slave_x`, `master_x` are the current coordinates of the two
/// surfaces' nodes (n × dim). Serial (every rank computes the same operators).
MortarOperators assemble_mortar(const Surface& slave, std::span<const double> slave_x,
                                const Surface& master, std::span<const double> master_x,
                                const MortarOptions& options);

}  // namespace coapt::contact
