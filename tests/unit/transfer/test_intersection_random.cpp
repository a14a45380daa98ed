// Random configurations of the element–element intersection against references that do
// not share the clipping code: partitions of an element by a simplex grid, vertex
// enumeration of the half-space system, exact monomial integrals; symmetry, rigid-motion
// invariance, slivers and near-degenerate pairs.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "coapt/transfer/intersection.hpp"
#include "intersection_test_support.hpp"
#include "reference_geometry.hpp"

namespace coapt::transfer {
namespace {

using testing::near_relative;
using testing::random_rotation;
using testing::random_simplex;
using testing::structured_grid;
using testing::transform;
using testing::Vertices;

// ------------------------------------------------------------------------------- partition tests

// Σ over the cells of a grid of |T ∩ cell|, ∫ λ^T_i, ∫ x, ∫ x xᵀ, Σ_j M_ij and the
// quadrature must give the integrals over T itself, because the cells partition the box.
template <int dim>
struct PartitionSums {
  double measure = 0.0;
  NodalVector<dim> integral_t{};
  NodalVector<dim> row_sums{};  // Σ_cells Σ_j ∫ λ^T_i λ^cell_j = ∫ λ^T_i
  Point<dim> first{};
  std::array<Point<dim>, dim> second{};  // ∫ x xᵀ
  double quadrature_measure = 0.0;
  std::array<Point<dim>, dim> quadrature_second{};
  int n_intersecting = 0;
};

template <int dim>
PartitionSums<dim> partition_sums(const Simplex<dim>& t, const std::vector<Vertices<dim>>& cells) {
  PartitionSums<dim> sums;
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  for (const auto& cell_vertices : cells) {
    const auto cell = make_simplex<dim>(cell_vertices);
    if (local_integrals(t, cell, workspace, local)) {
      ++sums.n_intersecting;
      const auto& m = local.moments;
      EXPECT_GT(m.measure, 0.0);
      EXPECT_LE(m.measure, std::fmin(t.measure, cell.measure));
      sums.measure += m.measure;
      for (int i = 0; i <= dim; ++i) {
        sums.integral_t[i] += local.integral_a[i];
        for (int j = 0; j <= dim; ++j) sums.row_sums[i] += local.mass[i][j];
      }
      for (int k = 0; k < dim; ++k) {
        sums.first[k] += m.measure * m.centroid[k];
        for (int l = 0; l < dim; ++l)
          sums.second[k][l] += m.second[k][l] + m.measure * m.centroid[k] * m.centroid[l];
      }
    }
    for (const auto& q : intersection_quadrature(t, cell, workspace)) {
      EXPECT_GT(q.weight, 0.0);
      sums.quadrature_measure += q.weight;
      for (int k = 0; k < dim; ++k)
        for (int l = 0; l < dim; ++l)
          sums.quadrature_second[k][l] += q.weight * q.point[k] * q.point[l];
    }
  }
  return sums;
}

template <int dim>
void check_partition(const Vertices<dim>& vertices, const std::vector<Vertices<dim>>& cells,
                     double rel) {
  const auto t = make_simplex<dim>(vertices);
  const auto sums = partition_sums<dim>(t, cells);
  const double measure = reference::simplex_measure<dim>(vertices);
  EXPECT_GT(sums.n_intersecting, 1);
  EXPECT_TRUE(near_relative(sums.measure, measure, rel, measure));
  EXPECT_TRUE(near_relative(sums.quadrature_measure, measure, rel, measure));
  for (int i = 0; i <= dim; ++i) {
    EXPECT_TRUE(near_relative(sums.integral_t[i], measure / (dim + 1), rel, measure));
    EXPECT_TRUE(near_relative(sums.row_sums[i], measure / (dim + 1), rel, measure));
  }
  for (int k = 0; k < dim; ++k) {
    std::array<int, dim> alpha{};
    alpha[k] = 1;
    EXPECT_TRUE(near_relative(sums.first[k], reference::monomial_integral<dim>(vertices, alpha),
                              rel, measure));
    for (int l = 0; l < dim; ++l) {
      std::array<int, dim> beta = alpha;
      ++beta[l];
      const double exact = reference::monomial_integral<dim>(vertices, beta);
      EXPECT_TRUE(near_relative(sums.second[k][l], exact, rel, measure));
      EXPECT_TRUE(near_relative(sums.quadrature_second[k][l], exact, rel, measure));
    }
  }
}

TEST(TriangleIntersection, PartitionByAGridRecoversTheTriangle) {
  std::mt19937_64 rng(11);
  const auto grid = structured_grid<2>(12);
  const auto jittered = structured_grid<2>(12, 0.1, 5);
  for (int trial = 0; trial < 20; ++trial) {
    const auto t = random_simplex<2>(rng, 0.02, 0.98);
    check_partition<2>(t, grid, 1e-12);
    check_partition<2>(t, jittered, 1e-12);
  }
}

TEST(TetrahedronIntersection, PartitionByAKuhnGridRecoversTheTetrahedron) {
  std::mt19937_64 rng(12);
  const auto grid = structured_grid<3>(6);
  const auto jittered = structured_grid<3>(6, 0.1, 7);
  for (int trial = 0; trial < 12; ++trial) {
    const auto t = random_simplex<3>(rng, 0.02, 0.98);
    check_partition<3>(t, grid, 1e-12);
    check_partition<3>(t, jittered, 1e-12);
  }
}

TEST(TetrahedronIntersection, PartitionWithVerticesOnGridNodesAndFaces) {
  // Vertices on grid nodes, edges along grid edges and diagonals, faces in grid planes.
  const auto grid = structured_grid<3>(4);
  check_partition<3>({{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, grid, 1e-13);
  check_partition<3>({{{0.25, 0.25, 0}, {1, 0.5, 0.25}, {0.5, 1, 0.5}, {0.25, 0.75, 1}}}, grid,
                     1e-13);
  check_partition<3>({{{0.5, 0.5, 0.5}, {1, 0.5, 0.5}, {0.5, 1, 0.5}, {0.5, 0.5, 1}}}, grid, 1e-13);
  const auto grid2 = structured_grid<2>(4);
  check_partition<2>({{{0, 0}, {1, 0}, {0, 1}}}, grid2, 1e-13);
  check_partition<2>({{{0.25, 0.25}, {1, 0.5}, {0.5, 0.75}}}, grid2, 1e-13);
}

TEST(TetrahedronIntersection, UnionOfGridCellsIsFoundExactly) {
  // The Kuhn tetrahedron {1 ≥ x ≥ y ≥ z ≥ 0} is the union of n³ cells of the Kuhn grid:
  // those give exactly their own volume, every other cell (many touch it on a face, an
  // edge or a vertex) gives nothing.
  const int n = 4;
  const auto cells = structured_grid<3>(n);
  const auto t = make_simplex<3>(Vertices<3>{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}}});
  IntersectionWorkspace<3> workspace;
  LocalIntegrals<3> local;
  int inside = 0;
  double total = 0.0;
  const double cell_volume = 1.0 / (6.0 * n * n * n);
  for (const auto& v : cells) {
    if (!local_integrals(t, make_simplex<3>(v), workspace, local)) continue;
    ++inside;
    total += local.measure();
    EXPECT_TRUE(near_relative(local.measure(), cell_volume, 1e-14, cell_volume));
  }
  EXPECT_EQ(inside, n * n * n);
  EXPECT_TRUE(near_relative(total, 1.0 / 6.0, 1e-14, 1.0));
}

TEST(TriangleIntersection, UnionOfGridCellsIsFoundExactly) {
  const int n = 8;
  const auto cells = structured_grid<2>(n);
  const auto t = make_simplex<2>(Vertices<2>{{{0, 0}, {1, 0}, {1, 1}}});
  IntersectionWorkspace<2> workspace;
  LocalIntegrals<2> local;
  int inside = 0;
  for (const auto& v : cells) {
    if (!local_integrals(t, make_simplex<2>(v), workspace, local)) continue;
    ++inside;
    EXPECT_TRUE(near_relative(local.measure(), 0.5 / (n * n), 1e-14, 0.5 / (n * n)));
  }
  EXPECT_EQ(inside, n * n);
}

template <int dim>
void check_mesh_against_itself(int n) {
  // Two copies of the same (jittered) conforming mesh: every cell meets itself and only
  // itself (its neighbours share a face, an edge or a vertex), and Σ M = the mass matrix.
  const auto vertices = structured_grid<dim>(n, 0.1, 9);
  std::vector<Simplex<dim>> cells;
  for (const auto& v : vertices) cells.push_back(make_simplex<dim>(v));
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  double total = 0.0;
  for (std::size_t c = 0; c < cells.size(); ++c)
    for (std::size_t d = 0; d < cells.size(); ++d) {
      const bool found = local_integrals(cells[c], cells[d], workspace, local);
      ASSERT_EQ(found, c == d) << "cells " << c << " and " << d;
      if (!found) continue;
      total += local.measure();
      const auto mass = testing::element_mass<dim>(cells[c].measure);
      for (int i = 0; i <= dim; ++i)
        for (int j = 0; j <= dim; ++j)
          EXPECT_TRUE(near_relative(local.mass[i][j], mass[i][j], 1e-14, cells[c].measure));
    }
  EXPECT_TRUE(near_relative(total, 1.0, 1e-14, 1.0));
}

TEST(TriangleIntersection, MeshAgainstItself) {
  check_mesh_against_itself<2>(8);
}
TEST(TetrahedronIntersection, MeshAgainstItself) {
  check_mesh_against_itself<3>(3);
}

// ------------------------------------------------------------------- against vertex enumeration

template <int dim>
std::vector<std::array<int, dim>> monomials_up_to_degree_two() {
  std::vector<std::array<int, dim>> result;
  result.push_back({});
  for (int k = 0; k < dim; ++k) {
    std::array<int, dim> a{};
    a[k] = 1;
    result.push_back(a);
    for (int l = k; l < dim; ++l) {
      auto b = a;
      ++b[l];
      result.push_back(b);
    }
  }
  return result;
}

template <int dim>
void check_against_reference(unsigned seed, int n_pairs) {
  std::mt19937_64 rng(seed);
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  int n_intersecting = 0, n_clipped = 0;
  for (int pair = 0; pair < n_pairs; ++pair) {
    const auto va = random_simplex<dim>(rng, 0.0, 1.0);
    const auto vb = random_simplex<dim>(rng, 0.0, 1.0);
    const auto a = make_simplex<dim>(va);
    const auto b = make_simplex<dim>(vb);
    const auto pieces = reference::intersection<dim>(va, vb);
    const double exact = reference::sum_over<dim>(pieces, reference::simplex_measure<dim>);
    const double scale = std::fmin(a.measure, b.measure);
    const bool found = local_integrals(a, b, workspace, local);
    if (!found) {
      EXPECT_LE(exact, 1e-12 * scale) << "pair " << pair;
      continue;
    }
    ++n_intersecting;
    n_clipped += local.measure() < scale * (1 - 1e-12);
    EXPECT_TRUE(near_relative(local.measure(), exact, 1e-12, scale)) << "pair " << pair;
    // moments and quadrature against exact monomial integrals on the reference pieces
    const auto points = intersection_quadrature(a, b, workspace);
    for (const auto& alpha : monomials_up_to_degree_two<dim>()) {
      const double expected = reference::sum_over<dim>(
          pieces, [&](const auto& s) { return reference::monomial_integral<dim>(s, alpha); });
      double from_points = 0.0;
      for (const auto& q : points) {
        double value = q.weight;
        for (int k = 0; k < dim; ++k) value *= std::pow(q.point[k], alpha[k]);
        from_points += value;
      }
      // from the moments: ∫1 = |Ω|, ∫x = |Ω| x̄, ∫x_k x_l = S_kl + |Ω| x̄_k x̄_l
      std::array<int, 2> c{-1, -1};
      int degree = 0;
      for (int k = 0; k < dim; ++k)
        for (int p = 0; p < alpha[k]; ++p) c[degree++] = k;
      const auto& m = local.moments;
      double from_moments = m.measure;
      if (degree == 1) from_moments = m.measure * m.centroid[c[0]];
      if (degree == 2)
        from_moments = m.second[c[0]][c[1]] + m.measure * m.centroid[c[0]] * m.centroid[c[1]];
      EXPECT_TRUE(near_relative(from_points, expected, 1e-12, scale)) << "pair " << pair;
      EXPECT_TRUE(near_relative(from_moments, expected, 1e-12, scale)) << "pair " << pair;
    }
    // local integrals against the reference (barycentric coordinates solved independently)
    const auto mass = reference::mass<dim>(pieces, va, vb);
    for (int i = 0; i <= dim; ++i) {
      double integral_a = 0.0, integral_b = 0.0;
      for (int j = 0; j <= dim; ++j) {
        EXPECT_TRUE(near_relative(local.mass[i][j], mass[i][j], 1e-12, scale)) << "pair " << pair;
        integral_a += mass[i][j];  // Σ_j λ^B_j = 1
        integral_b += mass[j][i];
      }
      EXPECT_TRUE(near_relative(local.integral_a[i], integral_a, 1e-12, scale));
      EXPECT_TRUE(near_relative(local.integral_b[i], integral_b, 1e-12, scale));
    }
  }
  EXPECT_GT(n_intersecting, n_pairs / 4);
  EXPECT_GT(n_clipped, n_pairs / 5);
}

TEST(TriangleIntersection, RandomPairsAgainstVertexEnumeration) {
  check_against_reference<2>(21, 400);
}
TEST(TetrahedronIntersection, RandomPairsAgainstVertexEnumeration) {
  check_against_reference<3>(22, 400);
}

// The quadrature points lie in both elements, and integrating λ^A_i λ^B_j and the dual
// ψ^A_i λ^B_j = ((d + 2) λ^A_i − 1) λ^B_j with them (λ solved independently at each point)
// reproduces local_integrals, dual_mass and dual_integrals.
template <int dim>
void check_integrals_against_quadrature(unsigned seed, int n_pairs) {
  std::mt19937_64 rng(seed);
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  for (int pair = 0; pair < n_pairs; ++pair) {
    const auto va = random_simplex<dim>(rng, 0.0, 1.0);
    const auto vb = random_simplex<dim>(rng, 0.0, 1.0);
    const auto a = make_simplex<dim>(va);
    const auto b = make_simplex<dim>(vb);
    if (!local_integrals(a, b, workspace, local)) continue;
    NodalMatrix<dim> mass{}, dual{};
    NodalVector<dim> dual_a{};
    for (const auto& q : intersection_quadrature(a, b, workspace)) {
      const auto la = reference::barycentric<dim>(va, q.point);
      const auto lb = reference::barycentric<dim>(vb, q.point);
      for (int i = 0; i <= dim; ++i) {
        EXPECT_GE(la[i], -1e-12);
        EXPECT_GE(lb[i], -1e-12);
        dual_a[i] += q.weight * ((dim + 2) * la[i] - 1);
        for (int j = 0; j <= dim; ++j) {
          mass[i][j] += q.weight * la[i] * lb[j];
          dual[i][j] += q.weight * ((dim + 2) * la[i] - 1) * lb[j];
        }
      }
    }
    const auto computed_dual = dual_mass(local);
    const auto computed_dual_a = dual_integrals(local);
    const double scale = std::fmin(a.measure, b.measure);
    for (int i = 0; i <= dim; ++i) {
      EXPECT_TRUE(near_relative(computed_dual_a[i], dual_a[i], 1e-12, scale)) << "pair " << pair;
      for (int j = 0; j <= dim; ++j) {
        EXPECT_TRUE(near_relative(local.mass[i][j], mass[i][j], 1e-12, scale)) << "pair " << pair;
        EXPECT_TRUE(near_relative(computed_dual[i][j], dual[i][j], 1e-12, scale))
            << "pair " << pair;
      }
    }
  }
}

TEST(TriangleIntersection, LocalIntegralsMatchTheQuadrature) {
  check_integrals_against_quadrature<2>(91, 300);
}
TEST(TetrahedronIntersection, LocalIntegralsMatchTheQuadrature) {
  check_integrals_against_quadrature<3>(92, 300);
}

// ------------------------------------------------------------------- symmetry and invariance

template <int dim>
void check_symmetry(unsigned seed, int n_pairs) {
  std::mt19937_64 rng(seed);
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> ab, ba;
  for (int pair = 0; pair < n_pairs; ++pair) {
    const auto a = make_simplex<dim>(random_simplex<dim>(rng, 0.0, 1.0));
    const auto b = make_simplex<dim>(random_simplex<dim>(rng, 0.0, 1.0));
    const bool found_ab = local_integrals(a, b, workspace, ab);
    const bool found_ba = local_integrals(b, a, workspace, ba);
    ASSERT_EQ(found_ab, found_ba);
    const double scale = std::fmax(ab.measure(), 1e-3 * std::fmin(a.measure, b.measure));
    EXPECT_TRUE(near_relative(ab.measure(), ba.measure(), 1e-13, scale));
    for (int i = 0; i <= dim; ++i)
      for (int j = 0; j <= dim; ++j)
        EXPECT_TRUE(near_relative(ab.mass[i][j], ba.mass[j][i], 1e-13, scale));
  }
}

TEST(TriangleIntersection, SymmetricInItsArguments) {
  check_symmetry<2>(31, 500);
}
TEST(TetrahedronIntersection, SymmetricInItsArguments) {
  check_symmetry<3>(32, 500);
}

// The public functions clip the smaller element, so (A, B) and (B, A) share their
// arithmetic; this checks the kernels themselves: A clipped by B's faces against B
// clipped by A's faces, two different computations of the same region.
template <int dim>
double clip_by_faces(const Simplex<dim>& s, const Simplex<dim>& by) {
  typename IntersectionWorkspace<dim>::Polytope polytope;
  if constexpr (dim == 2)
    polytope.assign_triangle(s.vertices);
  else
    polytope.assign_tetrahedron(s.vertices);
  for (int j = 0; j <= dim; ++j)
    if (!polytope.clip(
            HalfSpace<dim>::through(by.gradients[j], by.vertices[Simplex<dim>::anchor(j)]),
            kPlaneTolerance))
      return 0.0;
  return polytope.moments().measure;
}

template <int dim>
void check_kernel_symmetry(unsigned seed, int n_pairs) {
  std::mt19937_64 rng(seed);
  double worst = 0.0;
  for (int pair = 0; pair < n_pairs; ++pair) {
    const auto a = make_simplex<dim>(random_simplex<dim>(rng, 0.0, 1.0));
    const auto b = make_simplex<dim>(random_simplex<dim>(rng, 0.0, 1.0));
    const double ab = clip_by_faces(a, b), ba = clip_by_faces(b, a);
    // round-off of the clipped points is relative to the elements, not to A∩B
    const double scale = std::fmin(a.measure, b.measure);
    worst = std::fmax(worst, std::fabs(ab - ba) / scale);
    EXPECT_TRUE(near_relative(ab, ba, 1e-13, scale)) << "pair " << pair;
  }
  std::ostringstream text;
  text << std::scientific << worst;
  ::testing::Test::RecordProperty("worst_relative_difference", text.str());
}

TEST(TriangleIntersection, ClippingEitherTriangleGivesTheSameArea) {
  check_kernel_symmetry<2>(41, 2000);
}
TEST(TetrahedronIntersection, ClippingEitherTetrahedronGivesTheSameVolume) {
  check_kernel_symmetry<3>(42, 2000);
}

template <int dim>
void check_rigid_motion_invariance(unsigned seed, int n_pairs, double offset, double rel) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> before, after;
  for (int pair = 0; pair < n_pairs; ++pair) {
    const auto va = random_simplex<dim>(rng, 0.0, 1.0);
    const auto vb = random_simplex<dim>(rng, 0.0, 1.0);
    const auto rotation = random_rotation<dim>(rng);
    Point<dim> shift;
    for (double& c : shift) c = offset * u(rng);
    const auto a = make_simplex<dim>(va);
    const auto b = make_simplex<dim>(vb);
    const auto ra = make_simplex<dim>(transform<dim>(va, rotation, shift));
    const auto rb = make_simplex<dim>(transform<dim>(vb, rotation, shift));
    const bool found = local_integrals(a, b, workspace, before);
    const bool found_moved = local_integrals(ra, rb, workspace, after);
    const double scale = std::fmin(a.measure, b.measure);
    if (found != found_moved) {  // only for an intersection at round-off level
      EXPECT_LE(std::fmax(before.measure(), after.measure()), 1e-12 * scale);
      continue;
    }
    EXPECT_TRUE(near_relative(before.measure(), after.measure(), rel, scale));
    for (int i = 0; i <= dim; ++i)
      for (int j = 0; j <= dim; ++j)
        EXPECT_TRUE(near_relative(before.mass[i][j], after.mass[i][j], rel, scale));
    // the centroid moves with the element
    Point<dim> moved = shift;
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j) moved[i] += rotation[i][j] * before.moments.centroid[j];
    if (found) {
      for (int k = 0; k < dim; ++k)
        EXPECT_TRUE(near_relative(after.moments.centroid[k], moved[k], 1e2 * rel,
                                  1.0 + offset + scale / std::fmax(before.measure(), 1e-300)));
    }
  }
}

