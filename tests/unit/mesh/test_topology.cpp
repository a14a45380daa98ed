#include <gtest/gtest.h>

#include <algorithm>

#include "coapt/mesh/generators.hpp"
#include "coapt/mesh/topology.hpp"
#include "test_helpers.hpp"

namespace coapt::mesh {
namespace {

// Replaces the mesh's tagged facets with its extracted boundary.
Mesh with_extracted_boundary(Mesh mesh) {
  mesh.facets = boundary_facets(mesh, &mesh.facet_cell);
  mesh.facet_tags.assign(mesh.facet_cell.size(), 0);
  return mesh;
}

double facet_total(const Mesh& mesh) {
  double sum = 0;
  for (int f = 0; f < mesh.n_facets(); ++f) sum += testing::facet_measure(mesh, f);
  return sum;
}

TEST(LocalFacets, AreOutwardForTheReferenceSimplex) {
  for (const int dim : {2, 3}) {
    Mesh mesh = dim == 2 ? structured_rectangle(0, 0, 1, 1, 1, 1)
                         : structured_box(0, 0, 0, 1, 1, 1, 1, 1, 1);
    mesh.facets.clear();
    mesh.facet_cell.clear();
    for (int f = 0; f <= dim; ++f) {
      for (int k = 0; k < dim; ++k) {
        const int local = local_facet_vertex(dim, f, k);
        EXPECT_NE(local, f);  // facet f is opposite vertex f
        mesh.facets.push_back(mesh.cell(0)[local]);
      }
      mesh.facet_cell.push_back(0);
    }
    for (int f = 0; f <= dim; ++f) EXPECT_TRUE(testing::facet_outward(mesh, f)) << dim << " " << f;
  }
}

TEST(BoundaryFacets, OfARectangleAreItsPerimeter) {
  const Mesh mesh =
      with_extracted_boundary(structured_rectangle(0, 0, 3, 2, 3, 4, Diagonal::crossed));
  EXPECT_EQ(mesh.n_facets(), 2 * (3 + 4));
  testing::expect_valid_serial_mesh(mesh);
  EXPECT_NEAR(facet_total(mesh), 10.0, 1e-12);
  EXPECT_TRUE(std::is_sorted(mesh.facet_cell.begin(), mesh.facet_cell.end()));
}

TEST(BoundaryFacets, OfABoxAreItsSurface) {
  const Mesh mesh = with_extracted_boundary(structured_box(0, 0, 0, 1, 2, 3, 3, 2, 4));
  EXPECT_EQ(mesh.n_facets(), 4 * (3 * 2 + 2 * 4 + 3 * 4));
  testing::expect_valid_serial_mesh(mesh);
  EXPECT_NEAR(facet_total(mesh), 2 * (2 + 6 + 3), 1e-12);
}

TEST(BoundaryFacets, AreOutwardEvenForNegativeCells) {
  Mesh mesh = structured_rectangle(0, 0, 1, 1, 2, 2);
  for (int c = 0; c < mesh.n_cells(); ++c) std::swap(mesh.cells[3 * c], mesh.cells[3 * c + 1]);
  mesh.facets = boundary_facets(mesh, &mesh.facet_cell);
  ASSERT_EQ(mesh.n_facets(), 8);
  for (int f = 0; f < mesh.n_facets(); ++f) EXPECT_TRUE(testing::facet_outward(mesh, f));
}

TEST(FindFacetCells, FindsBoundaryAndInteriorFacets) {
  // Square split along the diagonal 0-3: cells (0, 1, 3) and (0, 3, 2).
  const Mesh mesh = structured_rectangle(0, 0, 1, 1, 1, 1);
  const std::vector<int> facets = {1,  0,   // bottom edge, reversed: cell 0
                                   2,  3,   // top edge: cell 1
                                   3,  0,   // the diagonal, interior: the lower cell, 0
                                   1,  2,   // the other diagonal: no cell
                                   -1, 2};  // invalid: no cell
  EXPECT_EQ(find_facet_cells(mesh, facets), (std::vector<int>{0, 1, 0, -1, -1}));

  const Mesh box = structured_box(0, 0, 0, 1, 1, 1, 2, 2, 2);
  const auto found = find_facet_cells(box, box.facets);
  EXPECT_EQ(found, box.facet_cell);
}

}  // namespace
}  // namespace coapt::mesh
