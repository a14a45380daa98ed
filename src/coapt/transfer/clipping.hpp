#pragma once
/// @file clipping.hpp
/// The clipping kernels behind intersection.hpp: a convex polygon (2D) and a convex
/// polyhedron (3D) in fixed-size buffers, clipped by half-spaces, with their moments and a
/// degree-2 quadrature on a fan decomposition. No heap allocation anywhere.
///
/// Most callers want intersection.hpp; these are public for the tests and for anyone who
/// needs to clip a simplex by other planes. The algorithm, invariants and size bounds of
/// each kernel are documented at the top of its implementation in clipping.cpp.

#include <array>

#include "coapt/transfer/geometry.hpp"

namespace coapt::transfer {

/// The closed half-space {x : offset + normal · x ≥ 0}. The intersection kernels clip in
/// the reference coordinates ξ of a simplex S by the face planes of another simplex L, with
/// distance(ξ) = λ^L_j(x(ξ)) (dimensionless): a tolerance on it is relative to the height
/// of L across face j.
template <int dim>
struct HalfSpace {
  Point<dim> normal{};
  double offset = 0.0;
  double distance(const Point<dim>& x) const {
    double value = offset;
    for (int k = 0; k < dim; ++k) value += normal[k] * x[k];
    return value;
  }
  /// The half-space with this normal whose boundary passes through `point`.
  static HalfSpace through(const Point<dim>& normal, const Point<dim>& point) {
    HalfSpace h{normal, 0.0};
    for (int k = 0; k < dim; ++k) h.offset -= normal[k] * point[k];
    return h;
  }
};

/// A convex polygon, counter-clockwise, made from a triangle and clipped by at most three
/// half-planes (the bound on its size needs no more).
class ConvexPolygon {
 public:
  static constexpr int max_clips = 3;
  static constexpr int capacity = 9;  ///< vertices after 3 clips of a triangle (see clipping.cpp)
  static constexpr int max_triangles = capacity - 2;
  static constexpr int max_quadrature_points = 3 * max_triangles;

  /// Starts from a triangle (either orientation).
  void assign_triangle(const std::array<Point<2>, 3>& vertices);
  /// Keeps the part with distance ≥ 0; |distance| ≤ tolerance counts as on the line.
  /// Returns false when nothing of positive area is left (the polygon is then empty).
  bool clip(const HalfSpace<2>& half_plane, double tolerance);
  int size() const { return n_vertices_; }
  const Point<2>& vertex(int k) const { return vertices_[k]; }
  /// Area, centroid and central second moment (exact, by the fan from vertex 0).
  Moments<2> moments() const;
  /// Degree-2 rule on the fan from vertex 0 (3 points per triangle of positive area) into
  /// `points` (capacity max_quadrature_points); returns the number of points written.
  int quadrature(QuadraturePoint<2>* points) const;

 private:
  int n_vertices_ = 0;
  int n_clips_ = 0;
  std::array<Point<2>, capacity> vertices_{};
};

/// A convex polyhedron as a 3-regular vertex graph (each vertex stores its three
/// neighbours counter-clockwise seen from outside, and where it appears in each neighbour's
/// list), made from a tetrahedron and clipped by at most four half-spaces. Clipped vertices
/// stay in the buffer, unused: the vertices in use are a list of buffer slots, so a clip moves
/// no vertex and renumbers no neighbour. Each vertex also records which of the starting
/// tetrahedron's faces and of the labelled clipping planes it lies on (touched_planes()).
class ConvexPolyhedron {
 public:
  static constexpr int max_clips = 4;
  static constexpr int max_vertices = 64;  ///< after 4 clips of a tetrahedron (see clipping.cpp)
  static constexpr int buffer_size = 96;   ///< vertices ever made by 4 clips (see clipping.cpp)
  static constexpr int max_tetrahedra = 2 * max_vertices - 4;  ///< fan decomposition
  static constexpr int max_quadrature_points = 4 * max_tetrahedra;

  /// Starts from a tetrahedron (either orientation).
  void assign_tetrahedron(const std::array<Point<3>, 4>& vertices);
  /// Starts from the unit tetrahedron (0, e_1, e_2, e_3).
  void assign_unit_tetrahedron();
  /// Keeps the part with distance ≥ 0; |distance| ≤ tolerance counts as on the plane.
  /// `label` ∈ [0, 4) names the plane for touched_planes() (−1: not recorded). Returns false
  /// when nothing of positive volume is left (the polyhedron is then empty).
  bool clip(const HalfSpace<3>& half_space, double tolerance, int label = -1);
  /// The planes some vertex in use lies on: bit i (i < 4) for the face of the starting
  /// tetrahedron opposite its vertex i, bit 4 + l for the plane of a clip labelled l (on it:
  /// |distance| ≤ tolerance in that clip, or made on an edge of two vertices on it). The
  /// polyhedron lies on one side of each of these planes, so one whose bit is clear does not
  /// meet it.
  unsigned touched_planes() const;
  /// Number of vertices; vertex(v) and neighbors(v) number them 0 .. size() − 1.
  int size() const { return n_vertices_; }
  const Point<3>& vertex(int v) const { return positions_[in_use_[v]]; }
  std::array<int, 3> neighbors(int v) const;
  /// Volume, centroid and central second moment (exact, by the fan from vertex 0).
  Moments<3> moments() const;
  /// Degree-2 rule on the same fan (4 points per tetrahedron of positive volume) into
  /// `points` (capacity max_quadrature_points); returns the number of points written.
  int quadrature(QuadraturePoint<3>* points) const;

 private:
  template <class Visit>
  void for_each_fan_tetrahedron(Visit&& visit) const;

  int n_vertices_ = 0;  // in use
  int n_made_ = 0;      // buffer slots used since assign_*
  int n_clips_ = 0;
  std::array<int, max_vertices> in_use_{};  // buffer slots of the vertices, in creation order
  std::array<Point<3>, buffer_size> positions_{};
  std::array<std::array<int, 3>, buffer_size> neighbors_{};
  // back_[v][k]: the slot of v in the neighbour list of neighbors_[v][k]
  std::array<std::array<int, 3>, buffer_size> back_{};
  std::array<double, buffer_size> distances_{};      // scratch for clip()
  std::array<unsigned char, buffer_size> planes_{};  // the planes of touched_planes() it lies on
};

}  // namespace coapt::transfer