TEST(TriangleIntersection, InvariantUnderRigidMotions) {
  check_rigid_motion_invariance<2>(51, 300, 1.0, 1e-13);
  check_rigid_motion_invariance<2>(52, 100, 1e3, 1e-11);
}
TEST(TetrahedronIntersection, InvariantUnderRigidMotions) {
  check_rigid_motion_invariance<3>(53, 300, 1.0, 1e-13);
  check_rigid_motion_invariance<3>(54, 100, 1e3, 1e-11);
}

// ------------------------------------------------------------------ slivers and near-degenerate

// Nearly flat tetrahedra of the classical bad shapes, of thickness eps relative to size 1,
// with the condition number of their barycentric map (~ 1/eps; 1/eps² for the spindle,
// thin in two directions, whose determinant loses that much to cancellation).
struct Sliver {
  Vertices<3> vertices;
  double condition;
};
std::vector<Sliver> slivers(double eps) {
  return {
      {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, eps}}}, 1 / eps},  // cap: apex over a face
      {{{{0, 0, 0}, {1, 1, 0}, {1, 0, eps}, {0, 1, eps}}}, 1 / eps},    // sliver: near-coplanar
      {{{{0, 0, 0}, {1, 0, 0}, {0.5, eps, 0}, {0.5, 0, eps}}}, 1 / (eps * eps)},  // spindle
      {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1 + eps, 1, eps}}}, 1 / eps},          // spade
      {{{{0, 0, 0}, {eps, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, 1 / eps},  // wedge (short edge)
  };
}

// Valid output for a pair involving slivers: finite, measure in [0, min(|A|, |B|)], and
// the identities M_ij ≥ 0, Σ_i ∫λ^A_i = Σ_j ∫λ^B_j = |A∩B| to the accuracy the
// conditioning allows (λ of a sliver is known to ε_machine · condition).
void check_valid(const LocalIntegrals<3>& local, bool found, double min_measure, double condition) {
  const double rel = 1e-14 * condition;
  EXPECT_TRUE(std::isfinite(local.measure()));
  EXPECT_GE(local.measure(), 0.0);
  EXPECT_LE(local.measure(), min_measure);
  if (!found) {
    EXPECT_EQ(local.measure(), 0.0);
  }
  double total_a = 0.0, total_b = 0.0;
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(std::isfinite(local.integral_a[i]));
    total_a += local.integral_a[i];
    total_b += local.integral_b[i];
    for (int j = 0; j < 4; ++j) {
      EXPECT_TRUE(std::isfinite(local.mass[i][j]));
      EXPECT_GE(local.mass[i][j], -rel * local.measure());
    }
  }
  EXPECT_NEAR(total_a, local.measure(), rel * local.measure());
  EXPECT_NEAR(total_b, local.measure(), rel * local.measure());
}

