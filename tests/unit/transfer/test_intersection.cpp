// Exact cases of the element–element intersection: identical elements, inclusion,
// disjoint and touching pairs, and intersections known in closed form.

#include <gtest/gtest.h>

#include <cmath>

#include "coapt/transfer/intersection.hpp"
#include "intersection_test_support.hpp"
#include "reference_geometry.hpp"

namespace coapt::transfer {
namespace {

using testing::element_mass;
using testing::near_relative;
using testing::Vertices;

template <int dim>
void expect_matrix_near(const NodalMatrix<dim>& actual, const NodalMatrix<dim>& expected,
                        double tolerance) {
  for (int i = 0; i <= dim; ++i)
    for (int j = 0; j <= dim; ++j)
      EXPECT_NEAR(actual[i][j], expected[i][j], tolerance) << "entry (" << i << ", " << j << ")";
}

// ∫_S λ^P_i λ^S_j for a simplex S inside P: |S| / ((d+1)(d+2)) (λ^P_i(s_j) + Σ_k λ^P_i(s_k)).
template <int dim>
NodalMatrix<dim> mass_of_inner(const Simplex<dim>& outer, const Simplex<dim>& inner) {
  NodalMatrix<dim> m;
  for (int i = 0; i <= dim; ++i) {
    double sum = 0.0;
    for (const auto& s : inner.vertices) sum += outer.barycentric(i, s);
    for (int j = 0; j <= dim; ++j)
      m[i][j] =
          inner.measure * (outer.barycentric(i, inner.vertices[j]) + sum) / ((dim + 1) * (dim + 2));
  }
  return m;
}

// A pair with zero-measure intersection: false, zeroed output, no quadrature points.
template <int dim>
void expect_empty(const Vertices<dim>& va, const Vertices<dim>& vb) {
  const auto a = make_simplex<dim>(va);
  const auto b = make_simplex<dim>(vb);
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  local.moments.measure = -1.0;
  EXPECT_FALSE(local_integrals(a, b, workspace, local));
  EXPECT_EQ(local.measure(), 0.0);
  EXPECT_FALSE(local_integrals(b, a, workspace, local));
  EXPECT_EQ(local.measure(), 0.0);
  EXPECT_TRUE(intersection_quadrature(a, b, workspace).empty());
  EXPECT_TRUE(intersection_quadrature(b, a, workspace).empty());
}

template <int dim>
LocalIntegrals<dim> integrals(const Vertices<dim>& va, const Vertices<dim>& vb) {
  IntersectionWorkspace<dim> workspace;
  LocalIntegrals<dim> local;
  EXPECT_TRUE(local_integrals(make_simplex<dim>(va), make_simplex<dim>(vb), workspace, local));
  return local;
}

const Vertices<2> kTriangle{{{0.1, 0.2}, {1.3, 0.4}, {0.5, 1.1}}};
const Vertices<3> kTetrahedron{
    {{0.1, 0.2, 0.0}, {1.2, 0.3, 0.1}, {0.4, 1.1, 0.2}, {0.3, 0.4, 0.9}}};
const Vertices<2> kUnitTriangle{{{0, 0}, {1, 0}, {0, 1}}};
const Vertices<3> kUnitTetrahedron{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

// ------------------------------------------------------------------------------------- simplices

TEST(Simplex, BarycentricCoordinatesAndMeasure) {
  const auto t = make_simplex<3>(kTetrahedron);
  EXPECT_NEAR(t.measure, reference::simplex_measure<3>(kTetrahedron), 1e-15);
  for (int i = 0; i < 4; ++i)
    for (int v = 0; v < 4; ++v) EXPECT_NEAR(t.barycentric(i, kTetrahedron[v]), i == v, 1e-15);
  // reversed orientation: same measure, same barycentric coordinates
  const Vertices<3> reversed{kTetrahedron[0], kTetrahedron[2], kTetrahedron[1], kTetrahedron[3]};
  const auto r = make_simplex<3>(reversed);
  EXPECT_NEAR(r.measure, t.measure, 1e-15);
  EXPECT_NEAR(r.barycentric(1, kTetrahedron[2]), 1.0, 1e-15);
  const auto tri = make_simplex<2>(Vertices<2>{kTriangle[1], kTriangle[0], kTriangle[2]});
  EXPECT_NEAR(tri.measure, reference::simplex_measure<2>(kTriangle), 1e-15);
}

TEST(Simplex, DegenerateElementsIntersectNothing) {
  const Vertices<3> flat{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 0}}};
  const Vertices<3> collapsed{{{0, 0, 0}, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  const Vertices<3> not_finite{{{0, 0, 0}, {NAN, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (const auto& v : {flat, collapsed, not_finite}) {
    EXPECT_EQ(make_simplex<3>(v).measure, 0.0);
    expect_empty<3>(v, kUnitTetrahedron);
  }
  const Vertices<2> segment{{{0, 0}, {1, 1}, {0.5, 0.5}}};
  EXPECT_EQ(make_simplex<2>(segment).measure, 0.0);
  expect_empty<2>(segment, kUnitTriangle);
}

// ---------------------------------------------------------------------------- identical elements

TEST(TriangleIntersection, IdenticalTriangles) {
  const auto a = make_simplex<2>(kTriangle);
  const auto local = integrals<2>(kTriangle, kTriangle);
  EXPECT_TRUE(near_relative(local.measure(), a.measure, 1e-15, a.measure));
  expect_matrix_near<2>(local.mass, element_mass<2>(a.measure), 1e-15 * a.measure);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(local.integral_a[i], a.measure / 3, 1e-15);
    EXPECT_NEAR(local.integral_b[i], a.measure / 3, 1e-15);
  }
  // dual basis: ∫ψ_i λ_j = δ_ij |T|/3, ∫ψ_i = |T|/3
  const auto dual = dual_mass(local);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(dual_integrals(local)[i], a.measure / 3, 1e-15);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(dual[i][j], i == j ? a.measure / 3 : 0.0, 1e-15);
  }
}

TEST(TetrahedronIntersection, IdenticalTetrahedra) {
  const auto a = make_simplex<3>(kTetrahedron);
  const auto local = integrals<3>(kTetrahedron, kTetrahedron);
  EXPECT_TRUE(near_relative(local.measure(), a.measure, 1e-15, a.measure));
  expect_matrix_near<3>(local.mass, element_mass<3>(a.measure), 1e-15 * a.measure);
  const auto dual = dual_mass(local);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(local.integral_a[i], a.measure / 4, 1e-15);
    EXPECT_NEAR(dual_integrals(local)[i], a.measure / 4, 1e-15);
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(dual[i][j], i == j ? a.measure / 4 : 0.0, 1e-15);
  }
}

TEST(TetrahedronIntersection, IdenticalTetrahedraWithPermutedVertices) {
  // B = A with vertices in order (2, 0, 3, 1): M_ij = mass(i, perm[j])
  const std::array<int, 4> perm{2, 0, 3, 1};
  Vertices<3> permuted;
  for (int j = 0; j < 4; ++j) permuted[j] = kTetrahedron[perm[j]];
  const auto a = make_simplex<3>(kTetrahedron);
  const auto local = integrals<3>(kTetrahedron, permuted);
  const auto mass = element_mass<3>(a.measure);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(local.mass[i][j], mass[i][perm[j]], 1e-15);
}

// -------------------------------------------------------------------------------------- inclusion

TEST(TriangleIntersection, OneInsideTheOther) {
  const Vertices<2> inner{{{0.4, 0.4}, {0.8, 0.5}, {0.5, 0.7}}};
  const auto outer = make_simplex<2>(kTriangle);
  const auto small = make_simplex<2>(inner);
  const auto expected = mass_of_inner<2>(outer, small);
  const auto ab = integrals<2>(kTriangle, inner);
  EXPECT_TRUE(near_relative(ab.measure(), small.measure, 1e-15, small.measure));
  expect_matrix_near<2>(ab.mass, expected, 1e-15);
  const auto ba = integrals<2>(inner, kTriangle);
  EXPECT_TRUE(near_relative(ba.measure(), small.measure, 1e-15, small.measure));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(ba.mass[j][i], expected[i][j], 1e-15);
}

TEST(TetrahedronIntersection, OneInsideTheOther) {
  const Vertices<3> inner{{{0.4, 0.4, 0.2}, {0.6, 0.4, 0.25}, {0.45, 0.6, 0.3}, {0.45, 0.45, 0.4}}};
  const auto outer = make_simplex<3>(kTetrahedron);
  const auto small = make_simplex<3>(inner);
  const auto expected = mass_of_inner<3>(outer, small);
  const auto ab = integrals<3>(kTetrahedron, inner);
  EXPECT_TRUE(near_relative(ab.measure(), small.measure, 1e-15, small.measure));
  expect_matrix_near<3>(ab.mass, expected, 1e-15);
  const auto ba = integrals<3>(inner, kTetrahedron);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(ba.mass[j][i], expected[i][j], 1e-15);
}

TEST(TetrahedronIntersection, InsideSharingAFace) {
  // B is A with its apex pulled in: B ⊂ A, sharing the face z = 0.
  const Vertices<3> inner{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, 0.3}}};
  const auto outer = make_simplex<3>(kUnitTetrahedron);
  const auto small = make_simplex<3>(inner);
  const auto local = integrals<3>(kUnitTetrahedron, inner);
  EXPECT_NEAR(local.measure(), 0.05, 1e-16);
  expect_matrix_near<3>(local.mass, mass_of_inner<3>(outer, small), 1e-16);
}

// ------------------------------------------------------------------------ disjoint and touching

TEST(TriangleIntersection, DisjointAndTouching) {
  // far apart (bounding boxes disjoint)
  expect_empty<2>(kUnitTriangle, {{{3, 3}, {4, 3}, {3, 4}}});
  // boxes overlap, separated by the hypotenuse of the unit triangle
  expect_empty<2>(kUnitTriangle, {{{0.6, 0.6}, {1, 0.6}, {0.6, 1}}});
  // touching at a vertex
  expect_empty<2>(kUnitTriangle, {{{1, 0}, {2, 0}, {2, 1}}});
  expect_empty<2>(kUnitTriangle, {{{1, 0}, {2, -1}, {2, 1}}});
  // sharing an edge, opposite sides
  expect_empty<2>(kUnitTriangle, {{{1, 0}, {0, 1}, {1, 1}}});
  // part of an edge in common, opposite sides
  expect_empty<2>(kUnitTriangle, {{{0.2, 0}, {0.7, 0}, {0.5, -1}}});
  // a vertex on the other's edge
  expect_empty<2>(kUnitTriangle, {{{0.5, 0.5}, {1, 1}, {2, 0.5}}});
}

TEST(TetrahedronIntersection, DisjointAndTouching) {
  expect_empty<3>(kUnitTetrahedron, {{{3, 3, 3}, {4, 3, 3}, {3, 4, 3}, {3, 3, 4}}});
  // boxes overlap, separated by the slanted face x + y + z = 1
  expect_empty<3>(kUnitTetrahedron,
                  {{{0.5, 0.5, 0.5}, {1, 0.5, 0.5}, {0.5, 1, 0.5}, {0.5, 0.5, 1}}});
  // touching at a vertex
  expect_empty<3>(kUnitTetrahedron, {{{1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {2, 0, 1}}});
  // touching along an edge
  expect_empty<3>(kUnitTetrahedron, {{{1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 1, 1}}});
  // sharing a face, opposite sides
  expect_empty<3>(kUnitTetrahedron, {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}}});
  expect_empty<3>(kUnitTetrahedron, {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.3, -1}}});
  // part of a face in common, opposite sides
  expect_empty<3>(kUnitTetrahedron,
                  {{{0.1, 0.1, 0}, {0.5, 0.1, 0}, {0.1, 0.5, 0}, {0.3, 0.3, -0.2}}});
  // a vertex in the middle of the other's face
  expect_empty<3>(kUnitTetrahedron, {{{0.2, 0.2, 0}, {1, 1, -1}, {-1, 1, -1}, {0, -1, -1}}});
}

