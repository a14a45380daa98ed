#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include "coapt/core/error.hpp"
#include "coapt/mesh/generators.hpp"
#include "coapt/mesh/quality.hpp"
#include "coapt/mesh/topology.hpp"
#include "test_helpers.hpp"

namespace coapt::mesh {
namespace {

using testing::count_facets;
using testing::expect_valid_serial_mesh;
using testing::group_facet_measure;
using testing::total_measure;

void expect_groups(const Mesh& mesh, const std::vector<std::string>& sides) {
  const auto& domain = mesh.group("domain");
  EXPECT_EQ(domain.dim, mesh.dim);
  EXPECT_EQ(domain.tag, 1);
  for (int c = 0; c < mesh.n_cells(); ++c) ASSERT_EQ(mesh.cell_tags[c], 1);
  for (std::size_t s = 0; s < sides.size(); ++s) {
    const auto& group = mesh.group(sides[s]);
    EXPECT_EQ(group.dim, mesh.dim - 1) << sides[s];
    EXPECT_EQ(group.tag, static_cast<int>(s) + 1) << sides[s];
  }
  EXPECT_EQ(mesh.groups.size(), sides.size() + 1);
}

void expect_rectangle_sides(const Mesh& mesh, double x0, double y0, double x1, double y1) {
  expect_groups(mesh, {"left", "right", "bottom", "top"});
  EXPECT_NEAR(group_facet_measure(mesh, "left"), y1 - y0, 1e-12);
  EXPECT_NEAR(group_facet_measure(mesh, "right"), y1 - y0, 1e-12);
  EXPECT_NEAR(group_facet_measure(mesh, "bottom"), x1 - x0, 1e-12);
  EXPECT_NEAR(group_facet_measure(mesh, "top"), x1 - x0, 1e-12);
  // Each facet lies on its side.
  const double side_value[4] = {x0, x1, y0, y1};
  for (int f = 0; f < mesh.n_facets(); ++f) {
    const int tag = mesh.facet_tags[f];
    for (int k = 0; k < 2; ++k)
      ASSERT_NEAR(mesh.point(mesh.facets[2 * f + k])[(tag - 1) / 2], side_value[tag - 1], 1e-12);
  }
  // The tagged facets are exactly the boundary: the mesh is conforming.
  EXPECT_EQ(static_cast<int>(boundary_facets(mesh).size()) / 2, mesh.n_facets());
}

void expect_box_sides(const Mesh& mesh, const double* lo, const double* hi) {
  expect_groups(mesh, {"left", "right", "front", "back", "bottom", "top"});
  const double lx = hi[0] - lo[0], ly = hi[1] - lo[1], lz = hi[2] - lo[2];
  const double tol = 1e-12 * (lx * ly + ly * lz + lx * lz);
  EXPECT_NEAR(group_facet_measure(mesh, "left"), ly * lz, tol);
  EXPECT_NEAR(group_facet_measure(mesh, "right"), ly * lz, tol);
  EXPECT_NEAR(group_facet_measure(mesh, "front"), lx * lz, tol);
  EXPECT_NEAR(group_facet_measure(mesh, "back"), lx * lz, tol);
  EXPECT_NEAR(group_facet_measure(mesh, "bottom"), lx * ly, tol);
  EXPECT_NEAR(group_facet_measure(mesh, "top"), lx * ly, tol);
  for (int f = 0; f < mesh.n_facets(); ++f) {
    const int side = mesh.facet_tags[f] - 1;
    const double value = side % 2 == 0 ? lo[side / 2] : hi[side / 2];
    for (int k = 0; k < 3; ++k)
      ASSERT_NEAR(mesh.point(mesh.facets[3 * f + k])[side / 2], value, 1e-12);
  }
  EXPECT_EQ(static_cast<int>(boundary_facets(mesh).size()) / 3, mesh.n_facets());
}

TEST(StructuredRectangle, EveryPatternHasTheRightCountsMeasuresAndGroups) {
  const double x0 = -1, y0 = 0.5, x1 = 2, y1 = 1.5;
  const int nx = 3, ny = 5;
  for (const Diagonal diagonal :
       {Diagonal::right, Diagonal::left, Diagonal::alternating, Diagonal::crossed}) {
    SCOPED_TRACE(to_string(diagonal));
    const Mesh mesh = structured_rectangle(x0, y0, x1, y1, nx, ny, diagonal);
    const bool crossed = diagonal == Diagonal::crossed;
    EXPECT_EQ(mesh.dim, 2);
    EXPECT_EQ(mesh.n_vertices(), (nx + 1) * (ny + 1) + (crossed ? nx * ny : 0));
    EXPECT_EQ(mesh.n_cells(), nx * ny * (crossed ? 4 : 2));
    EXPECT_EQ(mesh.n_facets(), 2 * (nx + ny));
    EXPECT_EQ(count_facets(mesh, "left"), ny);
    EXPECT_EQ(count_facets(mesh, "bottom"), nx);
    expect_valid_serial_mesh(mesh);
    EXPECT_NEAR(total_measure(mesh), (x1 - x0) * (y1 - y0), 1e-12);
    expect_rectangle_sides(mesh, x0, y0, x1, y1);
    EXPECT_EQ(mesh.original_vertex.front(), 1);
    EXPECT_EQ(mesh.original_cell.back(), mesh.n_cells());
    EXPECT_TRUE(check_quality(mesh).valid());
  }
}

TEST(StructuredRectangle, PatternsAreAsDocumented) {
  // One unit square: vertices v00 = 0, v10 = 1, v01 = 2, v11 = 3.
  EXPECT_EQ(structured_rectangle(0, 0, 1, 1, 1, 1, Diagonal::right).cells,
            (std::vector<int>{0, 1, 3, 0, 3, 2}));
  EXPECT_EQ(structured_rectangle(0, 0, 1, 1, 1, 1, Diagonal::left).cells,
            (std::vector<int>{0, 1, 2, 1, 3, 2}));
  const Mesh crossed = structured_rectangle(0, 0, 1, 1, 1, 1, Diagonal::crossed);
  EXPECT_EQ(crossed.point(4)[0], 0.5);
  EXPECT_EQ(crossed.point(4)[1], 0.5);
  // Alternating: square (1, 0) is cut the other way from square (0, 0).
  const Mesh alternating = structured_rectangle(0, 0, 2, 1, 2, 1, Diagonal::alternating);
  EXPECT_EQ(std::vector<int>(alternating.cells.begin() + 6, alternating.cells.end()),
            (std::vector<int>{1, 2, 4, 2, 5, 4}));
  EXPECT_EQ(parse_diagonal("crossed"), Diagonal::crossed);
  EXPECT_THROW(parse_diagonal("diagonal"), InputError);
}

TEST(StructuredRectangle, RejectsBadArguments) {
  EXPECT_THROW(structured_rectangle(0, 0, 1, 1, 0, 3), InputError);
  EXPECT_THROW(structured_rectangle(1, 0, 1, 1, 2, 3), InputError);
  EXPECT_THROW(structured_rectangle(0, 0, 1, NAN, 2, 3), InputError);
  EXPECT_THROW(structured_rectangle(0, 0, 1, 1, 100000, 100000), InputError);
}

TEST(StructuredBox, CountsMeasuresGroupsAndConformity) {
  const double lo[3] = {0, -1, 0.5}, hi[3] = {1, 2, 1.5};
  const int nx = 2, ny = 3, nz = 4;
  const Mesh mesh = structured_box(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], nx, ny, nz);
  EXPECT_EQ(mesh.dim, 3);
  EXPECT_EQ(mesh.n_vertices(), (nx + 1) * (ny + 1) * (nz + 1));
  EXPECT_EQ(mesh.n_cells(), 6 * nx * ny * nz);
  EXPECT_EQ(mesh.n_facets(), 4 * (nx * ny + ny * nz + nx * nz));
  EXPECT_EQ(count_facets(mesh, "left"), 2 * ny * nz);
  EXPECT_EQ(count_facets(mesh, "front"), 2 * nx * nz);
  EXPECT_EQ(count_facets(mesh, "top"), 2 * nx * ny);
  expect_valid_serial_mesh(mesh);
  EXPECT_NEAR(total_measure(mesh), 3.0, 1e-12);
  expect_box_sides(mesh, lo, hi);
  const auto report = check_quality(mesh);
  EXPECT_TRUE(report.valid());
  EXPECT_NEAR(report.min_measure, report.max_measure, 1e-14);  // Kuhn tets: all equal volume
}

TEST(StructuredBox, RejectsBadArguments) {
  EXPECT_THROW(structured_box(0, 0, 0, 1, 1, 1, 1, -1, 1), InputError);
  EXPECT_THROW(structured_box(0, 0, 1, 1, 1, 0, 1, 1, 1), InputError);
  EXPECT_THROW(structured_box(0, 0, 0, 1, 1, 1, 1000, 1000, 1000), InputError);
}

TEST(StructuredBox, Box64IsFast) {
  const auto start = std::chrono::steady_clock::now();
  const Mesh mesh = structured_box(0, 0, 0, 1, 1, 1, 64, 64, 64);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(mesh.n_cells(), 6 * 64 * 64 * 64);
  EXPECT_EQ(mesh.n_vertices(), 65 * 65 * 65);
  EXPECT_EQ(mesh.n_facets(), 12 * 64 * 64);
  EXPECT_NEAR(total_measure(mesh), 1.0, 1e-9);
  EXPECT_LT(seconds, 3.0);  // typically ~0.05 s in a release build
  RecordProperty("seconds", std::to_string(seconds));
}

TEST(UnstructuredRectangle, CoversTheRectangleWithTheBoundaryGroups) {
  const double x0 = 0, y0 = -0.5, x1 = 2, y1 = 0.5, h = 0.2;
  const Mesh mesh = unstructured_rectangle(x0, y0, x1, y1, h);
  EXPECT_EQ(mesh.dim, 2);
  EXPECT_GT(mesh.n_cells(), 50);  // about 2 / (0.433 * 0.04) = 115
  EXPECT_LT(mesh.n_cells(), 400);
  expect_valid_serial_mesh(mesh);
  EXPECT_NEAR(total_measure(mesh), 2.0, 1e-12);
  expect_rectangle_sides(mesh, x0, y0, x1, y1);
  EXPECT_EQ(mesh.original_cell.front(), 1);
  EXPECT_EQ(mesh.original_vertex.back(), mesh.n_vertices());
  // Deterministic.
  const Mesh again = unstructured_rectangle(x0, y0, x1, y1, h);
  EXPECT_EQ(again.cells, mesh.cells);
  EXPECT_EQ(again.coordinates, mesh.coordinates);
  EXPECT_EQ(again.facets, mesh.facets);
}

TEST(UnstructuredBox, CoversTheBoxWithTheBoundaryGroups) {
  const double lo[3] = {0, 0, -1}, hi[3] = {1, 1.5, 0};
  const Mesh mesh = unstructured_box(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], 0.3);
  EXPECT_EQ(mesh.dim, 3);
  EXPECT_GT(mesh.n_cells(), 100);
  expect_valid_serial_mesh(mesh);
  EXPECT_NEAR(total_measure(mesh), 1.5, 1e-12);
  expect_box_sides(mesh, lo, hi);
  EXPECT_TRUE(check_quality(mesh).valid());
  const Mesh again = unstructured_box(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], 0.3);
  EXPECT_EQ(again.cells, mesh.cells);
}

