// VtkSeries on one rank: write small hand-made meshes, read them back with
// tools/vtk_read.py (VTK's own readers) and compare everything.
#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/io/json.hpp"
#include "coapt/io/vtk_writer.hpp"
#include "coapt/mesh/mesh.hpp"

namespace {

using coapt::io::Field;
using coapt::io::Json;
using coapt::io::VtkSeries;
using coapt::mesh::Mesh;

std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("coapt_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

/// Runs tools/vtk_read.py on `file` and parses its JSON output.
Json vtk_read(const std::filesystem::path& file, const std::string& options = "") {
  const auto err = std::filesystem::path(file).concat(".stderr");
  const std::string command = std::string("/usr/bin/python3 ") + COAPT_SOURCE_DIR +
                              "/tools/vtk_read.py " + options + " '" + file.string() + "' 2>'" +
                              err.string() + "'";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed: " + command);
  std::string output;
  char buffer[65536];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
  const int status = ::pclose(pipe);
  if (status != 0) {
    std::ifstream in(err);
    std::stringstream text;
    text << in.rdbuf();
    throw std::runtime_error("vtk_read.py failed (status " + std::to_string(status) +
                             "): " + text.str());
  }
  return Json::parse(output);
}

/// The array named `name` in a list of arrays described by vtk_read.py.
const Json& array_named(const Json& arrays, const std::string& name) {
  for (const Json& a : arrays.as_array())
    if (a.at("name").as_string() == name) return a;
  throw std::runtime_error("no array named " + name);
}

std::vector<double> doubles(const Json& values) {
  std::vector<double> out;
  for (const Json& v : values.as_array()) out.push_back(v.as_double());
  return out;
}

/// A 2x2 square grid of the unit square split into 8 triangles, with one extra vertex
/// (local 4, at the end of the numbering of the grid) that no cell uses, to check that
/// pieces keep only the used vertices and renumber them.
Mesh square_mesh() {
  Mesh m;
  m.dim = 2;
  m.source = "test square";
  m.comm = MPI_COMM_SELF;
  // grid vertex (i, j) -> local index, skipping 4 (the unused vertex, placed at (5, 5)).
  auto id = [](int i, int j) {
    const int k = j * 3 + i;
    return k < 4 ? k : k + 1;
  };
  m.coordinates.assign(2 * 10, 0.0);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      m.coordinates[2 * id(i, j)] = 0.5 * i;
      m.coordinates[2 * id(i, j) + 1] = 0.5 * j;
    }
  m.coordinates[2 * 4] = 5.0;
  m.coordinates[2 * 4 + 1] = 5.0;
  for (int v = 0; v < 10; ++v) m.global_vertex.push_back(v);
  for (int v = 0; v < 10; ++v) m.original_vertex.push_back(v + 1);
  m.n_owned_vertices = 10;
  m.vertex_offset = 0;
  m.n_global_vertices = 10;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      for (int v : {a, b, c}) m.cells.push_back(v);
      for (int v : {a, c, d}) m.cells.push_back(v);
    }
  m.n_owned_cells = m.n_cells();
  m.n_global_cells = m.n_cells();
  m.cell_tags.assign(m.n_cells(), 0);
  return m;
}

/// The unit cube split into 6 tetrahedra around the diagonal 0-7.
Mesh cube_mesh() {
  Mesh m;
  m.dim = 3;
  m.source = "test cube";
  m.comm = MPI_COMM_SELF;
  for (int v = 0; v < 8; ++v) {
    m.coordinates.push_back(v & 1 ? 1.0 : 0.0);
    m.coordinates.push_back(v & 2 ? 1.0 : 0.0);
    m.coordinates.push_back(v & 4 ? 1.0 : 0.0);
    m.global_vertex.push_back(v);
  }
  m.n_owned_vertices = 8;
  m.n_global_vertices = 8;
  const int tets[6][4] = {{0, 1, 3, 7}, {0, 1, 7, 5}, {0, 2, 7, 3},
                          {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 7, 6}};
  for (const auto& t : tets)
    for (int v : t) m.cells.push_back(v);
  m.n_owned_cells = 6;
  m.n_global_cells = 6;
  m.cell_tags.assign(6, 0);
  return m;
}

/// Awkward values whose binary round trip is checked exactly.
double vertex_value(int vertex, int component, int step) {
  return std::sin(1.0 + vertex * 0.7 + component * 1.3) * std::pow(10.0, step * 100 - 50) +
         (component == 1 ? 1.0 / 3.0 : 0.0);
}
double cell_value(int cell, int step) {
  return std::exp(cell * 0.31) / 7.0 - step * 1e-17;
}

