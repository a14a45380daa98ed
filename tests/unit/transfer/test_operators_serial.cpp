// The transfer pipeline on one rank: the search stages alone (exchange, grid, pair list
// against brute force), then the operators B, D, T on structured meshes that are shifted,
// rotated, of very different resolution (1:10 both ways) and only partly overlapping, in 2D
// and 3D: sum of B = overlap volume, row sums of B = D, T exact for constant and linear
// fields on the constrained nodes, the standard variant, and re-assembly after a motion.

#include <gtest/gtest.h>
#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <set>
#include <utility>

#include "../../support/mesh_transforms.hpp"
#include "coapt/core/petsc.hpp"
#include "coapt/mesh/generators.hpp"
#include "coapt/transfer/intersection.hpp"
#include "coapt/transfer/operators.hpp"
#include "coapt/transfer/search.hpp"

namespace coapt::transfer {
namespace {

using mesh::Mesh;

// ---- meshes --------------------------------------------------------------------------------

Mesh square(double x0, double y0, double x1, double y1, int nx, int ny) {
  return mesh::structured_rectangle(x0, y0, x1, y1, nx, ny);
}
Mesh box(double x0, double y0, double z0, double x1, double y1, double z1, int nx, int ny, int nz) {
  return mesh::structured_box(x0, y0, z0, x1, y1, z1, nx, ny, nz);
}

using coapt::testing::rotated;

// ---- vectors -------------------------------------------------------------------------------

using Field = std::function<double(const double*)>;

/// Vector in the mesh's layout with f at each owned vertex.
OwnedVec interpolate(const Mesh& m, const OwnedVec& layout, const Field& f) {
  OwnedVec v;
  VecDuplicate(layout, v.out());
  PetscScalar* x = nullptr;
  VecGetArray(v, &x);
  for (int i = 0; i < m.n_owned_vertices; ++i) x[i] = f(m.point(i).data());
  VecRestoreArray(v, &x);
  return v;
}

/// Largest |T f_M − f| over the constrained nodes (owned by this rank).
double transfer_error(const VariationalTransfer& t, const Mesh& slave, const Mesh& master,
                      const Field& f, bool standard = false) {
  OwnedVec layout_m = t.create_master_vector();
  OwnedVec fm = interpolate(master, layout_m, f);
  OwnedVec fs = t.create_slave_vector();
  VecSet(fs, 1e30);  // rows T does not define stay untouched
  if (standard)
    t.apply_standard_transfer(fm, fs);
  else
    t.apply_transfer(fm, fs);
  const PetscScalar* x = nullptr;
  VecGetArrayRead(fs, &x);
  double error = 0;
  for (PetscInt row : t.constrained_rows()) {
    const int i = static_cast<int>(row - slave.vertex_offset);
    error = std::max(error, std::fabs(x[i] - f(slave.point(i).data())));
  }
  VecRestoreArrayRead(fs, &x);
  return error;
}

/// Σ_ij B_ij.
double matrix_sum(Mat b) {
  OwnedVec ones, sums;
  MatCreateVecs(b, ones.out(), sums.out());
  VecSet(ones, 1.0);
  MatMult(b, ones, sums);
  PetscScalar total = 0;
  VecSum(sums, &total);
  return total;
}

/// max_i |Σ_j B_ij − D_i| / Σ_j |B_ij|.
double row_sum_defect(Mat b, Vec d) {
  OwnedVec ones, sums;
  MatCreateVecs(b, ones.out(), sums.out());
  VecSet(ones, 1.0);
  MatMult(b, ones, sums);
  PetscInt lo = 0, hi = 0;
  MatGetOwnershipRange(b, &lo, &hi);
  const PetscScalar *s = nullptr, *dd = nullptr;
  VecGetArrayRead(sums, &s);
  VecGetArrayRead(d, &dd);
  double worst = 0;
  for (PetscInt r = lo; r < hi; ++r) {
    PetscInt n = 0;
    const PetscScalar* values = nullptr;
    MatGetRow(b, r, &n, nullptr, &values);
    double scale = 0;
    for (PetscInt e = 0; e < n; ++e) scale += std::fabs(values[e]);
    MatRestoreRow(b, r, &n, nullptr, &values);
    if (scale > 0) {
      worst = std::max(worst, std::fabs(s[r - lo] - dd[r - lo]) / scale);
    } else {
      EXPECT_EQ(dd[r - lo], 0.0);
    }
  }
  VecRestoreArrayRead(d, &dd);
  VecRestoreArrayRead(sums, &s);
  return worst;
}

const Field kConstant = [](const double*) { return 1.5; };
Field linear(int dim) {
  if (dim == 2) return [](const double* x) { return 0.3 + 1.7 * x[0] - 0.9 * x[1]; };
  return [](const double* x) { return 0.3 + 1.7 * x[0] - 0.9 * x[1] + 0.6 * x[2]; };
}

/// The checks every configuration must pass; `overlap` is |S ∩ M| computed independently.
void check_operators(const Mesh& slave, const Mesh& master, double overlap,
                     bool expect_constrained = true) {
  VariationalTransfer t(slave, master, {.standard = true});
  const double sum_b = matrix_sum(t.coupling());
  EXPECT_NEAR(sum_b, overlap, 1e-12 * overlap);
  PetscScalar d_sum = 0;
  VecSum(t.dual_mass(), &d_sum);
  EXPECT_NEAR(d_sum, overlap, 1e-12 * overlap);  // Σ_i ψ_i = 1
  const double defect = row_sum_defect(t.coupling(), t.dual_mass());
  EXPECT_LT(defect, 1e-12);
  if (expect_constrained) {
    EXPECT_GT(t.n_constrained(), 0);
  }
  const double constant_error = transfer_error(t, slave, master, kConstant);
  const double linear_error = transfer_error(t, slave, master, linear(slave.dim));
  EXPECT_LT(constant_error, 1e-12);
  EXPECT_LT(linear_error, 1e-12);
  // the standard variant: Σ B^std = |Ω| too, and exact for linear fields where covered
  EXPECT_NEAR(matrix_sum(t.standard_coupling()), overlap, 1e-12 * overlap);
  {  // Σ_ij M_S,ij = |Ω| + the unit diagonal of the rows without overlap (c_i = 0)
    const PetscScalar* c = nullptr;
    VecGetArrayRead(t.coverage(), &c);
    int uncovered = 0;
    for (int v = 0; v < slave.n_owned_vertices; ++v) uncovered += c[v] == 0.0;
    VecRestoreArrayRead(t.coverage(), &c);
    EXPECT_NEAR(matrix_sum(t.overlap_mass()), overlap + uncovered, 1e-12 * (overlap + uncovered));
  }
  const double standard_error = transfer_error(t, slave, master, linear(slave.dim), true);
  EXPECT_LT(standard_error, 1e-9);
  // the explicit T agrees with apply_transfer
  OwnedMat explicit_t = t.explicit_transfer();
  OwnedVec fm = interpolate(master, t.create_master_vector(), linear(slave.dim));
  OwnedVec a = t.create_slave_vector(), b = t.create_slave_vector();
  VecSet(a, 0.0);
  t.apply_transfer(fm, a);
  MatMult(explicit_t, fm, b);
  VecAXPY(b, -1.0, a);
  PetscReal difference = 0;
  VecNorm(b, NORM_INFINITY, &difference);
  EXPECT_LT(difference, 1e-13);
  // coverage: constrained nodes are covered, nothing exceeds 1
  PetscReal most = 0;
  VecMax(t.coverage(), nullptr, &most);
  EXPECT_LT(most, 1.0 + 1e-12);
  {  // the cells' covered fractions: in [0, 1], and Σ_T |T| f_T = |Ω|
    const auto& fraction = t.cell_coverage();
    ASSERT_EQ(fraction.size(), static_cast<std::size_t>(slave.n_owned_cells));
    double covered = 0;
    for (int c = 0; c < slave.n_owned_cells; ++c) {
      EXPECT_GE(fraction[c], 0.0);
      EXPECT_LT(fraction[c], 1.0 + 1e-12);
      covered += fraction[c] * std::fabs(mesh::cell_signed_measure(slave, c));
    }
    EXPECT_NEAR(covered, overlap, 1e-12 * overlap);
  }
  if (std::getenv("COAPT_TRANSFER_REPORT"))  // the figures of docs/verification/transfer.md
    std::printf(
        "[transfer] %s: %d/%d slave/master cells, %lld pairs, |sum B - overlap|/overlap %.1e, "
        "row-sum defect %.1e, constrained %d, T const %.1e, T linear %.1e, standard linear %.1e\n",
        ::testing::UnitTest::GetInstance()->current_test_info()->name(), slave.n_cells(),
        master.n_cells(), static_cast<long long>(t.statistics().intersecting_pairs),
        std::fabs(sum_b - overlap) / overlap, defect, static_cast<int>(t.n_constrained()),
        constant_error, linear_error, standard_error);
}

// ---- stages 1-2 alone ----------------------------------------------------------------------

TEST(TransferSearch, GridQueryMatchesBruteForce) {
  const Mesh master = rotated(box(0.1, 0.2, 0.05, 0.9, 0.7, 0.8, 5, 4, 6), 0.4, {1, 2, 3});
  std::vector<Box<3>> boxes;
  for (int c = 0; c < master.n_cells(); ++c)
    boxes.push_back(Box<3>::of(cell_simplex<3>(master, c)));
  BoxGrid<3> grid;
  grid.build(boxes);
  const Mesh slave = box(0, 0, 0, 1, 1, 1, 4, 3, 5);
  for (int c = 0; c < slave.n_cells(); ++c) {
    const Box<3> q = Box<3>::of(cell_simplex<3>(slave, c));
    std::vector<int> found, expected;
    grid.query(q, [&](int i) { found.push_back(i); });
    for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
      if (boxes[i].overlaps(q)) expected.push_back(i);
    std::sort(found.begin(), found.end());
    ASSERT_EQ(found, expected) << "slave cell " << c;  // each once
  }
}

TEST(TransferSearch, GridQueryMatchesBruteForceWithMixedSizes) {
  // Boxes of a fine mesh (small: stored once, by lower corner), a few large ones (listed in
  // every bin they overlap), flat and empty ones; queries of every size, touching included.
  const Mesh master = rotated(box(0.1, 0.2, 0.05, 0.9, 0.7, 0.8, 6, 5, 7), 0.4, {1, 2, 3});
  std::vector<Box<3>> boxes;
  for (int c = 0; c < master.n_cells(); ++c)
    boxes.push_back(Box<3>::of(cell_simplex<3>(master, c)));
  boxes.push_back(Box<3>{{0.0, 0.0, 0.0}, {0.6, 0.3, 0.9}});
  boxes.push_back(Box<3>{{0.5, 0.1, 0.2}, {0.55, 0.9, 0.25}});
  boxes.push_back(Box<3>{{0.3, 0.3, 0.3}, {0.3, 0.3, 0.7}});  // flat
  boxes.push_back(Box<3>::empty());
  boxes.push_back(Box<3>{{-0.2, 0.4, 0.4}, {1.2, 0.45, 0.45}});
  BoxGrid<3> grid;
  grid.build(boxes);
  std::vector<Box<3>> queries;
  const Mesh slave = box(0, 0, 0, 1, 1, 1, 9, 7, 8);
  for (int c = 0; c < slave.n_cells(); ++c)
    queries.push_back(Box<3>::of(cell_simplex<3>(slave, c)));
  queries.push_back(Box<3>{{0.2, 0.2, 0.2}, {0.8, 0.8, 0.8}});
  queries.push_back(Box<3>{{0.6, 0.3, 0.9}, {0.7, 0.4, 1.0}});  // touches a corner
  queries.push_back(Box<3>{{-1, -1, -1}, {2, 2, 2}});
  queries.push_back(boxes[7]);
  for (std::size_t q = 0; q < queries.size(); ++q) {
    std::vector<int> found, expected;
    grid.query(queries[q], [&](int i) { found.push_back(i); });
    for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
      if (!boxes[i].is_empty() && boxes[i].overlaps(queries[q])) expected.push_back(i);
    std::sort(found.begin(), found.end());
    ASSERT_EQ(found, expected) << "query " << q;  // each once
  }
}

TEST(TransferSearch, ExchangeSendsWhatOverlaps) {
  const Mesh master = box(0.5, 0.5, 0.5, 1.5, 1.5, 1.5, 3, 3, 3);
  MasterExchange<3> exchange;
  const std::vector<Box<3>> slave_boxes = {Box<3>{{0, 0, 0}, {1, 1, 1}}};
  exchange.exchange(master, MPI_COMM_SELF, slave_boxes, 0.0);
  const ReceivedMaster<3>& received = exchange.received();
  int expected = 0;
  for (int c = 0; c < master.n_cells(); ++c)
    if (Box<3>::of(cell_simplex<3>(master, c)).overlaps(slave_boxes[0])) ++expected;
  EXPECT_EQ(received.n_cells(), expected);
  EXPECT_TRUE(std::is_sorted(received.vertex_global.begin(), received.vertex_global.end()));
  for (int c = 0; c < received.n_cells(); ++c) {
    EXPECT_EQ(received.source_rank[c], 0);
    const auto vertices = master.cell(received.source_cell[c]);
    for (int a = 0; a < 4; ++a) {
      const int v = received.cells[c * 4 + a];
      EXPECT_EQ(received.vertex_global[v], master.global_vertex[vertices[a]]);
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(received.coordinates[v * 3 + k], master.point(vertices[a])[k]);
    }
  }
}

template <int dim>
void expect_pairs_complete(const Mesh& slave, const Mesh& master) {
  PairSearch<dim> search(slave, master);
  const auto& received = search.master();
  Box<dim> slave_box = owned_cells_box<dim>(slave);
  int reaching = 0;  // master cells whose box reaches the slave's box: all sent
  for (int m = 0; m < master.n_cells(); ++m)
    reaching += Box<dim>::of(cell_simplex<dim>(master, m)).overlaps(slave_box);
  ASSERT_EQ(received.n_cells(), reaching);
  std::set<std::pair<int, int>> listed;
  for (int c = 0; c < slave.n_owned_cells; ++c)
    for (int m : search.pairs_of(c)) listed.insert({c, received.source_cell[m]});
  EXPECT_EQ(listed.size(), static_cast<std::size_t>(search.statistics().pairs));  // no repeats
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  std::int64_t intersecting = 0, candidates = 0;
  for (int c = 0; c < slave.n_cells(); ++c)
    for (int m = 0; m < master.n_cells(); ++m) {
      const Simplex<dim> s = cell_simplex<dim>(slave, c), t = cell_simplex<dim>(master, m);
      if (Box<dim>::of(s).overlaps(Box<dim>::of(t)) && !s.degenerate()) ++candidates;
      if (local_integrals(s, t, workspace, local)) {
        ++intersecting;
        EXPECT_TRUE(listed.count({c, m})) << "missed pair " << c << ", " << m;
      }
    }
  EXPECT_EQ(search.statistics().candidate_pairs, candidates);
  EXPECT_LE(intersecting, search.statistics().pairs);
}

TEST(TransferSearch, PairListHoldsEveryIntersectingPair2D) {
  expect_pairs_complete<2>(square(0, 0, 1, 1, 7, 6),
                           rotated(square(0.2, -0.1, 1.1, 0.8, 9, 8), 0.3));
  expect_pairs_complete<2>(square(0, 0, 1, 1, 6, 6), square(0, 0, 1, 1, 6, 6));  // coincident
}

TEST(TransferSearch, PairListHoldsEveryIntersectingPair3D) {
  expect_pairs_complete<3>(box(0, 0, 0, 1, 1, 1, 3, 3, 3),
                           rotated(box(0.1, 0.1, 0.1, 0.9, 0.9, 1.1, 4, 4, 4), 0.5, {1, 1, 0}));
  expect_pairs_complete<3>(box(0, 0, 0, 1, 1, 1, 3, 3, 3), box(0, 0, 0, 1, 1, 1, 3, 3, 3));
}

// ---- operators -----------------------------------------------------------------------------

TEST(TransferOperators, ShiftedPartlyInside2D) {
  // master sticks out of the slave on two sides: overlap is the box intersection
  check_operators(square(0, 0, 1, 1, 10, 10), square(0.25, -0.15, 1.3, 0.7, 13, 9), 0.75 * 0.7);
}

TEST(TransferOperators, RotatedInside2D) {
  check_operators(square(0, 0, 1, 1, 12, 12), rotated(square(0.3, 0.3, 0.7, 0.7, 7, 7), 0.5236),
                  0.16);
}

TEST(TransferOperators, CoarseSlaveFineMaster2D) {
  check_operators(square(0, 0, 1, 1, 4, 4), rotated(square(-0.2, -0.2, 1.2, 1.2, 56, 56), 0.01),
                  1.0);
}

TEST(TransferOperators, FineSlaveCoarseMaster2D) {
  check_operators(square(0, 0, 1, 1, 50, 50), rotated(square(0.2, 0.2, 0.8, 0.8, 3, 3), 0.7), 0.36);
}

TEST(TransferOperators, CoincidentMeshes2D) {
  // identical meshes: every pair touches or coincides; B is D (diagonal, lumped) exactly
  check_operators(square(0, 0, 1, 1, 8, 8), square(0, 0, 1, 1, 8, 8), 1.0);
}

TEST(TransferOperators, ShiftedPartlyInside3D) {
  check_operators(box(0, 0, 0, 1, 1, 1, 6, 6, 6), box(0.2, -0.1, 0.15, 1.3, 0.8, 0.95, 7, 6, 5),
                  0.8 * 0.8 * 0.8);
}

TEST(TransferOperators, RotatedInside3D) {
  check_operators(box(0, 0, 0, 1, 1, 1, 10, 10, 10),
                  rotated(box(0.25, 0.25, 0.25, 0.75, 0.75, 0.75, 5, 5, 5), 0.7, {1, 2, 3}), 0.125);
}

TEST(TransferOperators, CoarseSlaveFineMaster3D) {
  check_operators(box(0, 0, 0, 1, 1, 1, 2, 2, 2),
                  rotated(box(-0.3, -0.3, -0.3, 1.3, 1.3, 1.3, 32, 32, 32), 0.02, {2, 1, 3}), 1.0);
}

TEST(TransferOperators, FineSlaveCoarseMaster3D) {
  check_operators(box(0, 0, 0, 1, 1, 1, 20, 20, 20),
                  rotated(box(0.25, 0.25, 0.25, 0.75, 0.75, 0.75, 1, 1, 1), 0.9, {1, -1, 2}),
                  0.125);  // half-diagonal 0.433 < 0.5: inside for any rotation
}

TEST(TransferOperators, CoincidentMeshes3D) {
  check_operators(box(0, 0, 0, 1, 1, 1, 4, 4, 4), box(0, 0, 0, 1, 1, 1, 4, 4, 4), 1.0);
}

TEST(TransferOperators, CoveredNodeRule) {
  // master covers x ≤ 0.55 of the unit square (h = 0.1): nodes with x ≤ 0.4 have their whole
  // support covered; nodes at x = 0.5 are partly covered and are not constrained, nor those
  // beyond; lowering the threshold admits them.
  const Mesh slave = square(0, 0, 1, 1, 10, 10);
  const Mesh master = square(-0.5, -0.5, 0.55, 1.5, 11, 20);
  VariationalTransfer t(slave, master);
  for (PetscInt row : t.constrained_rows()) EXPECT_LE(slave.point(row)[0], 0.4 + 1e-12);
  EXPECT_EQ(t.n_constrained(), 5 * 11);
  const PetscScalar* c = nullptr;
  VecGetArrayRead(t.coverage(), &c);
  for (int v = 0; v < slave.n_owned_vertices; ++v) {
    const double x = slave.point(v)[0];
    if (x < 0.45) {
      EXPECT_NEAR(c[v], 1.0, 1e-14);
    }
    if (x > 0.65) {
      EXPECT_EQ(c[v], 0.0);
    }
    if (std::fabs(x - 0.5) < 1e-12) {
      EXPECT_GT(c[v], 0.5);
      EXPECT_LT(c[v], 1.0);
    }
  }
  VecRestoreArrayRead(t.coverage(), &c);
  // the cells: whole left of x = 0.5, none right of 0.6, and half the column between
  double column = 0;
  for (int c = 0; c < slave.n_owned_cells; ++c) {
    double lo = 1, hi = 0;
    for (const int v : slave.cell(c)) {
      lo = std::min(lo, slave.point(v)[0]);
      hi = std::max(hi, slave.point(v)[0]);
    }
    const double f = t.cell_coverage()[c];
    if (hi < 0.5 + 1e-12) {
      EXPECT_NEAR(f, 1.0, 1e-14);
    } else if (lo > 0.6 - 1e-12) {
      EXPECT_EQ(f, 0.0);
    } else {
      EXPECT_GT(f, 0.0);
      EXPECT_LT(f, 1.0);
      column += f * std::fabs(mesh::cell_signed_measure(slave, c));
    }
  }
  EXPECT_NEAR(column, 0.05, 1e-14);
  VariationalTransfer loose(slave, master, {.coverage_threshold = 0.5});
  EXPECT_EQ(loose.n_constrained(), 6 * 11);
}

TEST(TransferOperators, ReassemblyAfterMotion) {
  const Mesh slave = box(0, 0, 0, 1, 1, 1, 6, 6, 6);
  Mesh master = rotated(box(0.2, 0.2, 0.2, 0.8, 0.8, 0.8, 5, 5, 5), 0.3, {1, 1, 1});
  VariationalTransfer moving(slave, master, {.search_margin = 0.01});
  PetscReal before = 0, after = 0;
  MatNorm(moving.coupling(), NORM_FROBENIUS, &before);
  moving.update_master(master);  // not moved: everything reused, the same values
  EXPECT_FALSE(moving.statistics().search.full);
  EXPECT_TRUE(moving.statistics().pattern_reused);
  MatNorm(moving.coupling(), NORM_FROBENIUS, &after);
  EXPECT_EQ(before, after);
  for (int step = 1; step <= 3; ++step) {
    // 0.004 per step along x and a wobble of at most 0.0005: within the margin for two steps
    for (std::size_t i = 0; i < master.coordinates.size(); ++i)
      master.coordinates[i] += (i % 3 == 0 ? 0.004 : 0.0) + 0.0005 * std::sin(3.0 * i + step);
    moving.update_master(master);
    EXPECT_EQ(moving.statistics().search.full, step == 3);
    VariationalTransfer fresh(slave, master);
    Mat a = moving.coupling(), b = fresh.coupling();
    PetscReal na = 0, nb = 0;
    MatNorm(a, NORM_FROBENIUS, &na);
    MatNorm(b, NORM_FROBENIUS, &nb);
    EXPECT_NEAR(na, nb, 1e-14 * nb);
    OwnedMat difference;
    MatDuplicate(a, MAT_COPY_VALUES, difference.out());
    MatAXPY(difference, -1.0, b, DIFFERENT_NONZERO_PATTERN);
    PetscReal nd = 0;
    MatNorm(difference, NORM_FROBENIUS, &nd);
    EXPECT_LT(nd, 1e-15 * nb);
    EXPECT_EQ(moving.n_constrained(), fresh.n_constrained());
    EXPECT_LT(transfer_error(moving, slave, master, linear(3)), 1e-12);
  }
}

TEST(TransferOperators, DisjointMeshesGiveEmptyOperators) {
  VariationalTransfer t(square(0, 0, 1, 1, 4, 4), square(2, 2, 3, 3, 4, 4));
  EXPECT_EQ(t.n_constrained(), 0);
  EXPECT_EQ(matrix_sum(t.coupling()), 0.0);
  EXPECT_EQ(t.statistics().intersecting_pairs, 0);
}

}  // namespace
}  // namespace coapt::transfer
