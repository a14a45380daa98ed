#pragma once
/// @file valve_surface.hpp
/// Where a closed valve's upstream surfaces stop bounding the upstream side: the part of
/// benchmark.upstream_surfaces whose sweep counts as flow on the flow boundary's side.
///
/// The valve benchmark's leak is the flow out through the flow boundary less the rate S at
/// which the leaflets' upstream surfaces sweep that side. Once the leaflets touch, only the
/// part of those surfaces between the solid's clamped base and the contact zone bounds that
/// side: beyond the contact zone (the wedge the coaptation faces open downstream of where they
/// touch, a face's overhang) the fluid they bound is the other side's, and counting its sweep
/// in S puts that volume on the wrong side of both leak measures. So S counts the facets
/// reached from the clamped nodes along the surface without crossing the contact zone:
///  - the contact zone: every contact pair's active slave nodes, and the master nodes that the
///    active nodes' multipliers cover over at least half their support,
///      Σ_{j ∈ A} M_jl ≥ ½ ∫_Γm N_l   (M_jl = ∫_Γc Φ̃_j N^m_l, mortar.hpp),
///    the master's counterpart of the slave's active set (Σ_j Φ̃_j = 1 on the contact zone,
///    so the sum is the part of N_l's support facing active slave nodes);
///  - reached nodes R: the unblocked nodes joined to an unblocked clamped node by a chain of
///    facets through unblocked nodes; a facet counts when one of its nodes is in R and lies in
///    the fluid mesh (in the reference configuration): a leaflet clamped in a wall of the fluid
///    mesh has a part of its surface outside the fluid, which sweeps no fluid.
/// A chain of blocked nodes joined by facet edges cuts the surface (in 2D one node does), so
/// the counted part ends at the contact zone's upstream edge, to a facet. Without contact
/// every facet counts (every part of the surface must be joined to a clamped node: checked at
/// construction).

#include <petscsys.h>

#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "coapt/contact/contact_constraints.hpp"
#include "coapt/contact/surface.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::coupling {

/// Per point (n × dim coordinates [m], the same on every rank): 1 when it lies in a cell of
/// `mesh` on some rank, on its boundary included (to 1e-9 in barycentric coordinates).
/// Collective on mesh.comm.
std::vector<char> points_in_mesh(const mesh::Mesh& mesh, std::span<const double> points);

/// Nodes of `surface` reached from the nodes with seed[node] != 0 along its facets without
/// passing a node with blocked[node] != 0 (a blocked seed starts nothing): 1 per reached node.
/// Serial.
std::vector<char> reached_nodes(const contact::Surface& surface, std::span<const char> seed,
                                std::span<const char> blocked);

/// The global vertex numbers of the contact zone of `pairs` (file comment): the active slave
/// nodes, and the master nodes covered by the active nodes' multipliers over at least half
/// their support. Sorted, distinct. Serial (the pair states are the same on every rank).
std::vector<PetscInt> contact_zone_vertices(const std::vector<contact::PairState>& pairs);

/// The upstream surfaces of a valve's solid and the clamped nodes their count starts from.
class UpstreamSurface {
 public:
  /// The boundary facets of `mesh` with one of the facet tags `tags` (the boundary groups
  /// named in `groups`, for messages), gathered on every rank; the clamped nodes are those
  /// with a prescribed displacement component among `dirichlet_dofs` (this rank's owned global
  /// dofs, interleaved: vertex · dim + component); the nodes outside `fluid_mesh`
  /// (points_in_mesh, reference coordinates) count no facet. InputError naming `key`, the
  /// groups and `solid` when a part of the surface is not joined to a clamped node. Collective.
  UpstreamSurface(const mesh::Mesh& mesh, std::span<const int> tags, const std::string& groups,
                  std::span<const PetscInt> dirichlet_dofs, const mesh::Mesh& fluid_mesh,
                  const std::string& key, const std::string& solid);

  /// Per local vertex of the mesh (owned and ghost) its level for
  /// SolidModel::surface_swept_volumes, for the contact zone of `pairs`: kCounted on the nodes
  /// in R (every surface node without contact) that lie in the fluid mesh, kOutsideFluid on
  /// the other nodes in R, kPastContact elsewhere. A facet of the upstream surfaces takes the
  /// largest level of its vertices, so it counts when one of its nodes is in R and in the
  /// fluid. Not collective.
  std::vector<char> vertex_levels(const std::vector<contact::PairState>& pairs) const;
  /// The levels of vertex_levels (kLevels of them).
  enum Level : char { kPastContact = 0, kOutsideFluid = 1, kCounted = 2, kLevels = 3 };

 private:
  const mesh::Mesh& mesh_;
  contact::Surface surface_;
  std::vector<char> clamped_;                         ///< per surface node
  std::vector<char> in_fluid_;                        ///< per surface node
  std::unordered_map<PetscInt, int> node_of_vertex_;  ///< global vertex → surface node
};

}  // namespace coapt::coupling
