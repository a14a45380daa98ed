// The advancing-front search (PairSearch::sweep, SearchOptions::front) against the grid
// search: on jittered, rotated, partly outside and disconnected masters, in 2D and 3D, the
// front must find exactly the overlapping pairs the grid's pair list holds (the grid's pairs
// filtered by the kernel), test no pair twice, and leave most slave cells to the front when
// the meshes overlap in one piece; the faces the kernel tells the front not to cross must be
// faces whose plane no vertex of the slave cell crosses or, for an overlapping pair, that the
// intersection (clipped again here, in physical coordinates) does not reach. Also
// face_neighbors against a direct count.

#include <gtest/gtest.h>
#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include "../../support/mesh_transforms.hpp"
#include "coapt/mesh/generators.hpp"
#include "coapt/transfer/clipping.hpp"
#include "coapt/transfer/intersection.hpp"
#include "coapt/transfer/operators.hpp"
#include "coapt/transfer/search.hpp"

namespace coapt::transfer {
namespace {

using coapt::testing::rotated;
using mesh::Mesh;

Mesh square(double x0, double y0, double x1, double y1, int nx, int ny) {
  return mesh::structured_rectangle(x0, y0, x1, y1, nx, ny);
}
Mesh box(double x0, double y0, double z0, double x1, double y1, double z1, int nx, int ny, int nz) {
  return mesh::structured_box(x0, y0, z0, x1, y1, z1, nx, ny, nz);
}

/// Uniform in [−1, 1] from an integer (splitmix64), as in the benchmark.
double hash_uniform(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return 2.0 * static_cast<double>(x >> 11) / 9007199254740992.0 - 1.0;
}

/// Interior vertices (of the unit square / cube) moved by up to ±fraction·h per coordinate.
Mesh jittered(Mesh m, double h, double fraction) {
  const int d = m.dim;
  for (int v = 0; v < m.n_vertices(); ++v) {
    double* x = m.coordinates.data() + static_cast<std::size_t>(v) * d;
    bool interior = true;
    for (int k = 0; k < d; ++k) interior = interior && x[k] > 0.5 * h && x[k] < 1 - 0.5 * h;
    if (!interior) continue;
    for (int k = 0; k < d; ++k)
      x[k] += fraction * h * hash_uniform(static_cast<std::uint64_t>(d * v + k));
  }
  return m;
}

/// The mesh without the cells whose vertex centroid has coordinate `axis` in (lower, upper):
/// two pieces that share no face (vertices left unused are harmless).
Mesh without_slab(const Mesh& m, int axis, double lower, double upper) {
  Mesh out = m;
  const int k = m.dim + 1;
  out.cells.clear();
  out.cell_tags.clear();
  out.original_cell.clear();
  for (int c = 0; c < m.n_cells(); ++c) {
    double centroid = 0;
    for (int v : m.cell(c)) centroid += m.point(v)[axis] / k;
    if (centroid > lower && centroid < upper) continue;
    for (int v : m.cell(c)) out.cells.push_back(v);
    if (!m.cell_tags.empty()) out.cell_tags.push_back(m.cell_tags[c]);
    if (!m.original_cell.empty()) out.original_cell.push_back(m.original_cell[c]);
  }
  out.n_owned_cells = out.n_cells();
  out.n_global_cells = out.n_cells();
  return out;
}

/// The lowest λ^B_i over the vertices of A ∩ B, clipped here independently of the kernel (A
/// in physical coordinates by the face half-spaces of B); +∞ when nothing is left.
double lowest_on_intersection(const Simplex<3>& a, const Simplex<3>& b, int i) {
  ConvexPolyhedron polytope;
  polytope.assign_tetrahedron(a.vertices);
  for (int j = 0; j <= 3; ++j)
    if (!polytope.clip(HalfSpace<3>::through(b.gradients[j], b.vertices[Simplex<3>::anchor(j)]),
                       kPlaneTolerance))
      return std::numeric_limits<double>::infinity();
  double lowest = std::numeric_limits<double>::infinity();
  for (int v = 0; v < polytope.size(); ++v)
    lowest = std::min(lowest, b.barycentric(i, polytope.vertex(v)));
  return lowest;
}

struct FrontResult {
  std::int64_t fallbacks = 0;
  std::int64_t tests = 0;
  std::int64_t grid_candidates = 0;
};

template <int dim>
FrontResult expect_front_matches_grid(const Mesh& slave, const Mesh& master) {
  // the grid: its pair list, kept where the kernel finds an overlap
  PairSearch<dim> grid(slave, master);
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  std::set<std::pair<int, int>> expected;  // (slave cell, master cell)
  for (int c = 0; c < slave.n_owned_cells; ++c) {
    const Simplex<dim> s = cell_simplex<dim>(slave, c);
    for (int m : grid.pairs_of(c))
      if (local_integrals(s, grid.master_simplices()[m], workspace, local))
        expected.insert({c, grid.master().source_cell[m]});
  }

  SearchOptions options;
  options.front = true;
  PairSearch<dim> front(slave, master, options);
  std::set<std::pair<int, int>> tested, found, finished;
  int last_finished = -1;
  front.sweep(
      [&](int c, const Simplex<dim>& s, int m, unsigned& crossed) {
        EXPECT_TRUE(tested.insert({c, m}).second) << "pair tested twice: " << c << ", " << m;
        const Contact contact =
            local_integrals_contact(s, front.master_simplices()[m], workspace, local);
        crossed = local.crossed_faces_b;
        if (contact != Contact::separated) {  // the bits the kernel cleared are right
          const Simplex<dim>& t = front.master_simplices()[m];
          for (int i = 0; i <= dim; ++i) {
            if ((crossed >> i) & 1u) continue;
            bool plane_crossed = false;  // by a vertex of s
            for (const auto& x : s.vertices)
              plane_crossed = plane_crossed || t.barycentric(i, x) < -kPlaneTolerance;
            if (!plane_crossed) continue;
            // then only because s ∩ t stays off face i (3D clipped pairs)
            EXPECT_EQ(dim, 3);
            EXPECT_EQ(contact, Contact::overlapping);
            if constexpr (dim == 3) {
              EXPECT_GT(lowest_on_intersection(s, t, i), 0.0);
            }
          }
        }
        return contact;
      },
      [&](int c, const Simplex<dim>&, std::span<const int> overlapping) {
        EXPECT_EQ(c, last_finished + 1);  // every owned cell, in order
        last_finished = c;
        for (int m : overlapping) {
          EXPECT_TRUE(tested.count({c, m}));
          found.insert({c, front.master().source_cell[m]});
        }
      });
  EXPECT_EQ(last_finished, slave.n_owned_cells - 1);
  for (int c = 0; c < slave.n_owned_cells; ++c)
    for (int m : front.pairs_of(c)) finished.insert({c, front.master().source_cell[m]});
  EXPECT_EQ(found, finished);
  EXPECT_EQ(static_cast<std::int64_t>(found.size()), front.statistics().pairs);
  EXPECT_EQ(static_cast<std::int64_t>(tested.size()), front.statistics().candidate_pairs);
  EXPECT_FALSE(expected.empty());
  EXPECT_EQ(found, expected);  // exactly the same pairs
  for (const auto& p : expected)
    if (!found.count(p)) ADD_FAILURE() << "front missed pair " << p.first << ", " << p.second;
  for (const auto& p : found)
    if (!expected.count(p)) ADD_FAILURE() << "front found extra " << p.first << ", " << p.second;
  return {front.statistics().front_fallbacks, front.statistics().candidate_pairs,
          grid.statistics().candidate_pairs};
}

TEST(TransferFront, FaceNeighborsMatchDirectCount) {
  for (const Mesh& m : {box(0, 0, 0, 1, 1, 1, 3, 2, 4), square(0, 0, 1, 1, 4, 3)}) {
    const int k = m.dim + 1;
    const std::vector<int> across = face_neighbors(m.dim, m.cells, m.n_vertices());
    ASSERT_EQ(across.size(), m.cells.size());
    for (int c = 0; c < m.n_cells(); ++c)
      for (int i = 0; i < k; ++i) {
        // the cells other than c holding every vertex of face i of c
        std::vector<int> holders;
        for (int d = 0; d < m.n_cells(); ++d) {
          if (d == c) continue;
          int shared = 0;
          for (int a = 0; a < k; ++a)
            if (a != i)
              for (int v : m.cell(d)) shared += v == m.cell(c)[a];
          if (shared == m.dim) holders.push_back(d);
        }
        ASSERT_LE(holders.size(), 1u);
        EXPECT_EQ(across[c * k + i], holders.empty() ? -1 : holders[0]) << c << " face " << i;
      }
  }
}

TEST(TransferFront, SamePairsAsGrid2D) {
  const Mesh slave = square(0, 0, 1, 1, 12, 12);
  // jittered copy: boundaries coincide
  FrontResult r = expect_front_matches_grid<2>(slave, jittered(slave, 1.0 / 12, 0.1));
  EXPECT_LT(r.fallbacks, slave.n_cells() / 2);
  // rotated, inside
  expect_front_matches_grid<2>(slave, rotated(square(0.25, 0.25, 0.75, 0.75, 7, 7), 0.4));
  // rotated and partly outside, finer than the slave
  expect_front_matches_grid<2>(slave, rotated(square(0.3, -0.2, 1.3, 0.7, 17, 13), 0.3));
  // master in two pieces (a slab of cells removed), coarser than the slave
  expect_front_matches_grid<2>(slave,
                               without_slab(rotated(square(0, 0, 1, 1, 7, 7), 0.2), 0, 0.4, 0.6));
}

TEST(TransferFront, SamePairsAsGrid3D) {
  const Mesh slave = box(0, 0, 0, 1, 1, 1, 6, 6, 6);
  FrontResult r = expect_front_matches_grid<3>(slave, jittered(slave, 1.0 / 6, 0.1));
  EXPECT_LT(r.fallbacks, slave.n_cells() / 2);
  EXPECT_LT(r.tests, r.grid_candidates);
  expect_front_matches_grid<3>(
      slave, rotated(box(0.22, 0.22, 0.22, 0.78, 0.78, 0.78, 4, 4, 4), 0.5, {1, 2, 3}));
  expect_front_matches_grid<3>(
      slave, rotated(box(0.3, -0.2, 0.1, 1.2, 0.8, 1.3, 7, 8, 9), 0.4, {1, 1, 0}));
  expect_front_matches_grid<3>(
      slave, without_slab(rotated(box(0, 0, 0, 1, 1, 1, 4, 4, 4), 0.3, {0, 1, 1}), 2, 0.35, 0.6));
  // the slave coarser than the master
  expect_front_matches_grid<3>(box(0, 0, 0, 1, 1, 1, 2, 2, 2),
                               rotated(box(0.1, 0.1, 0.1, 0.9, 0.9, 0.9, 7, 7, 7), 0.3, {1, 2, 3}));
}

/// Two triangles of the unit square linked only through two flat (degenerate) triangles: the
/// second triangle gets its own copies p', q' of the shared diagonal's vertices, and the flat
/// cells (p, q, q'), (p, q', p') join the diagonal (p, q) to (p', q'). Every cell's box is that
/// of a proper cell, and the front must walk through the flat cells to reach the other half.
Mesh linked_by_flat_cells() {
  Mesh m = square(0, 0, 1, 1, 1, 1);
  EXPECT_EQ(m.n_cells(), 2);
  std::vector<int> shared;
  for (int v : m.cell(0))
    for (int w : m.cell(1))
      if (v == w) shared.push_back(v);
  EXPECT_EQ(shared.size(), 2u);
  const int p = shared[0], q = shared[1];
  const int p2 = m.n_vertices(), q2 = p2 + 1;
  for (int v : {p, q}) {
    m.coordinates.push_back(m.point(v)[0]);
    m.coordinates.push_back(m.point(v)[1]);
    m.global_vertex.push_back(static_cast<PetscInt>(m.global_vertex.size()));
    if (!m.original_vertex.empty()) m.original_vertex.push_back(m.original_vertex.back() + 1);
  }
  m.n_owned_vertices = m.n_vertices();
  m.n_global_vertices = m.n_vertices();
  for (int a = 3; a < 6; ++a) {
    if (m.cells[a] == p)
      m.cells[a] = p2;
    else if (m.cells[a] == q)
      m.cells[a] = q2;
  }
  for (int v : {p, q, q2, p, q2, p2}) m.cells.push_back(v);
  for (int c = 0; c < 2; ++c) {
    if (!m.cell_tags.empty()) m.cell_tags.push_back(m.cell_tags[0]);
    if (!m.original_cell.empty()) m.original_cell.push_back(m.original_cell.back() + 1);
  }
  m.n_owned_cells = m.n_cells();
  m.n_global_cells = m.n_cells();
  return m;
}

TEST(TransferFront, WalksThroughFlatCells) {
  const Mesh master = linked_by_flat_cells();
  const std::vector<int> across = face_neighbors(2, master.cells, master.n_vertices());
  for (int i = 0; i < 3; ++i) EXPECT_NE(across[i], 1);  // the halves share no edge
  const Mesh slave = rotated(square(0.05, 0.05, 0.95, 0.95, 6, 6), 0.1);
  expect_front_matches_grid<2>(slave, master);
}

/// B and D of VariationalTransfer (front) against a reference sum over the grid's pair list
/// (the previous pipeline: filter, kernel, then (d+1)² adds per overlapping pair): the same
/// pattern, entries equal to round-off (relative to the row's scale), D likewise.
template <int dim>
void expect_operators_match_grid(const Mesh& slave, const Mesh& master) {
  constexpr int k = dim + 1;
  PairSearch<dim> grid(slave, master);
  std::map<std::pair<PetscInt, PetscInt>, double> b;
  std::map<PetscInt, double> d;
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  for (int c = 0; c < slave.n_owned_cells; ++c) {
    const Simplex<dim> s = cell_simplex<dim>(slave, c);
    for (int m : grid.pairs_of(c)) {
      if (!local_integrals(s, grid.master_simplices()[m], workspace, local)) continue;
      const NodalMatrix<dim> dual = dual_mass(local);
      const NodalVector<dim> dual_integral = dual_integrals(local);
      for (int a = 0; a < k; ++a) {
        const PetscInt row = slave.global_vertex[slave.cell(c)[a]];
        d[row] += dual_integral[a];
        for (int j = 0; j < k; ++j)
          b[{row, grid.master().vertex_global[grid.master().cells[m * k + j]]}] += dual[a][j];
      }
    }
  }
  VariationalTransfer t(slave, master);
  std::size_t n_entries = 0;
  double worst = 0;
  PetscInt lo = 0, hi = 0;
  MatGetOwnershipRange(t.coupling(), &lo, &hi);
  for (PetscInt r = lo; r < hi; ++r) {
    PetscInt n = 0;
    const PetscInt* columns = nullptr;
    const PetscScalar* values = nullptr;
    MatGetRow(t.coupling(), r, &n, &columns, &values);
    double scale = 0;
    for (PetscInt e = 0; e < n; ++e) scale += std::fabs(values[e]);
    for (PetscInt e = 0; e < n; ++e) {
      const auto it = b.find({r, columns[e]});
      if (it == b.end()) {
        ADD_FAILURE() << "entry (" << r << ", " << columns[e] << ") not in the reference";
        continue;
      }
      worst = std::max(worst, std::fabs(values[e] - it->second) / scale);
    }
    n_entries += static_cast<std::size_t>(n);
    MatRestoreRow(t.coupling(), r, &n, &columns, &values);
  }
  EXPECT_EQ(n_entries, b.size());  // no reference entry missing
  EXPECT_LT(worst, 1e-14);
  const PetscScalar* dual = nullptr;
  VecGetArrayRead(t.dual_mass(), &dual);
  for (PetscInt r = lo; r < hi; ++r) {
    const double reference = d.count(r) ? d[r] : 0.0;
    EXPECT_NEAR(dual[r - lo], reference, 1e-14 * std::fabs(reference) + 1e-300) << "row " << r;
  }
  VecRestoreArrayRead(t.dual_mass(), &dual);
}

TEST(TransferFront, OperatorsMatchGridPairList) {
  const Mesh slave3 = box(0, 0, 0, 1, 1, 1, 5, 5, 5);
  expect_operators_match_grid<3>(slave3, jittered(slave3, 0.2, 0.1));
  expect_operators_match_grid<3>(
      slave3, rotated(box(0.3, -0.2, 0.1, 1.2, 0.8, 1.3, 6, 7, 8), 0.4, {1, 1, 0}));
  const Mesh slave2 = square(0, 0, 1, 1, 10, 10);
  expect_operators_match_grid<2>(slave2, jittered(slave2, 0.1, 0.1));
  expect_operators_match_grid<2>(slave2,
                                 without_slab(rotated(square(0, 0, 1, 1, 7, 7), 0.2), 0, 0.4, 0.6));
}

}  // namespace
}  // namespace coapt::transfer
