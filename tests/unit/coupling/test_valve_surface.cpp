// The part of a valve's upstream surfaces that counts in the swept flow (coupling/
// valve_surface.hpp): the nodes reached from the clamped ones without crossing the contact
// zone, and the contact zone itself (active slave nodes, master nodes the active multipliers
// cover over at least half their support), on surfaces where both are known by hand.
#include <gtest/gtest.h>

#include <vector>

#include "coapt/contact/mortar.hpp"
#include "coapt/contact/surface.hpp"
#include "coapt/coupling/valve_surface.hpp"
#include "coapt/mesh/generators.hpp"

namespace coapt::coupling {
namespace {

using contact::make_surface;

/// A polyline of n + 1 nodes along x at y, spacing h from x0, its segments oriented so that
/// the outward normal is +y (up = true) or −y.
contact::Surface polyline(int n, double x0, double h, double y, bool up,
                          std::vector<double>& coordinates) {
  coordinates.clear();
  std::vector<int> facets;
  for (int i = 0; i <= n; ++i) {
    coordinates.push_back(x0 + h * i);
    coordinates.push_back(y);
  }
  // (b − a) turned clockwise is the outward normal: left to right gives −y
  for (int i = 0; i < n; ++i) {
    facets.push_back(up ? i + 1 : i);
    facets.push_back(up ? i : i + 1);
  }
  return make_surface(2, coordinates, facets);
}

TEST(ValveSurface, ReachedNodesStopAtABlockedNodeOfAPolyline) {
  std::vector<double> x;
  const auto line = polyline(6, 0.0, 1.0, 0.0, true, x);
  std::vector<char> seed(7, 0), blocked(7, 0);
  seed[0] = 1;
  EXPECT_EQ(reached_nodes(line, seed, blocked), std::vector<char>(7, 1));
  blocked[3] = 1;
  EXPECT_EQ(reached_nodes(line, seed, blocked), (std::vector<char>{1, 1, 1, 0, 0, 0, 0}));
  blocked[0] = 1;  // a blocked seed starts nothing
  EXPECT_EQ(reached_nodes(line, seed, blocked), std::vector<char>(7, 0));
}

TEST(ValveSurface, ReachedNodesCrossAStripOnlyWhereNoChainOfBlockedNodesCutsIt) {
  // a strip of 3 × 5 nodes (node = 5 row + column), two triangles per square; seed: column 0
  std::vector<double> x;
  std::vector<int> triangles;
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 5; ++column) x.insert(x.end(), {1.0 * column, 1.0 * row, 0.0});
  for (int row = 0; row < 2; ++row)
    for (int column = 0; column < 4; ++column) {
      const int a = 5 * row + column, b = a + 1, c = a + 6, d = a + 5;
      triangles.insert(triangles.end(), {a, b, c, a, c, d});
    }
  const auto strip = make_surface(3, x, triangles);
  std::vector<char> seed(15, 0), blocked(15, 0);
  for (int row = 0; row < 3; ++row) seed[5 * row] = 1;
  // column 2 blocked in rows 0 and 1 only: the path through row 2 stays open
  blocked[2] = blocked[7] = 1;
  auto reached = reached_nodes(strip, seed, blocked);
  EXPECT_EQ(reached[4], 1);
  EXPECT_EQ(reached[2], 0);
  // the whole column blocked: nothing beyond it
  blocked[12] = 1;
  reached = reached_nodes(strip, seed, blocked);
  for (int row = 0; row < 3; ++row) {
    EXPECT_EQ(reached[5 * row + 1], 1) << row;
    EXPECT_EQ(reached[5 * row + 3], 0) << row;
    EXPECT_EQ(reached[5 * row + 4], 0) << row;
  }
}

TEST(ValveSurface, ContactZoneIsTheActiveSlaveNodesAndTheMasterNodesTheyCover) {
  // slave: y = 0, x in [0, 1], 10 segments, normal +y; master: y = 0, x in [0.3, 1.3],
  // 10 segments, normal −y, its nodes on the slave's. Active slave nodes at x = 0.5, 0.6,
  // 0.7: Σ_A Φ̃_j is 1 on [0.5, 0.7] and 3 N − 1 on the segments either side, so the master
  // nodes at 0.5, 0.6, 0.7 are covered wholly and those at 0.4 and 0.8 not at all
  // (∫ (3 N_j − 1)(1 − N_j) = 0 over a segment).
  contact::PairState pair;
  pair.slave = polyline(10, 0.0, 0.1, 0.0, true, pair.slave_x);
  pair.master = polyline(10, 0.3, 0.1, 0.0, false, pair.master_x);
  for (auto& vertex : pair.master.global_vertex) vertex += 100;
  contact::MortarOptions options;
  options.search_distance = 0.05;
  options.coverage_threshold = 0.5;
  pair.mortar =
      contact::assemble_mortar(pair.slave, pair.slave_x, pair.master, pair.master_x, options);
  pair.active.assign(11, 0);
  EXPECT_TRUE(contact_zone_vertices({pair}).empty());
  pair.active[5] = pair.active[6] = pair.active[7] = 1;
  // master node k sits at x = 0.3 + 0.1 k: 0.5, 0.6, 0.7 are nodes 2, 3, 4 (global 102-104)
  EXPECT_EQ(contact_zone_vertices({pair}), (std::vector<PetscInt>{5, 6, 7, 102, 103, 104}));
}

TEST(ValveSurface, PointsInMeshIncludeItsBoundary) {
  // the unit square, 4 x 4 squares; points inside, on an edge, at a corner and outside
  const auto square = mesh::structured_rectangle(0.0, 0.0, 1.0, 1.0, 4, 4);
  const std::vector<double> points{0.5,  0.5, 1.0, 0.3, 0.0,   0.0,    0.3,
                                   0.25, 1.2, 0.5, 0.5, -1e-3, -1e-12, 0.5};
  EXPECT_EQ(points_in_mesh(square, points), (std::vector<char>{1, 1, 1, 1, 0, 0, 1}));
  // a box, in 3D
  const auto box = mesh::structured_box(0.0, 0.0, 0.0, 1.0, 2.0, 1.0, 2, 2, 2);
  const std::vector<double> points3{0.5, 1.5, 0.5, 1.0, 2.0, 1.0, 0.5, 2.1, 0.5};
  EXPECT_EQ(points_in_mesh(box, points3), (std::vector<char>{1, 1, 0}));
}

TEST(ValveSurface, PointsInMeshFindTheCellOfEveryPointOfAFineMesh) {
  // 6 x 5 x 4 boxes of 6 tetrahedra, 1000 points in a box 20 % larger on every side: a point
  // is in the mesh exactly when it is in [0, 1.2] x [0, 1] x [0, 0.8] (none lies within
  // 1e-9 of a face), whichever of the grid's bins holds it
  const auto box = mesh::structured_box(0.0, 0.0, 0.0, 1.2, 1.0, 0.8, 6, 5, 4);
  const double upper[3] = {1.2, 1.0, 0.8};
  std::vector<double> points;
  std::vector<char> expected;
  unsigned state = 12345;
  const auto uniform = [&state] {  // a fixed linear congruential sequence in [0, 1)
    state = state * 1103515245u + 12345u;
    return static_cast<double>((state >> 8) & 0xffffu) / 65536.0;
  };
  for (int p = 0; p < 1000; ++p) {
    bool in = true;
    for (int i = 0; i < 3; ++i) {
      const double x = upper[i] * (1.4 * uniform() - 0.2);
      points.push_back(x);
      in = in && x >= 0.0 && x <= upper[i];
    }
    expected.push_back(in ? 1 : 0);
  }
  EXPECT_EQ(points_in_mesh(box, points), expected);
}

}  // namespace
}  // namespace coapt::coupling
