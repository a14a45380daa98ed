// The clipping kernels alone: orientation, graph invariants of the polyhedron, and the
// conservation property behind the transfer (the two sides of any plane add up to the
// whole, including planes through vertices, along edges and on faces).

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "coapt/transfer/clipping.hpp"
#include "intersection_test_support.hpp"
#include "reference_geometry.hpp"

namespace coapt::transfer {
namespace {

using testing::near_relative;
using testing::random_simplex;
using testing::Vertices;

// 3-regular, symmetric adjacency, no self-loops, and Euler's formula V − E + F = 2 per
// connected component (F counted by walking faces).
void expect_valid_graph(const ConvexPolyhedron& p) {
  const int n = p.size();
  ASSERT_LE(n, ConvexPolyhedron::max_vertices);
  int n_faces = 0;
  std::vector<std::array<bool, 3>> visited(n, {false, false, false});
  for (int v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      const int w = p.neighbors(v)[k];
      ASSERT_GE(w, 0);
      ASSERT_LT(w, n);
      ASSERT_NE(w, v);
      int back = 0;
      while (back < 3 && p.neighbors(w)[back] != v) ++back;
      ASSERT_LT(back, 3) << "edge " << v << " → " << w << " is not symmetric";
    }
  for (int v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      if (visited[v][k]) continue;
      ++n_faces;
      int previous = v, slot = k;
      for (int steps = 0;; ++steps) {
        ASSERT_LE(steps, n);
        visited[previous][slot] = true;
        const int current = p.neighbors(previous)[slot];
        int back = 0;
        while (p.neighbors(current)[back] != previous) ++back;
        slot = (back + 1) % 3;
        previous = current;
        if (previous == v && slot == k) break;
      }
    }
  // connected components
  std::vector<int> component(n, -1);
  int n_components = 0;
  for (int v = 0; v < n; ++v) {
    if (component[v] >= 0) continue;
    std::vector<int> stack{v};
    component[v] = n_components;
    while (!stack.empty()) {
      const int x = stack.back();
      stack.pop_back();
      for (int w : p.neighbors(x))
        if (component[w] < 0) {
          component[w] = n_components;
          stack.push_back(w);
        }
    }
    ++n_components;
  }
  EXPECT_EQ(n - 3 * n / 2 + n_faces, 2 * n_components);
}

TEST(ConvexPolyhedron, TetrahedronOfEitherOrientation) {
  const Vertices<3> t{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  const Vertices<3> reversed{t[0], t[2], t[1], t[3]};
  for (const auto& v : {t, reversed}) {
    ConvexPolyhedron p;
    p.assign_tetrahedron(v);
    expect_valid_graph(p);
    const auto m = p.moments();
    EXPECT_NEAR(m.measure, 1.0 / 6.0, 1e-16);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.centroid[k], 0.25, 1e-16);
    QuadraturePoint<3> points[ConvexPolyhedron::max_quadrature_points];
    const int n = p.quadrature(points);
    double total = 0.0;
    for (int q = 0; q < n; ++q) total += points[q].weight;
    EXPECT_NEAR(total, 1.0 / 6.0, 1e-16);
  }
}

TEST(ConvexPolygon, TriangleOfEitherOrientation) {
  for (const Vertices<2>& v :
       {Vertices<2>{{{0, 0}, {1, 0}, {0, 1}}}, Vertices<2>{{{0, 0}, {0, 1}, {1, 0}}}}) {
    ConvexPolygon p;
    p.assign_triangle(v);
    const auto m = p.moments();
    EXPECT_NEAR(m.measure, 0.5, 1e-16);
    EXPECT_NEAR(m.centroid[0], 1.0 / 3.0, 1e-16);
    EXPECT_NEAR(m.second[0][0], 1.0 / 36.0, 1e-16);  // ∫(x − 1/3)² over the unit triangle
  }
}

// Clips a copy of `start` by {n·(x − anchor) ≥ 0} and another by the opposite half-space.
template <class Polytope, int dim>
std::array<Moments<dim>, 2> halves(const Polytope& start, const HalfSpace<dim>& plane) {
  HalfSpace<dim> opposite = plane;
  for (double& c : opposite.normal) c = -c;
  opposite.offset = -opposite.offset;
  Polytope positive = start, negative = start;
  std::array<Moments<dim>, 2> m{};
  if (positive.clip(plane, 1e-13)) m[0] = positive.moments();
  if (negative.clip(opposite, 1e-13)) m[1] = negative.moments();
  if constexpr (dim == 3) {
    expect_valid_graph(positive);
    expect_valid_graph(negative);
  }
  return m;
}

// The two sides of a plane add up to the whole: measure and first moment. Planes are drawn
// at random, through vertices, through two vertices (edges in 3D), through a face, and
// parallel to a face at round-off distance.
template <int dim>
void check_two_sides_add_up(unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 400; ++trial) {
    const auto v = random_simplex<dim>(rng, 0.0, 1.0);
    typename std::conditional_t<dim == 2, ConvexPolygon, ConvexPolyhedron> start;
    if constexpr (dim == 2)
      start.assign_triangle(v);
    else
      start.assign_tetrahedron(v);
    // pre-clip by a random plane to get a general polytope, sometimes
    if (trial % 2) {
      Point<dim> normal, anchor;
      for (double& c : normal) c = g(rng);
      for (int k = 0; k < dim; ++k) anchor[k] = 0.7 * v[0][k] + 0.3 * v[1][k];
      if (!start.clip(HalfSpace<dim>::through(normal, anchor), 1e-13)) continue;
    }
    const auto whole = start.moments();
    Point<dim> normal, anchor;
    for (double& c : normal) c = g(rng);
    const auto s = make_simplex<dim>(v);
    switch (trial % 5) {
      case 0:  // random plane through an interior point
        for (int k = 0; k < dim; ++k) anchor[k] = (v[0][k] + v[1][k] + v[2][k]) / 3;
        break;
      case 1:  // through a vertex
        anchor = v[trial % (dim + 1)];
        break;
      case 2:  // through two vertices
        anchor = v[0];
        if constexpr (dim == 2) {
          normal = {v[1][1] - v[0][1], v[0][0] - v[1][0]};
        } else {
          Point<3> e{v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
          Point<3> r = normal;
          normal = {e[1] * r[2] - e[2] * r[1], e[2] * r[0] - e[0] * r[2],
                    e[0] * r[1] - e[1] * r[0]};
        }
        break;
      case 3:  // a face plane
        normal = s.gradients[1];
        anchor = v[0];
        break;
      case 4:  // parallel to a face, at round-off distance
        normal = s.gradients[0];
        anchor = v[1];
        anchor[0] += (u(rng) - 0.5) * 1e-15;
        break;
    }
    const auto [positive, negative] = halves(start, HalfSpace<dim>::through(normal, anchor));
    EXPECT_GE(positive.measure, -1e-16);
    EXPECT_GE(negative.measure, -1e-16);
    const double scale = whole.measure;
    // a snapped vertex moves volume by at most tol · height; faces: exactly on
    EXPECT_TRUE(near_relative(positive.measure + negative.measure, whole.measure, 1e-12, scale))
        << "trial " << trial;
    for (int k = 0; k < dim; ++k)
      EXPECT_TRUE(near_relative(
          positive.measure * positive.centroid[k] + negative.measure * negative.centroid[k],
          whole.measure * whole.centroid[k], 1e-12, scale))
          << "trial " << trial;
  }
}

TEST(ConvexPolygon, TwoSidesOfAnyLineAddUp) {
  check_two_sides_add_up<2>(81);
}
TEST(ConvexPolyhedron, TwoSidesOfAnyPlaneAddUp) {
  check_two_sides_add_up<3>(82);
}

TEST(ConvexPolyhedron, GraphStaysValidUnderDegenerateClips) {
  // Four clips through vertices, edges and faces of the current polyhedron (all the
  // coincidences the transfer meets on conforming meshes), checked after each one.
  std::mt19937_64 rng(83);
  std::normal_distribution<double> g;
  int max_size = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const auto v = random_simplex<3>(rng, 0.0, 1.0, 0.01);
    ConvexPolyhedron p;
    p.assign_tetrahedron(v);
    for (int clip = 0; clip < ConvexPolyhedron::max_clips && p.size() > 0; ++clip) {
      // plane through 1–3 current vertices (or a random point), random otherwise
      const int a = static_cast<int>(rng() % p.size()), b = static_cast<int>(rng() % p.size());
      const Point<3> anchor = p.vertex(a);
      const Point<3>& x = p.vertex(b);
      Point<3> r{g(rng), g(rng), g(rng)};
      const Point<3> e{x[0] - anchor[0], x[1] - anchor[1], x[2] - anchor[2]};
      const Point<3> normal = trial % 3 == 0
                                  ? r
                                  : Point<3>{e[1] * r[2] - e[2] * r[1], e[2] * r[0] - e[0] * r[2],
                                             e[0] * r[1] - e[1] * r[0]};
      const double before = p.moments().measure;
      if (!p.clip(HalfSpace<3>::through(normal, anchor), 1e-13)) break;
      expect_valid_graph(p);
      const auto m = p.moments();
      EXPECT_GE(m.measure, -1e-16);
      EXPECT_LE(m.measure, before * (1 + 1e-13) + 1e-16);
      max_size = std::max(max_size, p.size());
    }
  }
  ::testing::Test::RecordProperty("largest_polyhedron", max_size);
}

}  // namespace
}  // namespace coapt::transfer
