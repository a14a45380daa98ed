#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <string>

#include "coapt/core/error.hpp"
#include "coapt/mesh/generators.hpp"
#include "coapt/mesh/quality.hpp"
#include "test_helpers.hpp"

namespace coapt::mesh {
namespace {

// A serial mesh from coordinates and cells (original cell numbers 101, 102, ...).
Mesh make_mesh(int dim, std::vector<double> coordinates, std::vector<int> cells) {
  Mesh mesh;
  mesh.dim = dim;
  mesh.source = "hand-made mesh";
  mesh.coordinates = std::move(coordinates);
  mesh.cells = std::move(cells);
  const int nv = static_cast<int>(mesh.coordinates.size()) / dim;
  mesh.global_vertex.resize(nv);
  std::iota(mesh.global_vertex.begin(), mesh.global_vertex.end(), PetscInt{0});
  mesh.n_owned_vertices = nv;
  mesh.n_global_vertices = nv;
  mesh.original_vertex.resize(nv);
  std::iota(mesh.original_vertex.begin(), mesh.original_vertex.end(), std::int64_t{1});
  mesh.original_cell.resize(mesh.n_cells());
  std::iota(mesh.original_cell.begin(), mesh.original_cell.end(), std::int64_t{101});
  mesh.cell_tags.assign(mesh.n_cells(), 0);
  mesh.n_owned_cells = mesh.n_cells();
  mesh.n_global_cells = mesh.n_cells();
  return mesh;
}

double quality_of(int dim, const std::vector<std::vector<double>>& p) {
  const double* points[4] = {};
  for (int k = 0; k <= dim; ++k) points[k] = p[k].data();
  return shape_quality(dim, points);
}

TEST(ShapeQuality, IsOneForRegularSimplices) {
  const double s = std::sqrt(3.0) / 2;
  EXPECT_NEAR(quality_of(2, {{0, 0}, {1, 0}, {0.5, s}}), 1.0, 1e-14);
  EXPECT_NEAR(quality_of(2, {{0, 0}, {0.5, s}, {1, 0}}), 1.0, 1e-14);  // orientation-free
  // Regular tetrahedron: alternate corners of a cube, scaled and moved.
  EXPECT_NEAR(quality_of(3, {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}), 1.0, 1e-14);
  EXPECT_NEAR(quality_of(3, {{3, 3, 3}, {3, 1, 1}, {1, 3, 1}, {1, 1, 3}}), 1.0, 1e-14);
}

TEST(ShapeQuality, IsSmallForBadSimplices) {
  // Sliver: the four corners of a square, slightly lifted alternately. Its edges are all
  // about the same length, but it is nearly flat.
  const double e = 0.001;
  const double sliver = quality_of(3, {{0, 0, 0}, {1, 0, e}, {1, 1, 0}, {0, 1, e}});
  EXPECT_GT(sliver, 0);
  EXPECT_LT(sliver, 0.05);
  // Needle and flat triangle.
  EXPECT_LT(quality_of(2, {{0, 0}, {1, 0}, {0.5, 0.01}}), 0.05);
  EXPECT_EQ(quality_of(2, {{0, 0}, {1, 0}, {2, 0}}), 0.0);
  // The right-angled corner tetrahedron is fine but not regular.
  const double corner = quality_of(3, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  EXPECT_GT(corner, 0.8);
  EXPECT_LT(corner, 0.9);
}

TEST(CheckQuality, SummarisesAValidMesh) {
  const Mesh mesh = structured_rectangle(0, 0, 2, 1, 4, 2);
  const auto report = check_quality(mesh);
  EXPECT_TRUE(report.valid());
  EXPECT_EQ(report.n_cells, 16);
  EXPECT_EQ(report.dim, 2);
  EXPECT_NEAR(report.total_measure, 2.0, 1e-14);
  EXPECT_NEAR(report.min_measure, 0.125, 1e-15);
  EXPECT_NEAR(report.max_measure, 0.125, 1e-15);
  // Right isosceles triangles: q = 4 sqrt(3) (1/2) / (1 + 1 + 2).
  EXPECT_NEAR(report.min_shape, std::sqrt(3.0) / 2, 1e-14);
  EXPECT_NEAR(report.max_shape, std::sqrt(3.0) / 2, 1e-14);
  EXPECT_NO_THROW(require_valid(mesh, report));
}

TEST(CheckQuality, ListsInvertedAndDegenerateCells) {
  // Four triangles: two fine, one flipped (102), one flat (104).
  Mesh mesh =
      make_mesh(2, {0, 0, 1, 0, 1, 1, 0, 1, 2, 0, 3, 0}, {0, 1, 2, 0, 3, 2, 0, 2, 3, 1, 4, 5});
  EXPECT_FALSE(orient_cells(mesh));
  const auto report = check_quality(mesh);
  ASSERT_EQ(report.inverted.size(), 1u);
  EXPECT_EQ(report.inverted[0].original, 102);
  EXPECT_NEAR(report.inverted[0].centroid[0], 1.0 / 3, 1e-15);
  EXPECT_NEAR(report.inverted[0].centroid[1], 2.0 / 3, 1e-15);
  EXPECT_EQ(report.inverted[0].centroid[2], 0.0);
  ASSERT_EQ(report.degenerate.size(), 1u);
  EXPECT_EQ(report.degenerate[0].original, 104);
  EXPECT_EQ(report.min_shape, 0.0);
  try {
    require_valid(mesh, report);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("hand-made mesh: inverted element 102 at (0.333333, 0.666667, 0)", 0),
              0u)
        << message;
    EXPECT_NE(message.find("degenerate element 104 at (2, 0, 0)"), std::string::npos) << message;
  }
}

TEST(CheckQuality, ListsTheFirstFewOfManyBadCells) {
  // 2 x 10 squares; flip 7 of the 40 triangles.
  Mesh mesh = structured_rectangle(0, 0, 10, 1, 10, 2);
  for (int c = 0; c < 14; c += 2) std::swap(mesh.cells[3 * c + 1], mesh.cells[3 * c + 2]);
  EXPECT_FALSE(orient_cells(mesh));
  const auto report = check_quality(mesh);
  EXPECT_EQ(report.inverted.size(), 7u);
  try {
    require_valid(mesh, report);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("element 9 at"), std::string::npos) << message;
    EXPECT_EQ(message.find("element 11 at"), std::string::npos) << message;  // 6th not listed
    EXPECT_NE(message.find("(7 inverted elements in total)"), std::string::npos) << message;
  }
}

TEST(OrientCells, ReordersAConsistentlyFlippedMesh) {
  Mesh mesh = structured_rectangle(0, 0, 1, 1, 3, 3, Diagonal::crossed);
  for (int c = 0; c < mesh.n_cells(); ++c) std::swap(mesh.cells[3 * c], mesh.cells[3 * c + 1]);
  for (int c = 0; c < mesh.n_cells(); ++c) ASSERT_LT(cell_signed_measure(mesh, c), 0);
  EXPECT_TRUE(orient_cells(mesh));
  testing::expect_valid_serial_mesh(mesh);  // facets are still outward
  EXPECT_TRUE(check_quality(mesh).valid());
  EXPECT_FALSE(orient_cells(mesh));  // idempotent

  Mesh box = structured_box(0, 0, 0, 1, 1, 1, 2, 2, 2);
  for (int c = 0; c < box.n_cells(); ++c) std::swap(box.cells[4 * c], box.cells[4 * c + 3]);
  EXPECT_TRUE(orient_cells(box));
  testing::expect_valid_serial_mesh(box);
}

}  // namespace
}  // namespace coapt::mesh