/// Writes two steps of `mesh` and checks everything vtk_read.py sees.
void write_and_check(const Mesh& mesh, const std::string& name) {
  const auto dir = scratch_dir(name);
  const int dim = mesh.dim;
  const int nv = mesh.n_vertices();
  const int nc = mesh.n_cells();
  const std::array<double, 2> times = {0.0, 0.125};
  VtkSeries series(MPI_COMM_SELF, dir, name);

  std::array<std::vector<double>, 2> velocity, pressure, stress;
  for (int step = 0; step < 2; ++step) {
    for (int v = 0; v < nv; ++v)
      for (int k = 0; k < dim; ++k) velocity[step].push_back(vertex_value(v, k, step));
    for (int c = 0; c < nc; ++c) pressure[step].push_back(cell_value(c, step));
    for (int c = 0; c < nc; ++c)
      for (int k = 0; k < 6; ++k) stress[step].push_back(cell_value(c + k, step) * (k + 1));
    const std::vector<Field> fields = {
        {"velocity", dim, Field::Location::vertex, velocity[step]},
        {"pressure", 1, Field::Location::cell, pressure[step]},
        {"stress <sym>", 6, Field::Location::cell, stress[step]},  // a name to escape in XML
    };
    series.write(mesh, times[step], fields);
    EXPECT_EQ(series.n_steps(), step + 1);
  }
  EXPECT_TRUE(std::filesystem::exists(dir / (name + ".pvd")));
  EXPECT_TRUE(std::filesystem::exists(dir / (name + "_000001.pvtu")));
  EXPECT_TRUE(std::filesystem::exists(dir / (name + "_pieces") / (name + "_000001_r0000.vtu")));
  EXPECT_EQ(series.piece_path(1, 0), dir / (name + "_pieces") / (name + "_000001_r0000.vtu"));

  // Vertices used by cells, in local order: what the piece should hold.
  std::vector<int> used;
  {
    std::vector<bool> is_used(nv, false);
    for (int v : mesh.cells) is_used[v] = true;
    for (int v = 0; v < nv; ++v)
      if (is_used[v]) used.push_back(v);
  }

  const Json read = vtk_read(dir / (name + ".pvd"));
  const Json& steps = read.at("steps");
  ASSERT_EQ(steps.size(), 2u);
  for (int step = 0; step < 2; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    const Json& s = steps.at(step);
    EXPECT_EQ(s.at("time").as_double(), times[step]);
    EXPECT_EQ(s.at("n_points").as_int(), static_cast<std::int64_t>(used.size()));
    EXPECT_EQ(s.at("n_cells").as_int(), nc);

    // Points: global ids say which vertex each point is; coordinates padded to 3.
    const Json& gid = array_named(s.at("point_data"), "global_id");
    EXPECT_EQ(gid.at("components").as_int(), 1);
    ASSERT_EQ(gid.at("values").size(), used.size());
    const auto points = doubles(s.at("points").at("values"));
    EXPECT_EQ(s.at("points").at("components").as_int(), 3);
    ASSERT_EQ(points.size(), 3 * used.size());
    const Json& vel = array_named(s.at("point_data"), "velocity");
    const int written = dim == 2 ? 3 : dim;  // 2D vectors padded to 3 components
    EXPECT_EQ(vel.at("components").as_int(), written);
    const auto vel_values = doubles(vel.at("values"));
    ASSERT_EQ(vel_values.size(), written * used.size());
    std::vector<int> local_of_point(used.size());
    for (std::size_t p = 0; p < used.size(); ++p) {
      const int v = static_cast<int>(gid.at("values").at(p).as_int());  // global == local here
      EXPECT_EQ(v, used[p]) << "points in local order";
      local_of_point[p] = v;
      for (int d = 0; d < 3; ++d)
        EXPECT_EQ(points[3 * p + d], d < dim ? mesh.point(v)[d] : 0.0) << "point " << p;
      for (int k = 0; k < written; ++k)
        EXPECT_EQ(vel_values[written * p + k], k < dim ? velocity[step][dim * v + k] : 0.0)
            << "point " << p << " component " << k;
    }

    // Cells: connectivity back to local vertices matches the mesh; types and offsets.
    const Json& cells = s.at("cells");
    const int per_cell = dim + 1;
    ASSERT_EQ(cells.at("connectivity").size(), static_cast<std::size_t>(nc * per_cell));
    for (int c = 0; c < nc; ++c) {
      EXPECT_EQ(cells.at("types").at(c).as_int(), dim == 2 ? 5 : 10);
      EXPECT_EQ(cells.at("offsets").at(c + 1).as_int(), (c + 1) * per_cell);
      for (int k = 0; k < per_cell; ++k)
        EXPECT_EQ(local_of_point[cells.at("connectivity").at(c * per_cell + k).as_int()],
                  mesh.cell(c)[k]);
    }
    const auto p_values = doubles(array_named(s.at("cell_data"), "pressure").at("values"));
    EXPECT_EQ(p_values, pressure[step]);
    const Json& st = array_named(s.at("cell_data"), "stress <sym>");
    EXPECT_EQ(st.at("components").as_int(), 6);
    EXPECT_EQ(doubles(st.at("values")), stress[step]);
    const Json& rank = array_named(s.at("cell_data"), "rank");
    ASSERT_EQ(rank.at("values").size(), static_cast<std::size_t>(nc));
    for (const Json& r : rank.at("values").as_array()) EXPECT_EQ(r.as_int(), 0);
  }

  // A single piece reads too and carries its time.
  const Json piece = vtk_read(series.piece_path(1, 0), "--summary");
  EXPECT_EQ(piece.at("steps").at(0).at("time").as_double(), 0.125);
  EXPECT_EQ(piece.at("steps").at(0).at("n_cells").as_int(), nc);
  std::filesystem::remove_all(dir);
}