TEST(TetrahedronIntersection, SliversGiveFiniteBoundedResults) {
  std::mt19937_64 rng(61);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  IntersectionWorkspace<3> workspace;
  LocalIntegrals<3> local;
  for (double eps : {1e-2, 1e-5, 1e-8, 1e-11, 1e-13}) {
    for (const auto& sliver : slivers(eps)) {
      for (int trial = 0; trial < 40; ++trial) {
        const auto rotation = random_rotation<3>(rng);
        const auto a =
            make_simplex<3>(transform<3>(sliver.vertices, rotation, {u(rng), u(rng), u(rng)}));
        std::vector<Sliver> partners = {{random_simplex<3>(rng, -0.5, 0.5), 1.0}};
        for (const auto& other : slivers(eps * (trial % 3 + 1)))
          partners.push_back(
              {transform<3>(other.vertices, random_rotation<3>(rng), {u(rng), u(rng), u(rng)}),
               other.condition});
        partners.push_back({a.vertices, sliver.condition});  // itself
        Vertices<3> shifted = a.vertices;  // itself, moved by a fraction of its thickness
        for (auto& p : shifted) p[2] += 0.1 * eps;
        partners.push_back({shifted, sliver.condition});
        for (const auto& [vb, condition] : partners) {
          const auto b = make_simplex<3>(vb);
          const double limit = std::fmin(a.measure, b.measure);
          const double worst = std::fmax(condition, sliver.condition);
          check_valid(local, local_integrals(a, b, workspace, local), limit, worst);
          check_valid(local, local_integrals(b, a, workspace, local), limit, worst);
          for (const auto& q : intersection_quadrature(a, b, workspace)) {
            EXPECT_GT(q.weight, 0.0);
            for (double c : q.point) EXPECT_TRUE(std::isfinite(c));
          }
        }
      }
    }
  }
}

