#pragma once
/// @file topology.hpp
/// Facets of a simplex mesh: local facet numbering, boundary extraction and facet → cell
/// lookup.
///
/// Facet orientation convention (used by every facet this module and the mesh generators
/// and reader produce): a facet is stored so that its normal points OUT of the cell it
/// bounds. In 2D a segment (a, b) has the cell on its left, i.e. the outward normal is
/// (b − a) rotated clockwise: (by − ay, −(bx − ax)); in 3D a triangle (a, b, c) has the
/// outward normal (b − a) × (c − a).

#include <span>
#include <vector>

#include "coapt/mesh/mesh.hpp"

namespace coapt::mesh {

/// Local vertex `k` (0 ≤ k < dim) of local facet `f` (0 ≤ f ≤ dim) of a simplex. Facet f is
/// the one opposite local vertex f, and its vertices are listed outward-oriented for a
/// positively oriented cell: 2D {1,2}, {2,0}, {0,1}; 3D {1,2,3}, {0,3,2}, {0,1,3}, {0,2,1}.
int local_facet_vertex(int dim, int f, int k);

/// Reorders the `dim` vertices of a facet of cell `cell` (local indices into `mesh`) so that
/// it is outward-oriented with respect to that cell (see the file comment), judging by the
/// coordinates (so it also holds for a negatively oriented cell). Leaves a degenerate facet
/// / cell as it is. The facet must be a face of the cell (not checked).
void orient_facet_outward(const Mesh& mesh, int cell, std::span<int> facet);

/// The boundary facets of the mesh's cells: the facets belonging to exactly one cell, as
/// n × dim local vertex indices, outward-oriented, in order of (cell, local facet). If
/// `facet_cell` is given it receives the cell each facet bounds. Facets shared by three or
/// more cells (non-manifold) are not boundary facets. O(n) time and memory (bucketed by the
/// smallest vertex); meant for the surface of untagged meshes.
std::vector<int> boundary_facets(const Mesh& mesh, std::vector<int>* facet_cell = nullptr);

/// For each facet in `facets` (n × dim local vertex indices of `mesh`, any vertex order), the
/// cell having it as a face, or −1 if no cell has it. A facet shared by two cells (an interior
/// facet, e.g. an interface) gets the lower-numbered cell. Entries equal to −1 (or ≥ the
/// number of vertices) in `facets` simply match nothing. O(n_cells log n_facets).
std::vector<int> find_facet_cells(const Mesh& mesh, std::span<const int> facets);

}  // namespace coapt::mesh