TEST(TetrahedronIntersection, EdgesCrossingWithoutAFaceSeparation) {
  // The top edge of A (along x) and the bottom edge of B (along y) cross at the origin; no
  // face plane of either separates them, so the clipping itself must find zero volume.
  const Vertices<3> a{{{-1, 0, 0}, {1, 0, 0}, {0, 1, -1}, {0, -1, -1}}};
  const Vertices<3> touching{{{0, -1, 0}, {0, 1, 0}, {1, 0, 1}, {-1, 0, 1}}};
  expect_empty<3>(a, touching);
  const Vertices<3> apart{{{0, -1, 1e-3}, {0, 1, 1e-3}, {1, 0, 1.001}, {-1, 0, 1.001}}};
  expect_empty<3>(a, apart);
  // and overlapping slightly: the intersection is the small tetrahedron between the edges
  const Vertices<3> overlapping{{{0, -1, -0.01}, {0, 1, -0.01}, {1, 0, 0.99}, {-1, 0, 0.99}}};
  const auto local = integrals<3>(a, overlapping);
  const auto exact = reference::sum_over<3>(reference::intersection<3>(a, overlapping),
                                            reference::simplex_measure<3>);
  EXPECT_GT(exact, 0.0);
  EXPECT_TRUE(near_relative(local.measure(), exact, 1e-10, exact));
}