TEST(VtkSeries, RoundTrip2D) {
  write_and_check(square_mesh(), "square");
}

TEST(VtkSeries, RoundTrip3D) {
  write_and_check(cube_mesh(), "cube");
}

TEST(VtkSeries, NonFiniteFieldThrowsNamingTheFieldAndWritesNothing) {
  const auto dir = scratch_dir("vtk_nan");
  const Mesh mesh = cube_mesh();
  VtkSeries series(MPI_COMM_SELF, dir, "nan");
  std::vector<double> good(8, 1.0), bad(8 * 3, 2.0);
  series.write(mesh, 0.0, std::vector<Field>{{"temperature", 1, Field::Location::vertex, good}});
  bad[3 * 5 + 2] = std::numeric_limits<double>::quiet_NaN();
  bad[3 * 6 + 0] = std::numeric_limits<double>::infinity();
  try {
    series.write(mesh, 1.0,
                 std::vector<Field>{{"temperature", 1, Field::Location::vertex, good},
                                    {"displacement", 3, Field::Location::vertex, bad}});
    FAIL() << "no exception";
  } catch (const coapt::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'displacement'"), std::string::npos) << what;
    EXPECT_NE(what.find("vertex 5"), std::string::npos) << what;
    EXPECT_NE(what.find("component 2"), std::string::npos) << what;
    EXPECT_NE(what.find("nan"), std::string::npos) << what;
  }
  EXPECT_EQ(series.n_steps(), 1);
  EXPECT_FALSE(std::filesystem::exists(series.pvtu_path(1)));
  EXPECT_FALSE(std::filesystem::exists(series.piece_path(1, 0)));

  std::vector<double> cells(6, 0.0);
  cells[4] = -std::numeric_limits<double>::infinity();
  try {
    series.write(mesh, 1.0, std::vector<Field>{{"pressure", 1, Field::Location::cell, cells}});
    FAIL() << "no exception";
  } catch (const coapt::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'pressure'"), std::string::npos) << what;
    EXPECT_NE(what.find("cell 4"), std::string::npos) << what;
  }
  EXPECT_THROW(series.write(mesh, std::numeric_limits<double>::quiet_NaN(), {}), coapt::Error);

  // The series goes on: the next good step is step 1.
  series.write(mesh, 2.0, std::vector<Field>{{"temperature", 1, Field::Location::vertex, good}});
  const Json read = vtk_read(series.pvd_path(), "--summary");
  ASSERT_EQ(read.at("steps").size(), 2u);
  EXPECT_EQ(read.at("steps").at(1).at("time").as_double(), 2.0);
  const Json& t = array_named(read.at("steps").at(1).at("point_data"), "temperature");
  EXPECT_EQ(t.at("min").at(0).as_double(), 1.0);
  EXPECT_EQ(t.at("non_finite").as_int(), 0);
  std::filesystem::remove_all(dir);
}

TEST(VtkSeries, BadArgumentsAreInternalErrors) {
  const auto dir = scratch_dir("vtk_bad");
  const Mesh mesh = square_mesh();
  VtkSeries series(MPI_COMM_SELF, dir, "bad");
  std::vector<double> short_field(3, 0.0), cells(8, 0.0);
  using L = Field::Location;
  EXPECT_THROW(series.write(mesh, 0.0, std::vector<Field>{{"u", 1, L::vertex, short_field}}),
               coapt::InternalError);
  EXPECT_THROW(series.write(mesh, 0.0, std::vector<Field>{{"rank", 1, L::cell, cells}}),
               coapt::InternalError);
  EXPECT_THROW(series.write(mesh, 0.0,
                            std::vector<Field>{{"p", 1, L::cell, cells}, {"p", 1, L::cell, cells}}),
               coapt::InternalError);
  Mesh broken = mesh;
  broken.cells[5] = 99;
  EXPECT_THROW(series.write(broken, 0.0, {}), coapt::InternalError);
  EXPECT_EQ(series.n_steps(), 0);
  EXPECT_THROW(VtkSeries(MPI_COMM_SELF, dir, "a/b"), coapt::Error);
  EXPECT_THROW(VtkSeries(MPI_COMM_SELF, "/proc/coapt-no-such-dir", "x"), coapt::Error);
  std::filesystem::remove_all(dir);
}

TEST(VtkSeries, Base64) {
  auto encode = [](const std::string& text) {
    return coapt::io::detail::base64_encode(
        std::as_bytes(std::span<const char>(text.data(), text.size())));
  };
  EXPECT_EQ(encode(""), "");
  EXPECT_EQ(encode("f"), "Zg==");
  EXPECT_EQ(encode("fo"), "Zm8=");
  EXPECT_EQ(encode("foo"), "Zm9v");
  EXPECT_EQ(encode("foob"), "Zm9vYg==");
  EXPECT_EQ(encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(encode(std::string("\xff\xfe\x00", 3)), "//4A");
}

}  // namespace
