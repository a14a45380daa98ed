// Mortar geometry and integration for contact: the dual basis (biorthogonality, partition of
// unity, boundary modification), exactness of the segment and projected-triangle integrals,
// and the operators D, D̂, M and the weighted gaps on flat, tilted and non-matching surfaces
// in 2D and 3D, against closed-form answers.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numeric>
#include <vector>

#include "../../support/mesh_transforms.hpp"
#include "coapt/contact/mortar.hpp"
#include "coapt/contact/surface.hpp"
#include "coapt/mesh/generators.hpp"

namespace coapt::contact {
namespace {

// ∫_T f g for affine f, g on a simplex with n vertices (values f_i, g_i at the vertices):
// |T| (Σ f_i g_i + Σ f_i Σ g_i) / (n (n + 1)).
double affine_product_integral(double measure, const std::vector<double>& f,
                               const std::vector<double>& g) {
  const double n = static_cast<double>(f.size());
  double diagonal = 0, sf = 0, sg = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    diagonal += f[i] * g[i];
    sf += f[i];
    sg += g[i];
  }
  return measure * (diagonal + sf * sg) / (n * (n + 1));
}

TEST(DualBasis, BiorthogonalAndPartitionOfUnity) {
  for (int n : {2, 3}) {
    const auto A = dual_coefficients(n, {true, true, true});
    for (int a = 0; a < n; ++a)
      for (int k = 0; k < n; ++k) {
        // ∫ Φ_a N_k over a facet of measure 1: Σ_b A_ab (1 + δ_bk) / (n (n + 1)).
        double value = 0;
        for (int b = 0; b < n; ++b) value += A[a][b] * (b == k ? 2.0 : 1.0) / (n * (n + 1));
        EXPECT_NEAR(value, a == k ? 1.0 / n : 0.0, 1e-15) << "n " << n << " a " << a;
      }
    for (int b = 0; b < n; ++b) {
      double sum = 0;
      for (int a = 0; a < n; ++a) sum += A[a][b];
      EXPECT_NEAR(sum, 1.0, 1e-15);  // Σ_a Φ_a = Σ_b N_b = 1
    }
  }
}

TEST(DualBasis, BoundaryModificationKeepsBiorthogonalityToMultiplierNodes) {
  // Triangle with vertex 2 on the surface boundary; segment with vertex 0 on it.
  for (int n : {2, 3}) {
    std::array<bool, 3> carries = {true, true, true};
    const int boundary = n == 3 ? 2 : 0;
    carries[boundary] = false;
    const auto A = dual_coefficients(n, carries);
    for (int b = 0; b < n; ++b) {
      double sum = 0;
      for (int a = 0; a < n; ++a) sum += A[a][b];
      EXPECT_NEAR(sum, 1.0, 1e-15) << "partition of unity, n " << n;
    }
    for (int a = 0; a < n; ++a) {
      if (!carries[a]) {
        for (int b = 0; b < n; ++b) EXPECT_EQ(A[a][b], 0.0);
        continue;
      }
      for (int k = 0; k < n; ++k) {
        if (!carries[k]) continue;
        double value = 0;
        for (int b = 0; b < n; ++b) value += A[a][b] * (b == k ? 2.0 : 1.0) / (n * (n + 1));
        EXPECT_NEAR(value, a == k ? 1.0 / n : 0.0, 1e-15);
      }
    }
  }
  // Segment with one boundary vertex: the other's dual function is the constant 1.
  const auto A = dual_coefficients(2, {true, false, false});
  EXPECT_NEAR(A[0][0], 1.0, 1e-15);
  EXPECT_NEAR(A[0][1], 1.0, 1e-15);
  // No multiplier node: nothing.
  const auto none = dual_coefficients(3, {false, false, false});
  for (const auto& row : none)
    for (double v : row) EXPECT_EQ(v, 0.0);
}

TEST(SegmentIntegration, ExactForQuadraticProducts) {
  // Slave (0,0)–(2,0); master (2.6, 0.3)–(0.4, 0.5) (opposite direction, tilted, above).
  const std::array<std::array<double, 2>, 2> slave = {{{0.0, 0.0}, {2.0, 0.0}}};
  const std::array<std::array<double, 2>, 2> master = {{{2.6, 0.3}, {0.4, 0.5}}};
  std::array<MortarPoint, kMaxMortarPoints> points;
  const int n = integrate_segments(slave, master, points.data());
  ASSERT_EQ(n, 2);
  // Overlap x ∈ [0.4, 2]; slave N = (1 − x/2, x/2); master parameter η = (2.6 − x)/2.2,
  // N^m = (1 − η, η). Every product is a quadratic in x: Simpson's rule is exact.
  const auto slave_n = [](double x, int a) { return a == 0 ? 1 - x / 2 : x / 2; };
  const auto master_n = [](double x, int l) {
    const double eta = (2.6 - x) / 2.2;
    return l == 0 ? 1 - eta : eta;
  };
  for (int a = 0; a < 2; ++a)
    for (int l = 0; l < 2; ++l) {
      const auto f = [&](double x) { return slave_n(x, a) * master_n(x, l); };
      const double lo = 0.4, hi = 2.0;
      const double simpson = (hi - lo) / 6 * (f(lo) + 4 * f(0.5 * (lo + hi)) + f(hi));
      double quadrature = 0;
      for (int q = 0; q < n; ++q)
        quadrature += points[q].weight * points[q].slave[a] * points[q].master[l];
      EXPECT_NEAR(quadrature, simpson, 1e-14) << a << " " << l;
    }
  // Disjoint projections give nothing.
  const std::array<std::array<double, 2>, 2> far = {{{3.5, 0.1}, {2.5, 0.1}}};
  EXPECT_EQ(integrate_segments(slave, far, points.data()), 0);
}

/// Rigid motion x → R x + t of a point.
std::array<double, 3> move(const std::array<double, 3>& x, double angle, double tilt) {
  // rotation about z by `angle`, then about x by `tilt`, then a shift
  const double c = std::cos(angle), s = std::sin(angle), ct = std::cos(tilt), st = std::sin(tilt);
  const std::array<double, 3> y = {c * x[0] - s * x[1], s * x[0] + c * x[1], x[2]};
  return {y[0] + 0.3, ct * y[1] - st * y[2] - 0.2, st * y[1] + ct * y[2] + 1.1};
}

TEST(TriangleIntegration, ExactOnTheClippedPolygonAndInvariantUnderRigidMotion) {
  // Slave: the unit right triangle in z = 0 (normal +z). Master: the same triangle shifted
  // by (0.5, 0) and lifted to z = 0.25, listed clockwise seen from +z (normal −z).
  std::array<std::array<double, 3>, 3> slave = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  std::array<std::array<double, 3>, 3> master = {{{0.5, 0, 0.25}, {0.5, 1, 0.25}, {1.5, 0, 0.25}}};
  // The overlap is the triangle (0.5,0), (1,0), (0.5,0.5) of area 1/8.
  const std::vector<std::array<double, 2>> overlap = {{0.5, 0}, {1, 0}, {0.5, 0.5}};
  const auto slave_n = [](const std::array<double, 2>& p, int a) {
    return a == 0 ? 1 - p[0] - p[1] : (a == 1 ? p[0] : p[1]);
  };
  const auto master_n = [](const std::array<double, 2>& p, int l) {
    // master vertices (0.5,0), (0.5,1), (1.5,0): λ_1 = y, λ_2 = x − 0.5, λ_0 = 1.5 − x − y
    return l == 0 ? 1.5 - p[0] - p[1] : (l == 1 ? p[1] : p[0] - 0.5);
  };
  for (int motion = 0; motion < 2; ++motion) {
    if (motion == 1)
      for (auto* t : {&slave, &master})
        for (auto& x : *t) x = move(x, 0.7, 0.4);
    std::array<MortarPoint, kMaxMortarPoints> points;
    const int n = integrate_triangles(slave, master, points.data());
    ASSERT_GT(n, 0);
    double area = 0;
    for (int q = 0; q < n; ++q) area += points[q].weight;
    EXPECT_NEAR(area, 0.125, 1e-15);
    for (int a = 0; a < 3; ++a)
      for (int l = 0; l < 3; ++l) {
        std::vector<double> f, g;
        for (const auto& p : overlap) {
          f.push_back(slave_n(p, a));
          g.push_back(master_n(p, l));
        }
        double quadrature = 0;
        for (int q = 0; q < n; ++q)
          quadrature += points[q].weight * points[q].slave[a] * points[q].master[l];
        EXPECT_NEAR(quadrature, affine_product_integral(0.125, f, g), 1e-14)
            << "motion " << motion << " " << a << " " << l;
      }
  }
}

// ---- surfaces from generated meshes ------------------------------------------------------

/// The facets of group `name` of a serial mesh as a surface.
Surface group_surface(const mesh::Mesh& m, const std::string& name) {
  const int tag = m.group(name).tag;
  return gather_surface(m, std::span<const int>(&tag, 1), name);
}

/// Applies y ← f(y) to every node of a surface's coordinates.
template <class F>
std::vector<double> mapped(const Surface& s, F&& f) {
  std::vector<double> x = s.reference;
  for (int n = 0; n < s.n_nodes(); ++n) f(x.data() + static_cast<std::size_t>(n) * s.dim);
  return x;
}

struct Checks {
  double dual_sum = 0;         // Σ_j D_jj
  double max_row_defect = 0;   // max |Σ_l M_jl − D_jj| on constrained nodes
  double max_offdiagonal = 0;  // max |D̂_jk − δ_jk D_jj| on constrained nodes
  int constrained = 0;
};

Checks check_operators(const MortarOperators& op, int n_nodes) {
  Checks c;
  std::vector<double> row_m(static_cast<std::size_t>(n_nodes), 0.0);
  for (int j = 0; j < n_nodes; ++j) c.dual_sum += op.dual_mass[j];
  for (const auto& e : op.master_coupling) row_m[e.row] += e.value;
  for (const auto& e : op.slave_coupling)
    if (op.constrained(e.row))
      c.max_offdiagonal = std::max(
          c.max_offdiagonal, std::abs(e.value - (e.row == e.column ? op.dual_mass[e.row] : 0.0)));
  for (int j = 0; j < n_nodes; ++j)
    if (op.constrained(j)) {
      ++c.constrained;
      c.max_row_defect = std::max(c.max_row_defect, std::abs(row_m[j] - op.dual_mass[j]));
    }
  return c;
}

TEST(MortarOperators2D, FlatNonMatchingTiltedAndModified) {
  // Slave: the bottom of [0,1] × [0.05, 1] (7 cells; normal −y). Master: the top of the
  // wider [-0.2, 1.3] × [-1, 0] (10 cells; normal +y), 0.05 below.
  const auto upper = mesh::structured_rectangle(0.0, 0.05, 1.0, 1.0, 7, 3);
  const auto lower = mesh::structured_rectangle(-0.2, -1.0, 1.3, 0.0, 10, 3);
  const Surface slave = group_surface(upper, "bottom");
  const Surface master = group_surface(lower, "top");
  ASSERT_EQ(slave.n_nodes(), 8);
  MortarOptions options;
  options.search_distance = 0.2;
  options.boundary_modification = false;
  auto op = assemble_mortar(slave, slave.reference, master, master.reference, options);
  auto c = check_operators(op, slave.n_nodes());
  EXPECT_NEAR(c.dual_sum, 1.0, 1e-14);  // Σ D_jj = slave length
  EXPECT_EQ(c.constrained, 8);          // every node covered (master wider)
  EXPECT_LT(c.max_row_defect, 1e-15);
  EXPECT_LT(c.max_offdiagonal, 1e-15);
  for (int j = 0; j < slave.n_nodes(); ++j) {
    EXPECT_NEAR(op.gap(j), 0.05, 1e-14);
    EXPECT_NEAR(op.normals[2 * j + 1], -1.0, 1e-15);
  }

  // Tilt the master: its top becomes y = −0.1 x + 0.02 (a shear of the coordinates); the
  // gap along the slave normal (0, −1) is 0.05 − (−0.1 x + 0.02) = 0.03 + 0.1 x, linear,
  // so the dual basis gives it exactly at every covered node.
  const auto tilted = mapped(master, [](double* x) { x[1] += -0.1 * x[0] + 0.02; });
  op = assemble_mortar(slave, slave.reference, master, tilted, options);
  c = check_operators(op, slave.n_nodes());
  EXPECT_EQ(c.constrained, 8);
  EXPECT_LT(c.max_row_defect, 1e-15);
  for (int j = 0; j < slave.n_nodes(); ++j)
    EXPECT_NEAR(op.gap(j), 0.03 + 0.1 * slave.reference[2 * j], 1e-14) << j;

  // Boundary modification: the two end nodes carry no multiplier; the partition of unity
  // Σ_j (D_jj + Σ_{k≠j} D̂_jk) = length and row sums Σ_l M_jl = Σ_k D̂_jk remain, and the
  // weighted gap is Σ_k D̂_jk g(x_k) for the linear gap g.
  options.boundary_modification = true;
  op = assemble_mortar(slave, slave.reference, master, tilted, options);
  EXPECT_FALSE(op.multiplier[0]);
  EXPECT_FALSE(op.multiplier[7]);
  double total = 0;
  std::vector<double> row_s(8, 0.0), row_m(8, 0.0), expected_gap(8, 0.0);
  for (const auto& e : op.slave_coupling) {
    total += e.value;
    row_s[e.row] += e.value;
    expected_gap[e.row] += e.value * (0.03 + 0.1 * slave.reference[2 * e.column]);
  }
  for (const auto& e : op.master_coupling) row_m[e.row] += e.value;
  EXPECT_NEAR(total, 1.0, 1e-14);
  for (int j = 1; j < 7; ++j) {
    EXPECT_NEAR(row_s[j], row_m[j], 1e-15);
    EXPECT_NEAR(op.weighted_gap[j], expected_gap[j], 1e-15);
    EXPECT_GT(op.dual_mass[j], 0.0);
  }
}

TEST(MortarOperators2D, PartlyCoveredNodesAreNotConstrained) {
  // Master covers x ∈ [0.3, 2] of the slave [0, 1] (5 cells): nodes 0, 1 (support reaching
  // x < 0.3) are not covered; node 2 at x = 0.4 has support [0.2, 0.6]: not covered either.
  const auto upper = mesh::structured_rectangle(0.0, 0.0, 1.0, 1.0, 5, 2);
  const auto lower = mesh::structured_rectangle(0.3, -1.0, 2.0, 0.0, 4, 2);
  const Surface slave = group_surface(upper, "bottom");
  const Surface master = group_surface(lower, "top");
  MortarOptions options;
  options.search_distance = 0.1;
  options.boundary_modification = false;
  const auto op = assemble_mortar(slave, slave.reference, master, master.reference, options);
  for (int j = 0; j < slave.n_nodes(); ++j) {
    const double x = slave.reference[2 * j];
    const double lo = std::max(0.0, x - 0.2), hi = std::min(1.0, x + 0.2);
    // Covered part of ∫ N_j: the hat function integrated over [max(lo, 0.3), hi].
    const auto hat = [&](double t) { return 1.0 - std::abs(t - x) / 0.2; };
    const double a = std::max(lo, 0.3);
    double covered = 0;
    if (hi > a) {  // piecewise linear: exact by splitting at x
      const auto trapezoid = [&](double p, double q) { return (q - p) * 0.5 * (hat(p) + hat(q)); };
      covered = (a < x && x < hi) ? trapezoid(a, x) + trapezoid(x, hi) : trapezoid(a, hi);
    }
    EXPECT_NEAR(op.covered[j], covered, 1e-15) << j;
    EXPECT_EQ(op.constrained(j), x - 0.2 >= 0.3 - 1e-12) << j;
  }
}

// Checks of a slave node j with a multiplier on partly covered facets: its D̂ row is diagonal
// on the multiplier nodes (boundary nodes enter off the diagonal, like master nodes),
// D_jj = ∫_Γc N_j, Σ_l M_jl = Σ_k D̂_jk, and the gap of a master plane is reproduced exactly:
// g̃_j = Σ_k D̂_jk g(x_k), which is D_jj g(x_j) when no boundary node is near.
template <class Gap>
void expect_consistent_partial_node(const MortarOperators& op, const Surface& slave, int j,
                                    Gap gap) {
  SCOPED_TRACE(j);
  const int dim = slave.dim;
  double offdiagonal = 0, diagonal = 0, row_s = 0, row_m = 0, weighted = 0;
  for (const auto& e : op.slave_coupling) {
    if (e.row != j) continue;
    if (e.column == j)
      diagonal += e.value;
    else if (op.multiplier[e.column])
      offdiagonal += std::abs(e.value);
    row_s += e.value;
    weighted += e.value * gap(slave.reference.data() + dim * e.column);
  }
  for (const auto& e : op.master_coupling)
    if (e.row == j) row_m += e.value;
  EXPECT_GT(op.dual_mass[j], 0.0);
  EXPECT_LT(offdiagonal, 1e-13 * op.support[j]);
  EXPECT_NEAR(diagonal, op.dual_mass[j], 1e-14 * op.support[j]);
  EXPECT_NEAR(op.dual_mass[j], op.covered[j], 1e-14 * op.support[j]);
  EXPECT_NEAR(row_m, row_s, 1e-14 * op.support[j]);
  EXPECT_NEAR(op.weighted_gap[j], weighted, 1e-14 * op.support[j]);
  bool boundary_near = false;
  for (const auto& e : op.slave_coupling)
    boundary_near = boundary_near || (e.row == j && !op.multiplier[e.column]);
  if (!boundary_near) {
    EXPECT_NEAR(op.gap(j), gap(slave.reference.data() + dim * j), 1e-12);
  }
}

TEST(MortarOperators2D, PartlyCoveredFacetsKeepDiagonalOperatorsAndExactGaps) {
  // The slave [0, 1] (5 cells) over a master covering x ≥ 0.3, tilted: gap 0.03 + 0.1 x.
  // Node 1 (x = 0.2) has 12.5 % of its support covered, node 2 (x = 0.4) 87.5 %. With the
  // dual functions biorthogonal on the covered part each such node's gap is the tilted
  // plane's at the node. The standard functions integrated over the overlap give node 1
  // ∫_0.3^0.4 (3 N_1 − 1) (g) < 0: a penetration for a gap of 0.05 (checked below).
  const auto upper = mesh::structured_rectangle(0.0, 0.05, 1.0, 1.0, 5, 2);
  const auto lower = mesh::structured_rectangle(0.3, -1.0, 2.0, 0.0, 4, 2);
  const Surface slave = group_surface(upper, "bottom");
  const Surface master = group_surface(lower, "top");
  const auto tilted = mapped(master, [](double* x) { x[1] += -0.1 * x[0] + 0.02; });
  for (bool modification : {false, true}) {
    SCOPED_TRACE(modification);
    MortarOptions options;
    options.search_distance = 0.5;  // the gap reaches 0.13
    options.boundary_modification = modification;
    options.coverage_threshold = 0.1;
    const auto op = assemble_mortar(slave, slave.reference, master, tilted, options);
    for (int j = 0; j < slave.n_nodes(); ++j) {
      const double x = slave.reference[2 * j];
      if (!op.multiplier[j]) {
        EXPECT_EQ(op.dual_mass[j], 0.0);
        continue;
      }
      if (x < 0.1 - 1e-12) {  // node 0: support [0, 0.2] uncovered
        EXPECT_EQ(op.dual_mass[j], 0.0);
        EXPECT_FALSE(op.constrained(j));
        continue;
      }
      EXPECT_TRUE(op.constrained(j));
      expect_consistent_partial_node(op, slave, j,
                                     [](const double* y) { return 0.03 + 0.1 * y[0]; });
    }
  }
  // The standard functions on node 1's covered part [0.3, 0.4] (N_1 = 2 − 5x there): the
  // weighted gap they would give has the wrong sign for the open gap 0.03 + 0.1 x > 0.
  double standard = 0;
  for (double t : {0.35 - 0.05 / std::sqrt(3.0), 0.35 + 0.05 / std::sqrt(3.0)})
    standard += 0.05 * (3.0 * (2.0 - 5.0 * t) - 1.0) * (0.03 + 0.1 * t);
  EXPECT_LT(standard, 0.0);
}

TEST(MortarOperators3D, PartlyCoveredFacetsKeepDiagonalOperatorsAndExactGaps) {
  // The slave [0,1]² (4×4 cells) over a tilted master rotated by 0.3 rad that covers only
  // part of it (x ≥ about 0.37): gap 0.02 − 0.05 x + 0.03 y at every node with a covered
  // part, whatever its fraction.
  const auto upper = mesh::structured_box(0, 0, 0.02, 1, 1, 1, 4, 4, 1);
  const auto lower = coapt::testing::rotated(
      mesh::structured_box(0.4, -0.6, -1, 2.0, 1.6, 0, 5, 6, 1), 0.3, {0, 0, 1}, {0.5, 0.5, 0});
  const Surface slave = group_surface(upper, "bottom");
  const Surface master = group_surface(lower, "top");
  const auto tilted = mapped(master, [](double* x) { x[2] += 0.05 * x[0] - 0.03 * x[1]; });
  MortarOptions options;
  options.search_distance = 0.1;
  options.boundary_modification = false;
  options.coverage_threshold = 1e-3;
  const auto op = assemble_mortar(slave, slave.reference, master, tilted, options);
  int partial = 0, whole = 0, none = 0;
  for (int j = 0; j < slave.n_nodes(); ++j) {
    const double fraction = op.covered[j] / op.support[j];
    if (fraction > 1 - 1e-12)
      ++whole;
    else if (fraction > 0.0)
      ++partial;
    else
      ++none;
    if (op.dual_mass[j] > 0.0)
      expect_consistent_partial_node(
          op, slave, j, [](const double* y) { return 0.02 - 0.05 * y[0] + 0.03 * y[1]; });
  }
  EXPECT_GT(partial, 3);
  EXPECT_GT(whole, 3);
  EXPECT_GT(none, 0);
}

TEST(MortarOperators2D, BackFacingAndDistantMastersAreIgnored) {
  const auto upper = mesh::structured_rectangle(0.0, 0.0, 1.0, 1.0, 4, 2);
  const Surface slave = group_surface(upper, "bottom");
  // The master's bottom (normal −y) faces away from the slave's bottom (normal −y).
  const auto lower = mesh::structured_rectangle(-0.5, -1.0, 1.5, -0.01, 4, 2);
  MortarOptions options;
  options.search_distance = 2.0;  // reaches the master's bottom at y = −1
  const auto back = group_surface(lower, "bottom");
  EXPECT_EQ(assemble_mortar(slave, slave.reference, back, back.reference, options).facet_pairs, 0);
  const auto top = group_surface(lower, "top");
  EXPECT_GT(assemble_mortar(slave, slave.reference, top, top.reference, options).facet_pairs, 0);
  options.search_distance = 0.005;  // the top is 0.01 away
  EXPECT_EQ(assemble_mortar(slave, slave.reference, top, top.reference, options).facet_pairs, 0);
}

TEST(MortarOperators3D, NonMatchingRotatedAndTilted) {
  // Slave: bottom of [0,1]² × [0.02, 1] (5×4 cells, normal −z). Master: top of a wider box
  // with 7×6 cells rotated by 0.3 rad about the z axis (normal +z).
  const auto upper = mesh::structured_box(0, 0, 0.02, 1, 1, 1, 5, 4, 1);
  const auto lower = coapt::testing::rotated(
      mesh::structured_box(-0.6, -0.6, -1, 1.6, 1.6, 0, 7, 6, 1), 0.3, {0, 0, 1}, {0.5, 0.5, 0});
  const Surface slave = group_surface(upper, "bottom");
  const Surface master = group_surface(lower, "top");
  MortarOptions options;
  options.search_distance = 0.1;
  options.boundary_modification = false;
  auto op = assemble_mortar(slave, slave.reference, master, master.reference, options);
  auto c = check_operators(op, slave.n_nodes());
  EXPECT_NEAR(c.dual_sum, 1.0, 1e-14);  // Σ D_jj = slave area
  EXPECT_EQ(c.constrained, slave.n_nodes());
  EXPECT_LT(c.max_row_defect, 1e-14);
  EXPECT_LT(c.max_offdiagonal, 1e-14);
  for (int j = 0; j < slave.n_nodes(); ++j) EXPECT_NEAR(op.gap(j), 0.02, 1e-14);
  // Tilted master z = 0.05 x − 0.03 y: gap 0.02 − 0.05 x + 0.03 y, exactly at every node.
  const auto tilted = mapped(master, [](double* x) { x[2] += 0.05 * x[0] - 0.03 * x[1]; });
  op = assemble_mortar(slave, slave.reference, master, tilted, options);
  c = check_operators(op, slave.n_nodes());
  EXPECT_LT(c.max_row_defect, 1e-14);
  for (int j = 0; j < slave.n_nodes(); ++j) {
    const double* x = slave.reference.data() + 3 * j;
    EXPECT_NEAR(op.gap(j), 0.02 - 0.05 * x[0] + 0.03 * x[1], 1e-14) << j;
  }
  // Modified basis: no multipliers on the 18 boundary nodes, partition of unity kept.
  options.boundary_modification = true;
  op = assemble_mortar(slave, slave.reference, master, tilted, options);
  int multipliers = 0;
  for (int j = 0; j < slave.n_nodes(); ++j) multipliers += op.multiplier[j] ? 1 : 0;
  EXPECT_EQ(multipliers, (5 - 1) * (4 - 1));
  // Facets whose three vertices are all on the boundary (at two corners of the square) have
  // no multiplier node: the partition of unity holds on the rest of the surface.
  double without = 0;
  for (int f = 0; f < slave.n_facets(); ++f) {
    bool any = false;
    for (int node : slave.facet(f)) any = any || op.multiplier[node];
    if (!any) without += 0.5 / (5 * 4);
  }
  EXPECT_NEAR(without, 2 * 0.5 / (5 * 4), 1e-15);
  double total = 0;
  for (const auto& e : op.slave_coupling) total += e.value;
  EXPECT_NEAR(total, 1.0 - without, 1e-14);
  std::vector<double> row_s(slave.n_nodes(), 0.0), row_m(slave.n_nodes(), 0.0);
  for (const auto& e : op.slave_coupling) row_s[e.row] += e.value;
  for (const auto& e : op.master_coupling) row_m[e.row] += e.value;
  for (int j = 0; j < slave.n_nodes(); ++j) EXPECT_NEAR(row_s[j], row_m[j], 1e-14);
}

TEST(Surface, NormalsAndBoundaryOfACurvedSurface) {
  // A quarter circle of radius 2 in 8 segments, oriented with outward normal pointing away
  // from the centre: the averaged normal at an interior node is the radial direction.
  const int n = 8;
  std::vector<double> x;
  std::vector<int> facets;
  for (int k = 0; k <= n; ++k) {
    const double t = 0.5 * M_PI * k / n;
    x.push_back(2 * std::cos(t));
    x.push_back(2 * std::sin(t));
  }
  for (int k = 0; k < n; ++k) {  // (a, b) with normal (b − a) rotated clockwise: outward
    facets.push_back(k);
    facets.push_back(k + 1);
  }
  const Surface s = make_surface(2, x, facets);
  std::vector<char> valid;
  const auto normals = nodal_normals(s, s.reference, &valid);
  for (int k = 1; k < n; ++k) {
    const double t = 0.5 * M_PI * k / n;
    EXPECT_NEAR(normals[2 * k], std::cos(t), 1e-14);
    EXPECT_NEAR(normals[2 * k + 1], std::sin(t), 1e-14);
  }
  const auto boundary = boundary_nodes(s);
  EXPECT_EQ(std::accumulate(boundary.begin(), boundary.end(), 0), 2);
  EXPECT_TRUE(boundary[0] && boundary[n]);
  // A fold (two segments back to back) has no meaningful normal.
  const Surface fold = make_surface(2, {0, 0, 1, 0, 0, 0.0}, {0, 1, 1, 2});
  nodal_normals(fold, fold.reference, &valid);
  EXPECT_FALSE(valid[1]);
}

}  // namespace
}  // namespace coapt::contact