TEST(TetrahedronIntersection, SliverPartitionByAGrid) {
  // A sliver swept through a Kuhn grid: its volume is recovered to the accuracy its own
  // conditioning allows (relative round-off ~ 1e-16 / thickness).
  const auto grid = structured_grid<3>(6, 0.1, 3);
  for (double eps : {1e-3, 1e-6}) {
    const Vertices<3> t{
        {{0.1, 0.15, 0.2}, {0.9, 0.85, 0.3}, {0.85, 0.1, 0.6 + eps}, {0.15, 0.9, 0.5 + eps}}};
    const auto s = make_simplex<3>(t);
    const auto sums = partition_sums<3>(s, grid);
    EXPECT_TRUE(near_relative(sums.measure, s.measure, 1e-13 / eps, s.measure));
    for (int i = 0; i < 4; ++i)
      EXPECT_TRUE(near_relative(sums.integral_t[i], s.measure / 4, 1e-13 / eps, s.measure));
  }
}

TEST(TriangleIntersection, ThinTrianglesGiveFiniteBoundedResults) {
  std::mt19937_64 rng(62);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  IntersectionWorkspace<2> workspace;
  LocalIntegrals<2> local;
  for (double eps : {1e-3, 1e-7, 1e-11, 1e-13}) {
    const Vertices<2> thin{{{0, 0}, {1, 0}, {0.4, eps}}};
    for (int trial = 0; trial < 200; ++trial) {
      const auto a = make_simplex<2>(transform<2>(thin, random_rotation<2>(rng), {u(rng), u(rng)}));
      const auto b = make_simplex<2>(
          trial % 2 ? random_simplex<2>(rng, -0.5, 0.5)
                    : transform<2>(thin, random_rotation<2>(rng), {u(rng) * 0.1, u(rng) * 0.1}));
      const bool found = local_integrals(a, b, workspace, local);
      EXPECT_TRUE(std::isfinite(local.measure()));
      EXPECT_GE(local.measure(), 0.0);
      EXPECT_LE(local.measure(), std::fmin(a.measure, b.measure));
      if (!found) {
        EXPECT_EQ(local.measure(), 0.0);
      }
      for (const auto& row : local.mass)
        for (double value : row) EXPECT_TRUE(std::isfinite(value));
    }
  }
}