TEST(Unstructured, RejectsBadSizes) {
  EXPECT_THROW(unstructured_rectangle(0, 0, 1, 1, 0), InputError);
  EXPECT_THROW(unstructured_rectangle(0, 0, 1, 1, -1), InputError);
  EXPECT_THROW(unstructured_box(0, 0, 0, 1, 1, 1, 1e-5), InputError);  // ~1e15 cells
  EXPECT_THROW(unstructured_box(0, 0, 0, 0, 1, 1, 0.1), InputError);
}

TEST(MeshGeoFile, MeshesA2DGeoFileWithItsGroups) {
  const std::string path = testing::data_file("l_shape.geo");
  const Mesh coarse = mesh_geo_file(path, 1.0);  // the file's own sizes (0.5) apply
  const Mesh fine = mesh_geo_file(path, 0.1);
  for (const Mesh* mesh : {&coarse, &fine}) {
    EXPECT_EQ(mesh->dim, 2);
    EXPECT_EQ(mesh->source, path);
    expect_valid_serial_mesh(*mesh);
    EXPECT_NEAR(total_measure(*mesh), 3.0, 1e-12);
    EXPECT_EQ(mesh->group("domain").tag, 1);
    EXPECT_NEAR(group_facet_measure(*mesh, "bottom"), 2.0, 1e-12);
    EXPECT_NEAR(group_facet_measure(*mesh, "rest"), 6.0, 1e-12);
    EXPECT_EQ(std::count(mesh->cell_tags.begin(), mesh->cell_tags.end(), 1), mesh->n_cells());
  }
  EXPECT_GT(fine.n_cells(), 4 * coarse.n_cells());
}

TEST(MeshGeoFile, MeshesA3DGeoFile) {
  const Mesh mesh = mesh_geo_file(testing::data_file("block.geo"), 0.4);
  EXPECT_EQ(mesh.dim, 3);
  expect_valid_serial_mesh(mesh);
  EXPECT_NEAR(total_measure(mesh), 2.0, 1e-12);
  EXPECT_EQ(mesh.group("block").tag, 7);
  EXPECT_NEAR(group_facet_measure(mesh, "sides"), 10.0, 1e-12);
}

TEST(MeshGeoFile, ErrorsNameTheFile) {
  testing::TempDir dir("geo");
  const std::string bad = dir.file("bad.geo");
  std::ofstream(bad) << "Point(1) = {0, 0, 0;\nthis is not gmsh\n";
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  for (const std::string& path : {bad, dir.file("missing.geo")}) {
    try {
      mesh_geo_file(path, 0.1);
      ADD_FAILURE() << "no exception for " << path;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  // Gmsh still works after the failure.
  EXPECT_EQ(mesh_geo_file(testing::data_file("l_shape.geo"), 1.0).dim, 2);
}

}  // namespace
}  // namespace coapt::mesh
