#pragma once
/// @file surface.hpp
/// Contact surfaces: the boundary facets of some facet groups of a (distributed) mesh,
/// gathered whole on every rank with the global numbers of their vertices, their averaged
/// nodal normals and their boundary nodes.
///
/// Contact surfaces are small next to the volume mesh (a 2D curve or a 3D surface), so the
/// first, simple and exact parallel strategy is used: every rank holds every contact surface
/// and computes the mortar integrals of all of them; each rank then assembles only the rows
/// it owns. Nodes and facets are ordered by the source numbering of the vertices
/// (Mesh::original_vertex), so the surface, and every sum over it, is the same on any number
/// of ranks.

#include <mpi.h>
#include <petscsys.h>
#include <petscvec.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "coapt/core/petsc.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::contact {

/// A contact surface (segments in 2D, triangles in 3D), the same on every rank.
struct Surface {
  int dim = 0;                          ///< space dimension: 2 (segments) or 3 (triangles)
  std::string name;                     ///< for messages (the group names)
  std::vector<PetscInt> global_vertex;  ///< global (PETSc layout) vertex number of each node
  std::vector<std::int64_t> key;        ///< source vertex number of each node (sort key)
  std::vector<double> reference;        ///< n_nodes × dim reference coordinates [m]
  std::vector<int> facets;              ///< n_facets × dim node indices, outward oriented

  int n_nodes() const { return static_cast<int>(global_vertex.size()); }
  int n_facets() const { return dim == 0 ? 0 : static_cast<int>(facets.size()) / dim; }
  /// Node indices of facet f (dim entries).
  std::span<const int> facet(int f) const {
    return {facets.data() + static_cast<std::size_t>(f) * dim, static_cast<std::size_t>(dim)};
  }
};

/// The surface of the boundary facets of `mesh` tagged with one of `tags`, gathered on every
/// rank (each facet taken from the rank owning the cell it bounds). Collective on mesh.comm.
Surface gather_surface(const mesh::Mesh& mesh, std::span<const int> tags, std::string name);

/// A surface from explicit arrays (serial use and tests): `coordinates` n × dim, `facets`
/// n_facets × dim node indices (outward oriented); global numbers and keys are 0..n−1.
Surface make_surface(int dim, std::vector<double> coordinates, std::vector<int> facets);

/// Nodes on the boundary of the surface: in 2D the nodes of exactly one segment, in 3D the
/// nodes of an edge that belongs to exactly one triangle. One flag per node.
std::vector<char> boundary_nodes(const Surface& surface);

/// Outward facet normal scaled by the facet's measure (2D: the segment rotated clockwise,
/// 3D: half the cross product) at coordinates `x` (n_nodes × dim).
std::array<double, 3> facet_area_normal(const Surface& surface, std::span<const double> x, int f);

/// ∫ N_j over the surface at coordinates `x` (n_nodes × dim) for each node j: the sum of
/// |F| / dim over its facets F [m^(dim−1)], one per node.
std::vector<double> nodal_measures(const Surface& surface, std::span<const double> x);

/// Averaged nodal normals at coordinates `x` (n_nodes × dim): the normalised sum of the
/// measure-weighted normals of the node's facets (n_nodes × dim). A node whose facet normals
/// nearly cancel (|Σ a_f n_f| < min_alignment Σ a_f: a thin edge or a fold, where no normal
/// is meaningful) gets a zero normal and valid[node] = 0.
std::vector<double> nodal_normals(const Surface& surface, std::span<const double> x,
                                  std::vector<char>* valid = nullptr, double min_alignment = 0.5);

/// Gathers the values of a ghosted vertex vector (dim components per vertex, from
/// fem::create_vertex_vector) at the nodes of a surface, on every rank.
class SurfaceGather {
 public:
  /// Prepares the scatter for vectors with the layout of `layout`. Collective.
  SurfaceGather(const Surface& surface, Vec layout);
  /// values[node·dim + i] = vector[global_vertex[node]·dim + i] on every rank. Collective.
  void gather(Vec vector, std::vector<double>& values) const;

 private:
  int dim_ = 0;
  OwnedVec local_;
  OwnedVecScatter scatter_;
};

}  // namespace coapt::contact