// Pairs at round-off distance from touching, from coinciding and from sharing a face: the
// result is either nothing or a sensible value, never NaN, negative or above min(|A|, |B|).
template <int dim>
void check_near_degenerate(unsigned seed) {
  std::mt19937_64 rng(seed);
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  for (int trial = 0; trial < 300; ++trial) {
    const auto va = random_simplex<dim>(rng, 0.0, 1.0);
    const auto a = make_simplex<dim>(va);
    const double noise = std::pow(10.0, -16.0 + (trial % 6));  // 1e-16 .. 1e-11
    std::uniform_real_distribution<double> u(-noise, noise);
    // (1) a copy of A with noisy vertices: |A∩B| ≈ |A|
    Vertices<dim> copy = va;
    for (auto& p : copy)
      for (double& c : p) c += u(rng);
    // (2) A reflected through the plane of its face 0, with noise: touching on a face
    Vertices<dim> mirror = va;
    {
      const auto& g = a.gradients[0];
      double g2 = 0.0;
      for (double c : g) g2 += c * c;
      const double lambda = a.barycentric(0, va[0]);  // = 1
      for (int k = 0; k < dim; ++k) mirror[0][k] = va[0][k] - 2 * lambda * g[k] / g2 + u(rng);
      for (int v = 1; v <= dim; ++v)
        for (double& c : mirror[v]) c += u(rng);
    }
    // (3) A shrunk towards a vertex: inside, sharing faces up to noise
    Vertices<dim> shrunk = va;
    for (int v = 1; v <= dim; ++v)
      for (int k = 0; k < dim; ++k) shrunk[v][k] = va[0][k] + 0.5 * (va[v][k] - va[0][k]) + u(rng);
    const std::array<double, 3> expected{a.measure, 0.0, a.measure / (1 << dim)};
    const std::array<const Vertices<dim>*, 3> partners{&copy, &mirror, &shrunk};
    for (int p = 0; p < 3; ++p) {
      const auto b = make_simplex<dim>(*partners[p]);
      for (const bool swap : {false, true}) {
        const bool found = swap ? local_integrals(b, a, workspace, local)
                                : local_integrals(a, b, workspace, local);
        ASSERT_TRUE(std::isfinite(local.measure()));
        EXPECT_GE(local.measure(), 0.0);
        EXPECT_LE(local.measure(), std::fmin(a.measure, b.measure));
        EXPECT_NEAR(local.measure(), expected[p], 1e3 * noise * a.measure + 1e-15 * a.measure)
            << "trial " << trial << " partner " << p;
        if (found) {
          for (const auto& row : local.mass)
            for (double value : row) EXPECT_TRUE(std::isfinite(value));
        }
      }
    }
  }
}

TEST(TriangleIntersection, NearDegeneratePairs) {
  check_near_degenerate<2>(71);
}
TEST(TetrahedronIntersection, NearDegeneratePairs) {
  check_near_degenerate<3>(72);
}

}  // namespace
}  // namespace coapt::transfer