// ------------------------------------------------------------------- intersections known exactly

TEST(TriangleIntersection, StarOfDavid) {
  // An equilateral triangle and its rotation by 180° about the centroid: a regular hexagon
  // of area 2/3 of the triangle.
  const double r = 0.7;  // circumradius
  Vertices<2> up, down;
  for (int k = 0; k < 3; ++k) {
    const double t = M_PI / 2 + 2 * M_PI * k / 3;
    up[k] = {0.3 + r * std::cos(t), -0.2 + r * std::sin(t)};
    down[k] = {0.3 - r * std::cos(t), -0.2 - r * std::sin(t)};
  }
  const double triangle = 3 * std::sqrt(3.0) / 4 * r * r;
  IntersectionWorkspace<2> workspace;
  const auto a = make_simplex<2>(up);
  const auto b = make_simplex<2>(down);
  Moments<2> m;
  ASSERT_TRUE(intersection_moments(a, b, workspace, m));
  EXPECT_TRUE(near_relative(m.measure, 2.0 / 3.0 * triangle, 1e-15, triangle));
  EXPECT_NEAR(m.centroid[0], 0.3, 1e-15);
  EXPECT_NEAR(m.centroid[1], -0.2, 1e-15);
  // regular hexagon of inradius r/2, side s = r/√3: ∫(x − x̄)² = ∫(y − ȳ)² = 5√3/16 s⁴
  const double s = r / std::sqrt(3.0);
  EXPECT_NEAR(m.second[0][0], 5 * std::sqrt(3.0) / 16 * std::pow(s, 4), 1e-15);
  EXPECT_NEAR(m.second[1][1], 5 * std::sqrt(3.0) / 16 * std::pow(s, 4), 1e-15);
  EXPECT_NEAR(m.second[0][1], 0.0, 1e-15);
  const auto points = intersection_quadrature(a, b, workspace);
  EXPECT_EQ(points.size(), 12u);  // 4 triangles of the fan × 3 points
  double total = 0.0;
  for (const auto& q : points) total += q.weight;
  EXPECT_TRUE(near_relative(total, 2.0 / 3.0 * triangle, 1e-15, triangle));
}

