#pragma once
// Shared checks for the mesh unit tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "coapt/mesh/mesh.hpp"
#include "coapt/mesh/topology.hpp"

namespace coapt::mesh::testing {

inline std::string data_file(const std::string& name) {
  return std::string(COAPT_SOURCE_DIR) + "/tests/data/meshes/" + name;
}

/// A fresh temporary directory, removed on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& name) {
    path_ = std::filesystem::temp_directory_path() /
            ("coapt_mesh_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline double total_measure(const Mesh& mesh) {
  double sum = 0;
  for (int c = 0; c < mesh.n_cells(); ++c) sum += cell_signed_measure(mesh, c);
  return sum;
}

inline double tagged_cell_measure(const Mesh& mesh, int tag) {
  double sum = 0;
  for (int c = 0; c < mesh.n_cells(); ++c)
    if (mesh.cell_tags[c] == tag) sum += cell_signed_measure(mesh, c);
  return sum;
}

/// Length (2D) or area (3D) of facet f.
inline double facet_measure(const Mesh& mesh, int f) {
  const int* v = mesh.facets.data() + static_cast<std::size_t>(f) * mesh.dim;
  const auto a = mesh.point(v[0]), b = mesh.point(v[1]);
  if (mesh.dim == 2) return std::hypot(b[0] - a[0], b[1] - a[1]);
  const auto c = mesh.point(v[2]);
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                       u[0] * w[1] - u[1] * w[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

inline double group_facet_measure(const Mesh& mesh, const std::string& name) {
  const int tag = mesh.group(name).tag;
  double sum = 0;
  for (int f = 0; f < mesh.n_facets(); ++f)
    if (mesh.facet_tags[f] == tag) sum += facet_measure(mesh, f);
  return sum;
}

inline int count_facets(const Mesh& mesh, const std::string& name) {
  const int tag = mesh.group(name).tag;
  return static_cast<int>(std::count(mesh.facet_tags.begin(), mesh.facet_tags.end(), tag));
}

/// True if the facet's normal points away from its cell's remaining vertex.
inline bool facet_outward(const Mesh& mesh, int f) {
  const int dim = mesh.dim;
  const int* v = mesh.facets.data() + static_cast<std::size_t>(f) * dim;
  int opposite = -1;
  for (const int u : mesh.cell(mesh.facet_cell[f]))
    if (std::find(v, v + dim, u) == v + dim) opposite = u;
  const double* points[4] = {};
  for (int k = 0; k < dim; ++k) points[k] = mesh.point(v[k]).data();
  points[dim] = mesh.point(opposite).data();
  const double m = signed_measure(dim, points);
  return dim == 2 ? m > 0 : m < 0;
}

inline bool facet_in_cell(const Mesh& mesh, int f) {
  const int c = mesh.facet_cell[f];
  if (c < 0 || c >= mesh.n_cells()) return false;
  const auto cell = mesh.cell(c);
  for (int k = 0; k < mesh.dim; ++k)
    if (std::find(cell.begin(), cell.end(), mesh.facets[f * mesh.dim + k]) == cell.end())
      return false;
  return true;
}

/// The invariants every serial mesh from the reader or a generator satisfies.
inline void expect_valid_serial_mesh(const Mesh& mesh) {
  const int dim = mesh.dim;
  ASSERT_TRUE(dim == 2 || dim == 3);
  const int nv = mesh.n_vertices(), nc = mesh.n_cells(), nf = mesh.n_facets();
  EXPECT_EQ(mesh.comm, MPI_COMM_SELF);
  EXPECT_EQ(mesh.coordinates.size(), static_cast<std::size_t>(nv) * dim);
  EXPECT_EQ(mesh.original_vertex.size(), static_cast<std::size_t>(nv));
  EXPECT_EQ(mesh.n_owned_vertices, nv);
  EXPECT_EQ(mesh.n_global_vertices, nv);
  EXPECT_EQ(mesh.vertex_offset, 0);
  for (int v = 0; v < nv; ++v) ASSERT_EQ(mesh.global_vertex[v], v);
  EXPECT_EQ(mesh.cells.size(), static_cast<std::size_t>(nc) * (dim + 1));
  EXPECT_EQ(mesh.cell_tags.size(), static_cast<std::size_t>(nc));
  EXPECT_EQ(mesh.original_cell.size(), static_cast<std::size_t>(nc));
  EXPECT_EQ(mesh.n_owned_cells, nc);
  EXPECT_EQ(mesh.n_global_cells, nc);
  EXPECT_EQ(mesh.facet_tags.size(), static_cast<std::size_t>(nf));
  EXPECT_EQ(mesh.facet_cell.size(), static_cast<std::size_t>(nf));
  std::vector<char> used(static_cast<std::size_t>(nv), 0);
  for (const int v : mesh.cells) {
    ASSERT_GE(v, 0);
    ASSERT_LT(v, nv);
    used[v] = 1;
  }
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "unused vertices";
  for (int c = 0; c < nc; ++c) ASSERT_GT(cell_signed_measure(mesh, c), 0) << "cell " << c;
  for (int f = 0; f < nf; ++f) {
    ASSERT_TRUE(facet_in_cell(mesh, f)) << "facet " << f;
    ASSERT_TRUE(facet_outward(mesh, f)) << "facet " << f;
  }
}

}  // namespace coapt::mesh::testing
