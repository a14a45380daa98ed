// VtkSeries on any number of ranks: each rank builds its strip of a structured triangle
// mesh (with ghost vertices and a ghost cell layer, as the mesh contract has them), writes
// fields that are known functions of the coordinates, and rank 0 reads the series back with
// tools/vtk_read.py (VTK's own readers) and checks every value.
#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
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

constexpr int kNx = 5;  // cells in x
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

int comm_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int comm_size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

/// A fresh directory named by rank 0, the same on every rank.
std::filesystem::path shared_scratch_dir(const std::string& name) {
  std::string path;
  if (comm_rank() == 0) {
    path = (std::filesystem::temp_directory_path() /
            ("coapt_mpi_" + name + "_" + std::to_string(::getpid())))
               .string();
    std::filesystem::remove_all(path);
  }
  int size = static_cast<int>(path.size());
  MPI_Bcast(&size, 1, MPI_INT, 0, MPI_COMM_WORLD);
  path.resize(size);
  MPI_Bcast(path.data(), size, MPI_CHAR, 0, MPI_COMM_WORLD);
  return path;
}

/// Runs tools/vtk_read.py on `file` and parses its JSON output (call on one rank).
Json vtk_read(const std::filesystem::path& file) {
  const auto err = std::filesystem::path(file).concat(".stderr");
  const std::string command = std::string("/usr/bin/python3 ") + COAPT_SOURCE_DIR +
                              "/tools/vtk_read.py '" + file.string() + "' 2>'" + err.string() + "'";
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

// The global mesh: vertices (i, j), i in [0, kNx], j in [0, ny], global number
// j (kNx + 1) + i; each cell square (i, j) split into two triangles.
double x_of(int i, int j, int ny) {
  return static_cast<double>(i) / kNx + 0.1 * j / ny;
}
double y_of(int j, int ny) {
  return static_cast<double>(j) / ny;
}
double vertex_function(double x, double y) {
  return std::sin(3.0 * x) + x * y * y - 0.25;
}
double cell_function(double x, double y) {
  return std::cos(x + 2.0 * y) * 1e3 + 1.0 / 3.0;
}

/// Cell rows [row_begin(r), row_begin(r + 1)) are rank r's.
int row_begin(int rank, int size, int ny) {
  return static_cast<int>(1LL * rank * ny / size);
}

/// This rank's part: owned cells of its rows, then the ghost cell rows just below and above;
/// vertex row j0 is shared with the rank below, which owns it (its top row); local vertices
/// are the owned ones in global order, then the ghosts (from the top down, to make the
/// local order differ from the global one).
struct Strip {
  Mesh mesh;
  std::vector<int> row_of_vertex, column_of_vertex;
};

Strip build_strip(int rank, int size, int ny) {
  const int j0 = row_begin(rank, size, ny), j1 = row_begin(rank + 1, size, ny);
  Strip s;
  Mesh& m = s.mesh;
  m.dim = 2;
  m.source = "strip";
  m.comm = MPI_COMM_WORLD;
  m.n_global_vertices = static_cast<PetscInt>((kNx + 1) * (ny + 1));
  m.n_global_cells = 2LL * kNx * ny;
  std::map<std::pair<int, int>, int> local;  // (i, j) -> local vertex
  auto add_vertex = [&](int i, int j) {
    local[{i, j}] = m.n_vertices();
    m.coordinates.push_back(x_of(i, j, ny));
    m.coordinates.push_back(y_of(j, ny));
    m.global_vertex.push_back(static_cast<PetscInt>(j * (kNx + 1) + i));
    m.original_vertex.push_back(j * (kNx + 1) + i + 1);
    s.row_of_vertex.push_back(j);
    s.column_of_vertex.push_back(i);
  };
  const int first_owned_row = rank == 0 ? 0 : j0 + 1;
  if (j1 > j0)
    for (int j = first_owned_row; j <= j1; ++j)
      for (int i = 0; i <= kNx; ++i) add_vertex(i, j);
  m.n_owned_vertices = m.n_vertices();
  m.vertex_offset = static_cast<PetscInt>(first_owned_row * (kNx + 1));
  if (j1 == j0) m.vertex_offset = 0;  // owns nothing (more ranks than rows)
  // Ghost vertices: top ghost row, shared row j0, bottom ghost row.
  std::vector<int> ghost_rows;
  if (j1 > j0) {
    if (j1 < ny) ghost_rows.push_back(j1 + 1);
    if (rank > 0) ghost_rows.push_back(j0);
    if (rank > 0 && j0 > 0) ghost_rows.push_back(j0 - 1);
  }
  for (int j : ghost_rows)
    for (int i = kNx; i >= 0; --i) add_vertex(i, j);

  auto add_cells_of_row = [&](int j) {
    for (int i = 0; i < kNx; ++i) {
      const int a = local.at({i, j}), b = local.at({i + 1, j});
      const int c = local.at({i + 1, j + 1}), d = local.at({i, j + 1});
      for (int v : {a, b, c}) m.cells.push_back(v);
      for (int v : {a, c, d}) m.cells.push_back(v);
    }
  };
  for (int j = j0; j < j1; ++j) add_cells_of_row(j);
  m.n_owned_cells = m.n_cells();
  if (j1 > j0) {
    if (rank > 0 && j0 > 0) add_cells_of_row(j0 - 1);  // ghost cells below
    if (j1 < ny) add_cells_of_row(j1);                 // ghost cells above
  }
  m.cell_tags.assign(m.n_cells(), 0);
  return s;
}

/// The fields of `strip`: ghost cells and ghost vertices no owned cell uses get NaN, which
/// must neither be written nor trip the non-finite check.
struct StripFields {
  std::vector<double> f, u, c;
};

StripFields strip_fields(const Strip& s, int ny, double scale) {
  const Mesh& m = s.mesh;
  StripFields out;
  std::vector<bool> used(m.n_vertices(), false);
  for (int c = 0; c < m.n_owned_cells; ++c)
    for (int v : m.cell(c)) used[v] = true;
  for (int v = 0; v < m.n_vertices(); ++v) {
    const double x = m.point(v)[0], y = m.point(v)[1];
    out.f.push_back(used[v] ? scale * vertex_function(x, y) : kNaN);
    out.u.push_back(used[v] ? x : kNaN);
    out.u.push_back(used[v] ? -y : kNaN);
  }
  for (int c = 0; c < m.n_cells(); ++c) {
    double x = 0, y = 0;
    for (int v : m.cell(c)) {
      x += m.point(v)[0];
      y += m.point(v)[1];
    }
    out.c.push_back(c < m.n_owned_cells ? scale * cell_function(x / 3, y / 3) : kNaN);
  }
  (void)ny;
  return out;
}

void check_step(const Json& step, int ny, int size, double scale) {
  const int n_cells = 2 * kNx * ny;
  EXPECT_EQ(step.at("n_cells").as_int(), n_cells);
  // Each rank writes the vertex rows j0..j1 of its cells (shared rows appear twice).
  std::int64_t expected_points = 0;
  for (int r = 0; r < size; ++r) {
    const int j0 = row_begin(r, size, ny), j1 = row_begin(r + 1, size, ny);
    if (j1 > j0) expected_points += static_cast<std::int64_t>(j1 - j0 + 1) * (kNx + 1);
  }
  EXPECT_EQ(step.at("n_points").as_int(), expected_points);

  const auto points = doubles(step.at("points").at("values"));
  const auto f = doubles(array_named(step.at("point_data"), "f").at("values"));
  const auto u = doubles(array_named(step.at("point_data"), "u").at("values"));
  const Json& gid = array_named(step.at("point_data"), "global_id").at("values");
  const std::size_t np = points.size() / 3;
  ASSERT_EQ(f.size(), np);
  ASSERT_EQ(u.size(), 3 * np);
  ASSERT_EQ(gid.size(), np);
  std::vector<std::int64_t> global(np);
  for (std::size_t p = 0; p < np; ++p) {
    const double x = points[3 * p], y = points[3 * p + 1];
    EXPECT_EQ(points[3 * p + 2], 0.0);
    const double expected = scale * vertex_function(x, y);
    EXPECT_NEAR(f[p], expected, 1e-15 * std::max(1.0, std::abs(expected))) << "point " << p;
    EXPECT_EQ(u[3 * p], x);
    EXPECT_EQ(u[3 * p + 1], -y);
    EXPECT_EQ(u[3 * p + 2], 0.0);
    const int j = static_cast<int>(std::lround(y * ny));
    const int i = static_cast<int>(std::lround((x - 0.1 * j / ny) * kNx));
    global[p] = gid.at(p).as_int();
    EXPECT_EQ(global[p], j * (kNx + 1) + i) << "point " << p << " at " << x << ", " << y;
  }

  // Every global cell exactly once (by its global vertices), with the right value.
  const Json& cells = step.at("cells");
  const auto c_values = doubles(array_named(step.at("cell_data"), "c").at("values"));
  const Json& rank = array_named(step.at("cell_data"), "rank").at("values");
  ASSERT_EQ(c_values.size(), static_cast<std::size_t>(n_cells));
  ASSERT_EQ(rank.size(), static_cast<std::size_t>(n_cells));
  std::set<std::array<std::int64_t, 3>> seen;
  std::vector<int> cells_of_rank(size, 0);
  for (int c = 0; c < n_cells; ++c) {
    EXPECT_EQ(cells.at("types").at(c).as_int(), 5);
    std::array<std::int64_t, 3> key{};
    double x = 0, y = 0;
    for (int k = 0; k < 3; ++k) {
      const auto p = static_cast<std::size_t>(cells.at("connectivity").at(3 * c + k).as_int());
      key[k] = global[p];
      x += points[3 * p];
      y += points[3 * p + 1];
    }
    std::sort(key.begin(), key.end());
    EXPECT_TRUE(seen.insert(key).second) << "cell written twice";
    const double expected = scale * cell_function(x / 3, y / 3);
    EXPECT_NEAR(c_values[c], expected, 1e-14 * std::max(1.0, std::abs(expected))) << "cell " << c;
    const auto r = rank.at(c).as_int();
    ASSERT_TRUE(r >= 0 && r < size);
    ++cells_of_rank[r];
  }
  for (int r = 0; r < size; ++r) {
    const int rows = row_begin(r + 1, size, ny) - row_begin(r, size, ny);
    EXPECT_EQ(cells_of_rank[r], 2 * kNx * rows) << "cells of rank " << r;
  }
}

TEST(VtkParallel, StripsReadBackWithEveryValue) {
  const int rank = comm_rank(), size = comm_size();
  const int ny = 2 * size + 1;
  const auto dir = shared_scratch_dir("vtk_strips");
  const Strip strip = build_strip(rank, size, ny);
  VtkSeries series(MPI_COMM_WORLD, dir, "strips");
  const std::array<double, 2> times = {0.25, 0.5};
  const std::array<double, 2> scales = {1.0, -3.0};
  for (int step = 0; step < 2; ++step) {
    const StripFields fields = strip_fields(strip, ny, scales[step]);
    const std::vector<Field> list = {
        {"f", 1, Field::Location::vertex, fields.f},
        {"u", 2, Field::Location::vertex, fields.u},
        {"c", 1, Field::Location::cell, fields.c},  // n_cells entries: ghosts ignored
    };
    series.write(strip.mesh, times[step], list);
  }
  if (rank == 0) {
    const Json read = vtk_read(series.pvd_path());
    const Json& steps = read.at("steps");
    ASSERT_EQ(steps.size(), 2u);
    for (int step = 0; step < 2; ++step) {
      SCOPED_TRACE("step " + std::to_string(step));
      EXPECT_EQ(steps.at(step).at("time").as_double(), times[step]);
      check_step(steps.at(step), ny, size, scales[step]);
    }
    std::filesystem::remove_all(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(VtkParallel, RanksWithoutCellsWriteEmptyPieces) {
  // Rank 0 holds the whole mesh; the others have nothing.
  const int rank = comm_rank(), size = comm_size();
  const int ny = 3;
  const auto dir = shared_scratch_dir("vtk_empty");
  Strip strip = rank == 0 ? build_strip(0, 1, ny) : Strip{};
  strip.mesh.dim = 2;
  strip.mesh.comm = MPI_COMM_WORLD;
  const StripFields fields = strip_fields(strip, ny, 1.0);
  VtkSeries series(MPI_COMM_WORLD, dir, "empty");
  series.write(strip.mesh, 1.0,
               std::vector<Field>{{"f", 1, Field::Location::vertex, fields.f},
                                  {"u", 2, Field::Location::vertex, fields.u},
                                  {"c", 1, Field::Location::cell, fields.c}});
  if (rank == 0) {
    const Json read = vtk_read(series.pvd_path());
    ASSERT_EQ(read.at("steps").size(), 1u);
    check_step(read.at("steps").at(0), ny, 1, 1.0);
    std::filesystem::remove_all(dir);
  }
  (void)size;
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(VtkParallel, NonFiniteValueOnOneRankThrowsOnAll) {
  const int rank = comm_rank(), size = comm_size();
  const int ny = 2 * size + 1;
  const auto dir = shared_scratch_dir("vtk_nan");
  const Strip strip = build_strip(rank, size, ny);
  StripFields fields = strip_fields(strip, ny, 1.0);
  if (rank == size - 1) fields.c[1] = kNaN;  // an owned cell of the last rank
  VtkSeries series(MPI_COMM_WORLD, dir, "nan");
  std::string message;
  try {
    series.write(strip.mesh, 0.0, std::vector<Field>{{"c", 1, Field::Location::cell, fields.c}});
  } catch (const coapt::Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("'c'"), std::string::npos) << message;
  EXPECT_NE(message.find("owned cell 1"), std::string::npos) << message;
  EXPECT_NE(message.find("on rank " + std::to_string(size - 1)), std::string::npos) << message;
  EXPECT_EQ(series.n_steps(), 0);
  // Every rank got the same message.
  int length = static_cast<int>(message.size()), low = 0, high = 0;
  MPI_Allreduce(&length, &low, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&length, &high, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(low, high);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) {
    EXPECT_FALSE(std::filesystem::exists(series.pvtu_path(0)));
    std::filesystem::remove_all(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

}  // namespace