TEST(TetrahedronIntersection, StellaOctangula) {
  // The two tetrahedra inscribed in the unit cube meet in the octahedron with vertices at
  // the face centres, {|u| + |v| + |w| ≤ 1/2} about (1/2, 1/2, 1/2): volume 1/6 and
  // ∫u² = 4 ∫_0^a u² (a − u)² du = 2a⁵/15 = 1/240 for a = 1/2.
  const Vertices<3> a{{{0, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}}};
  const Vertices<3> b{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}}};
  IntersectionWorkspace<3> workspace;
  Moments<3> m;
  ASSERT_TRUE(intersection_moments(make_simplex<3>(a), make_simplex<3>(b), workspace, m));
  EXPECT_NEAR(m.measure, 1.0 / 6.0, 1e-15);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(m.centroid[k], 0.5, 1e-15);
    EXPECT_NEAR(m.second[k][k], 1.0 / 240.0, 1e-15);
    EXPECT_NEAR(m.second[k][(k + 1) % 3], 0.0, 1e-15);
  }
  EXPECT_EQ(workspace.polytope.size(), 12);  // 6 octahedron vertices, each of degree 4 → 2 copies
}

// A ∩ (A + s e_1) for the unit simplex A is the simplex s e_1 + (1 − s) A: its measure,
// moments and M are those of a single simplex (computed without clipping).
template <int dim>
void check_translated_along_an_edge(double s) {
  Vertices<dim> a{}, b{}, expected_region{};
  for (int k = 0; k < dim; ++k) a[k + 1][k] = 1.0;
  for (int v = 0; v <= dim; ++v) {
    b[v] = a[v];
    b[v][0] += s;
    for (int k = 0; k < dim; ++k) expected_region[v][k] = (1 - s) * a[v][k] + (k == 0 ? s : 0.0);
  }
  const auto sa = make_simplex<dim>(a);
  const auto sb = make_simplex<dim>(b);
  const auto region = make_simplex<dim>(expected_region);
  const auto expected = simplex_moments(region);
  const auto local = integrals<dim>(a, b);
  EXPECT_NEAR(local.measure(), expected.measure, 1e-15);
  for (int k = 0; k < dim; ++k) {
    EXPECT_NEAR(local.moments.centroid[k], expected.centroid[k], 1e-15);
    for (int l = 0; l < dim; ++l)
      EXPECT_NEAR(local.moments.second[k][l], expected.second[k][l], 1e-15);
  }
  expect_matrix_near<dim>(local.mass, reference::mass<dim>({expected_region}, a, b), 1e-15);
  EXPECT_TRUE(near_relative(local.measure(), std::pow(1 - s, dim) * sa.measure, 1e-14, sa.measure));
  (void)sb;
}

