#include <gmsh.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/mesh/gmsh_reader.hpp"
#include "coapt/mesh/quality.hpp"
#include "test_helpers.hpp"

namespace coapt::mesh {
namespace {

using testing::data_file;
using testing::expect_valid_serial_mesh;
using testing::group_facet_measure;
using testing::TempDir;
using testing::total_measure;

struct Format {
  const char* name;
  double version;
  int binary;
};
constexpr Format kFormats[] = {
    {"v2_ascii", 2.2, 0}, {"v2_binary", 2.2, 1}, {"v41_ascii", 4.1, 0}, {"v41_binary", 4.1, 1}};

struct Expected {
  std::size_t cells = 0;
  std::size_t nodes = 0;
  std::vector<std::string> files;
};

// Writes the current Gmsh model in the four formats.
void write_all_formats(const TempDir& dir, const std::string& stem, Expected& expected) {
  for (const auto& format : kFormats) {
    const std::string path = dir.file(stem + "_" + format.name + ".msh");
    gmsh::option::setNumber("Mesh.MshFileVersion", format.version);
    gmsh::option::setNumber("Mesh.Binary", format.binary);
    gmsh::write(path);
    expected.files.push_back(path);
  }
}

void count_model(int cell_type, Expected& expected) {
  std::vector<std::size_t> tags, nodes;
  gmsh::model::mesh::getElementsByType(cell_type, tags, nodes);
  expected.cells = tags.size();
  std::vector<double> coordinates, parametric;
  gmsh::model::mesh::getNodes(nodes, coordinates, parametric, -1, -1, false, false);
  expected.nodes = nodes.size();
}

// Rectangle [0, 2] x [0, 1] (built-in kernel, known curve tags) with a named surface group,
// two named curve groups and an unnamed one.
Expected write_rectangle(const TempDir& dir) {
  Expected expected;
  GmshSession session("test rectangle");
  session.run([&] {
    namespace geo = gmsh::model::geo;
    const double lc = 0.25;
    geo::addPoint(0, 0, 0, lc, 1);
    geo::addPoint(2, 0, 0, lc, 2);
    geo::addPoint(2, 1, 0, lc, 3);
    geo::addPoint(0, 1, 0, lc, 4);
    geo::addLine(1, 2, 1);  // bottom
    geo::addLine(2, 3, 2);  // right
    geo::addLine(3, 4, 3);  // top
    geo::addLine(4, 1, 4);  // left
    geo::addCurveLoop({1, 2, 3, 4}, 1);
    geo::addPlaneSurface({1}, 1);
    geo::synchronize();
    gmsh::model::addPhysicalGroup(2, {1}, 5);
    gmsh::model::setPhysicalName(2, 5, "fluid");
    gmsh::model::addPhysicalGroup(1, {4}, 1);
    gmsh::model::setPhysicalName(1, 1, "inlet");
    gmsh::model::addPhysicalGroup(1, {1, 3}, 2);
    gmsh::model::setPhysicalName(1, 2, "walls");
    gmsh::model::addPhysicalGroup(1, {2}, 7);  // unnamed
    // Every curve is in a second group too (MSH 2 files repeat such elements).
    gmsh::model::addPhysicalGroup(1, {1, 2, 3, 4}, 9);
    gmsh::model::setPhysicalName(1, 9, "boundary");
    gmsh::model::mesh::generate(2);
    count_model(2, expected);
    write_all_formats(dir, "rectangle", expected);
  });
  return expected;
}

// Two unit cubes side by side ([0, 2] x [0, 1]^2, conforming through the fragment), one
// volume group each, a group on the interface between them and one on the face x = 0.
Expected write_two_cubes(const TempDir& dir) {
  Expected expected;
  GmshSession session("test cubes");
  session.run([&] {
    namespace occ = gmsh::model::occ;
    occ::addBox(0, 0, 0, 1, 1, 1, 1);
    occ::addBox(1, 0, 0, 1, 1, 1, 2);
    gmsh::vectorpair out;
    std::vector<gmsh::vectorpair> out_map;
    occ::fragment({{3, 1}}, {{3, 2}}, out, out_map);
    occ::synchronize();
    auto surface_at_x = [](double x) {
      gmsh::vectorpair found;
      gmsh::model::getEntitiesInBoundingBox(x - 1e-3, -1e-3, -1e-3, x + 1e-3, 1 + 1e-3, 1 + 1e-3,
                                            found, 2);
      EXPECT_EQ(found.size(), 1u);
      return found.at(0).second;
    };
    gmsh::model::addPhysicalGroup(3, {1}, 1);
    gmsh::model::setPhysicalName(3, 1, "a");
    gmsh::model::addPhysicalGroup(3, {2}, 2);
    gmsh::model::setPhysicalName(3, 2, "b");
    gmsh::model::addPhysicalGroup(2, {surface_at_x(1)}, 10);
    gmsh::model::setPhysicalName(2, 10, "interface");
    gmsh::model::addPhysicalGroup(2, {surface_at_x(0)}, 11);
    gmsh::model::setPhysicalName(2, 11, "left");
    gmsh::option::setNumber("Mesh.MeshSizeMax", 0.4);
    gmsh::model::mesh::generate(3);
    count_model(4, expected);
    write_all_formats(dir, "cubes", expected);
  });
  return expected;
}

std::vector<std::tuple<std::string, int, int>> group_list(const Mesh& mesh) {
  std::vector<std::tuple<std::string, int, int>> list;
  for (const auto& g : mesh.groups) list.emplace_back(g.name, g.dim, g.tag);
  return list;
}

// Reads `path` with Gmsh's terminal output captured; checks nothing was printed.
Mesh read_quietly(const std::string& path) {
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  Mesh mesh;
  try {
    mesh = read_gmsh(path);
  } catch (...) {
    ::testing::internal::GetCapturedStdout();
    ::testing::internal::GetCapturedStderr();
    throw;
  }
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  return mesh;
}

// Expects read_gmsh(path) to throw an InputError starting with "<path>: " and containing
// every one of `parts`, printing nothing.
void expect_input_error(const std::string& path, const std::vector<std::string>& parts = {}) {
  SCOPED_TRACE(path);
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  std::string message;
  try {
    read_gmsh(path);
  } catch (const InputError& e) {
    message = e.what();
  } catch (const std::exception& e) {
    message = std::string("wrong exception type: ") + e.what();
  } catch (...) {
    message = "non-standard exception";
  }
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ASSERT_FALSE(message.empty()) << "no exception";
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  for (const auto& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

void write_first_half(const std::string& from, const std::string& to) {
  std::ifstream in(from, std::ios::binary);
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(to, std::ios::binary) << content.substr(0, content.size() / 2);
}

TEST(GmshReader, RoundTrip2DInEveryFormat) {
  TempDir dir("round_trip_2d");
  const Expected expected = write_rectangle(dir);
  ASSERT_GT(expected.cells, 10u);
  std::vector<Mesh> meshes;
  for (const auto& path : expected.files) {
    SCOPED_TRACE(path);
    Mesh mesh = read_quietly(path);
    EXPECT_EQ(mesh.dim, 2);
    EXPECT_EQ(mesh.source, path);
    EXPECT_EQ(static_cast<std::size_t>(mesh.n_cells()), expected.cells);
    EXPECT_EQ(static_cast<std::size_t>(mesh.n_vertices()), expected.nodes);
    expect_valid_serial_mesh(mesh);
    EXPECT_NEAR(total_measure(mesh), 2.0, 1e-12);
    EXPECT_EQ(group_list(mesh),
              (std::vector<std::tuple<std::string, int, int>>{{"fluid", 2, 5},
                                                              {"inlet", 1, 1},
                                                              {"walls", 1, 2},
                                                              {"group_7", 1, 7},
                                                              {"boundary", 1, 9}}));
    for (const int tag : mesh.cell_tags) ASSERT_EQ(tag, 5);
    EXPECT_NEAR(group_facet_measure(mesh, "inlet"), 1.0, 1e-12);
    EXPECT_NEAR(group_facet_measure(mesh, "walls"), 4.0, 1e-12);
    EXPECT_NEAR(group_facet_measure(mesh, "group_7"), 1.0, 1e-12);
    EXPECT_NEAR(group_facet_measure(mesh, "boundary"), 6.0, 1e-12);
    // Vertices in increasing node tag, cells in increasing element tag.
    EXPECT_TRUE(std::is_sorted(mesh.original_vertex.begin(), mesh.original_vertex.end()));
    EXPECT_TRUE(std::is_sorted(mesh.original_cell.begin(), mesh.original_cell.end()));
    meshes.push_back(std::move(mesh));
  }
  for (std::size_t i = 1; i < meshes.size(); ++i) {
    EXPECT_EQ(meshes[i].cells, meshes[0].cells);
    // Element tags agree within a version (MSH 2 renumbers the repeated boundary elements).
    if (i % 2 == 1) {
      EXPECT_EQ(meshes[i].original_cell, meshes[i - 1].original_cell);
    }
    EXPECT_EQ(meshes[i].facets, meshes[0].facets);
    ASSERT_EQ(meshes[i].coordinates.size(), meshes[0].coordinates.size());
    for (std::size_t k = 0; k < meshes[0].coordinates.size(); ++k)
      ASSERT_NEAR(meshes[i].coordinates[k], meshes[0].coordinates[k], 1e-15);
  }
}

TEST(GmshReader, RoundTrip3DInEveryFormat) {
  TempDir dir("round_trip_3d");
  const Expected expected = write_two_cubes(dir);
  ASSERT_GT(expected.cells, 50u);
  for (const auto& path : expected.files) {
    SCOPED_TRACE(path);
    const Mesh mesh = read_quietly(path);
    EXPECT_EQ(mesh.dim, 3);
    EXPECT_EQ(static_cast<std::size_t>(mesh.n_cells()), expected.cells);
    EXPECT_EQ(static_cast<std::size_t>(mesh.n_vertices()), expected.nodes);
    expect_valid_serial_mesh(mesh);
    EXPECT_NEAR(total_measure(mesh), 2.0, 1e-12);
    EXPECT_NEAR(testing::tagged_cell_measure(mesh, 1), 1.0, 1e-12);
    EXPECT_NEAR(testing::tagged_cell_measure(mesh, 2), 1.0, 1e-12);
    EXPECT_EQ(group_list(mesh),
              (std::vector<std::tuple<std::string, int, int>>{
                  {"a", 3, 1}, {"b", 3, 2}, {"interface", 2, 10}, {"left", 2, 11}}));
    EXPECT_NEAR(group_facet_measure(mesh, "interface"), 1.0, 1e-12);
    EXPECT_NEAR(group_facet_measure(mesh, "left"), 1.0, 1e-12);
    // Interface facets are interior: they get the lower-numbered of their two cells.
    for (int f = 0; f < mesh.n_facets(); ++f)
      if (mesh.facet_tags[f] == 10) {
        int owners = 0, lowest = -1;
        for (int c = 0; c < mesh.n_cells(); ++c) {
          const auto cell = mesh.cell(c);
          int shared = 0;
          for (int k = 0; k < 3; ++k)
            shared += std::count(cell.begin(), cell.end(), mesh.facets[3 * f + k]);
          if (shared == 3) {
            if (owners++ == 0) lowest = c;
          }
        }
        ASSERT_EQ(owners, 2);
        ASSERT_EQ(mesh.facet_cell[f], lowest);
      }
  }
}

TEST(GmshReader, TruncatedFilesAreInputErrors) {
  TempDir dir("truncated");
  const Expected rectangle = write_rectangle(dir);
  const Expected cubes = write_two_cubes(dir);
  for (const auto* expected : {&rectangle, &cubes})
    for (const auto& path : expected->files) {
      const std::string cut = path + ".half.msh";
      write_first_half(path, cut);
      expect_input_error(cut);
    }
  // Gmsh is still usable afterwards.
  EXPECT_EQ(static_cast<std::size_t>(read_quietly(rectangle.files[0]).n_cells()), rectangle.cells);
}

TEST(GmshReader, MissingEmptyAndMalformedFilesAreInputErrors) {
  TempDir dir("bad");
  expect_input_error(dir.file("no_such_file.msh"), {"no such file"});
  expect_input_error(dir.file(""), {"directory"});
  std::ofstream(dir.file("empty.msh")).close();
  expect_input_error(dir.file("empty.msh"), {"empty"});
  std::ofstream(dir.file("text.msh")) << "this is not a mesh\n";
  expect_input_error(dir.file("text.msh"));
  // The same file as garbage_nodes_v4.msh without the garbage reads fine...
  const Mesh triangle = read_quietly(data_file("one_triangle_v4.msh"));
  EXPECT_EQ(triangle.n_cells(), 1);
  // ... with it, or in version 2, it does not.
  expect_input_error(data_file("garbage_nodes_v4.msh"));
  expect_input_error(data_file("garbage_nodes_v2.msh"));
}

TEST(GmshReader, CellsInTwoPhysicalGroupsAreAnInputError) {
  TempDir dir("two_groups");
  const std::string path = dir.file("two_groups.msh");
  {
    GmshSession session("test two groups");
    session.run([&] {
      gmsh::model::occ::addRectangle(0, 0, 0, 1, 1);
      gmsh::model::occ::synchronize();
      gmsh::model::addPhysicalGroup(2, {1}, 1);
      gmsh::model::setPhysicalName(2, 1, "first");
      gmsh::model::addPhysicalGroup(2, {1}, 2);
      gmsh::model::setPhysicalName(2, 2, "second");
      gmsh::model::mesh::generate(2);
      gmsh::write(path);
    });
  }
  expect_input_error(path, {"'first'", "'second'"});
}

TEST(GmshReader, UnsupportedElementsAreNamed) {
  expect_input_error(data_file("quads.msh"), {"Quadrilateral", "type 3", "element 1"});
  expect_input_error(data_file("second_order.msh"), {"Triangle 6", "type 9", "element 7"});
}

TEST(GmshReader, TwoDimensionalMeshMustLieInThePlaneZ0) {
  expect_input_error(data_file("tilted.msh"), {"z = 0", "node 2"});
}

TEST(GmshReader, TaggedFacetThatBoundsNoCellIsNamed) {
  expect_input_error(data_file("orphan_facet.msh"), {"boundary element 99", "'wall'"});
}

TEST(GmshReader, InvertedTetrahedronIsReportedByItsNumber) {
  const std::string path = data_file("inverted_tet.msh");
  Mesh mesh = read_quietly(path);
  ASSERT_EQ(mesh.n_cells(), 2);
  EXPECT_EQ(mesh.original_cell, (std::vector<std::int64_t>{11, 12}));
  EXPECT_FALSE(orient_cells(mesh));  // only one of the two is flipped: not re-oriented
  const auto report = check_quality(mesh);
  ASSERT_EQ(report.inverted.size(), 1u);
  EXPECT_TRUE(report.degenerate.empty());
  EXPECT_EQ(report.inverted[0].original, 12);
  EXPECT_EQ(report.inverted[0].cell, 1);
  EXPECT_NEAR(report.inverted[0].centroid[0], 0.25, 1e-15);
  EXPECT_NEAR(report.inverted[0].centroid[1], 0.25, 1e-15);
  EXPECT_NEAR(report.inverted[0].centroid[2], -0.25, 1e-15);
  EXPECT_LT(report.min_measure, 0);
  try {
    require_valid(mesh, report);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path + ": inverted element 12 at (0.25, 0.25, -0.25)", 0), 0u)
        << message;
    EXPECT_NE(message.find("1 inverted element in total"), std::string::npos) << message;
  }
  // The tagged triangle (element 13) lies on the flipped tetrahedron only.
  ASSERT_EQ(mesh.n_facets(), 1);
  EXPECT_EQ(mesh.facet_cell[0], 1);
  EXPECT_EQ(mesh.group("bottom").dim, 2);
  EXPECT_EQ(mesh.group("solid").tag, 2);
}

TEST(GmshReader, ConsistentlyFlipped2DMeshIsReorientedSilently) {
  const Mesh mesh = read_quietly(data_file("flipped_2d.msh"));
  expect_valid_serial_mesh(mesh);  // all cells positive, facets outward
  EXPECT_NEAR(total_measure(mesh), 2.0, 1e-15);
  EXPECT_NEAR(group_facet_measure(mesh, "wall"), 4.0, 1e-15);
  EXPECT_TRUE(check_quality(mesh).valid());
}

TEST(GmshSession, DoesNotNest) {
  GmshSession outer("outer");
  EXPECT_THROW(GmshSession("inner"), InternalError);
}

TEST(GmshSession, TranslatesGmshExceptions) {
  GmshSession session("api misuse");
  try {
    session.run([] { gmsh::model::mesh::generate(7); });  // not a dimension
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("api misuse: ", 0), 0u) << e.what();
  }
  try {
    session.run([] { throw std::string("raw Gmsh error"); });
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "api misuse: raw Gmsh error");
  }
}

}  // namespace
}  // namespace coapt::mesh