TEST(TriangleIntersection, TranslatedAlongAnEdge) {
  for (double s : {0.5, 0.1, 1e-3, 0.999}) check_translated_along_an_edge<2>(s);
}
TEST(TetrahedronIntersection, TranslatedAlongAnEdge) {
  for (double s : {0.5, 0.1, 1e-3, 0.999}) check_translated_along_an_edge<3>(s);
}

TEST(TriangleIntersection, CutByALine) {
  // B has an edge on x = 1/2 and contains the part x ≤ 1/2 of the unit triangle:
  // area 1/2 − 1/8 = 3/8.
  const Vertices<2> b{{{0.5, -10}, {0.5, 10}, {-20, 0}}};
  const auto local = integrals<2>(kUnitTriangle, b);
  EXPECT_NEAR(local.measure(), 3.0 / 8.0, 1e-15);
}

TEST(TetrahedronIntersection, CutByAPlane) {
  // B has a face on x = 1/2 and contains the part x ≤ 1/2 of the unit tetrahedron:
  // volume 1/6 − (1/2)³/6 = 7/48, ∫x = ∫_0^{1/2} x (1 − x)²/2 dx = 11/384.
  const Vertices<3> b{{{0.5, -10, -10}, {0.5, 30, -10}, {0.5, -10, 30}, {-20, 0, 0}}};
  const auto local = integrals<3>(kUnitTetrahedron, b);
  EXPECT_NEAR(local.measure(), 7.0 / 48.0, 1e-15);
  EXPECT_NEAR(local.measure() * local.moments.centroid[0], 11.0 / 384.0, 1e-15);
  // ∫λ^A_1 = ∫x
  EXPECT_NEAR(local.integral_a[1], 11.0 / 384.0, 1e-15);
}

TEST(IntersectionWorkspace, SizesAreFixed) {
  // The bounds the workspace is sized by (see clipping.cpp).
  static_assert(ConvexPolygon::capacity == 9);
  static_assert(ConvexPolyhedron::max_vertices == 64 && ConvexPolyhedron::buffer_size == 96);
  static_assert(IntersectionWorkspace<3>::max_quadrature_points == 496);
  SUCCEED() << "sizeof workspace: 2D " << sizeof(IntersectionWorkspace<2>) << " B, 3D "
            << sizeof(IntersectionWorkspace<3>) << " B";
}

}  // namespace
}  // namespace coapt::transfer
