/// @file clipping.cpp
/// Convex polygon and convex polyhedron clipping, moments and fan quadrature.

#include "coapt/transfer/clipping.hpp"

#include <cmath>

#include "coapt/core/error.hpp"

namespace coapt::transfer {

namespace {

// Degree-2 rules of geometry.hpp.
constexpr double kTriangleOther = detail::kTriangleRuleOther;
constexpr double kTriangleOwn = detail::kTriangleRuleOwn;
constexpr double kTetrahedronOwn = detail::kTetrahedronRuleOwn;
constexpr double kTetrahedronOther = detail::kTetrahedronRuleOther;

Point<3> cross(const Point<3>& a, const Point<3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Point<3>& a, const Point<3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Turns moments about a point c (measure V, m = ∫(x − c), S = ∫(x − c)(x − c)ᵀ) into the
// centroid and central second moment: x̄ = c + m/V, ∫(x − x̄)(x − x̄)ᵀ = S − m mᵀ / V.
template <int dim>
Moments<dim> central_moments(double measure, const Point<dim>& center, const Point<dim>& first,
                             const std::array<Point<dim>, dim>& second) {
  Moments<dim> m;
  m.measure = measure;
  m.centroid = center;
  if (!(measure > 0.0)) return m;
  for (int k = 0; k < dim; ++k) m.centroid[k] += first[k] / measure;
  for (int r = 0; r < dim; ++r)
    for (int c = 0; c < dim; ++c) m.second[r][c] = second[r][c] - first[r] * first[c] / measure;
  return m;
}

/// Where a convex set lies against a half-space, from its vertices.
enum class Side { inside, outside, cut };

/// Signed distances of `points[0..n)` to the half-space into `distance`, snapped to 0 within
/// `tolerance` so that a vertex on the plane is treated alike by every clip; says whether the
/// set is wholly inside (nothing to clip), wholly outside (empty) or cut.
template <int dim, class Points>
Side classify(const HalfSpace<dim>& half_space, const Points& points, int n, double tolerance,
              double* distance) {
  bool any_inside = false, any_outside = false;
  for (int k = 0; k < n; ++k) {
    double d = half_space.distance(points[k]);
    if (std::fabs(d) <= tolerance) d = 0.0;
    distance[k] = d;
    any_inside |= d > 0.0;  // | not ||: no branch per vertex
    any_outside |= d < 0.0;
  }
  if (!any_outside) return Side::inside;
  return any_inside ? Side::cut : Side::outside;
}

}  // namespace

// ================================================================================================
// Convex polygon (2D): Sutherland–Hodgman clipping by half-planes.
//
// Algorithm. The polygon is a counter-clockwise vertex cycle. Clipping by {d(x) ≥ 0}:
// compute d at every vertex and snap |d| ≤ tol to exactly 0 ("on the line"). If no vertex
// is strictly outside, nothing changes; if none is strictly inside, the rest has zero area
// and the polygon is emptied. Otherwise walk the edges (p, q): emit p when d(p) ≥ 0, and
// emit the crossing point when d(p) and d(q) have strictly opposite signs, computed from
// the strictly inside end as x = p_in + t (p_out − p_in), t = d_in / (d_in − d_out) ∈ (0, 1).
//
// Invariants. (1) The cycle stays counter-clockwise and, up to round-off, convex.
// (2) A vertex on the line is kept as it is and never duplicated: points on a shared plane
// are classified the same way by every element that has that plane, so no area is lost or
// counted twice between neighbours (the snapping moves area by at most tol · height).
// (3) No division by zero: a crossing needs d_in > 0 > d_out.
//
// Size bound. A clip keeps k vertices and adds one per crossing edge; crossings ≤ 2·(runs
// of outside vertices) ≤ min(2·outside, n), so n' ≤ n + min(outside, n − outside) ≤ 3n/2
// even for a cycle that round-off made non-convex. A triangle clipped 3 times has at most
// 3 → 4 → 6 → 9 vertices (6 in exact arithmetic: triangle ∩ triangle is at most a hexagon).
//
// Moments and quadrature use the fan of triangles (v_0, v_k, v_k+1), in coordinates
// relative to the vertex centroid c for conditioning.
// ================================================================================================

void ConvexPolygon::assign_triangle(const std::array<Point<2>, 3>& vertices) {
  const double orientation = (vertices[1][0] - vertices[0][0]) * (vertices[2][1] - vertices[0][1]) -
                             (vertices[1][1] - vertices[0][1]) * (vertices[2][0] - vertices[0][0]);
  vertices_[0] = vertices[0];
  vertices_[1] = orientation >= 0.0 ? vertices[1] : vertices[2];
  vertices_[2] = orientation >= 0.0 ? vertices[2] : vertices[1];
  n_vertices_ = 3;
  n_clips_ = 0;
}

bool ConvexPolygon::clip(const HalfSpace<2>& half_plane, double tolerance) {
  if (n_vertices_ == 0) return false;
  std::array<double, capacity> distance;
  const Side side = classify<2>(half_plane, vertices_, n_vertices_, tolerance, distance.data());
  if (side == Side::inside) return true;
  if (side == Side::outside) {
    n_vertices_ = 0;
    return false;
  }
  COAPT_ASSERT(n_clips_ < max_clips, "a triangle is clipped by at most 3 half-planes");
  std::array<Point<2>, 2 * capacity> clipped;  // ≤ capacity by the bound above
  int n = 0;
  for (int k = 0; k < n_vertices_; ++k) {
    const int next = k + 1 == n_vertices_ ? 0 : k + 1;
    const double dp = distance[k], dq = distance[next];
    if (dp >= 0.0) clipped[n++] = vertices_[k];
    if ((dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0)) {
      const Point<2>& in = dp > 0.0 ? vertices_[k] : vertices_[next];
      const Point<2>& out = dp > 0.0 ? vertices_[next] : vertices_[k];
      const double d_in = dp > 0.0 ? dp : dq, d_out = dp > 0.0 ? dq : dp;
      const double t = d_in / (d_in - d_out);
      clipped[n++] = {in[0] + t * (out[0] - in[0]), in[1] + t * (out[1] - in[1])};
    }
  }
  COAPT_ASSERT(n <= capacity, "polygon clipping exceeded its size bound");
  for (int k = 0; k < n; ++k) vertices_[k] = clipped[k];
  n_vertices_ = n;
  ++n_clips_;
  return true;
}

Moments<2> ConvexPolygon::moments() const {
  if (n_vertices_ < 3) return {};
  Point<2> center{};
  for (int k = 0; k < n_vertices_; ++k)
    for (int c = 0; c < 2; ++c) center[c] += vertices_[k][c] / n_vertices_;
  std::array<Point<2>, capacity> q;
  for (int k = 0; k < n_vertices_; ++k)
    q[k] = {vertices_[k][0] - center[0], vertices_[k][1] - center[1]};
  // Triangle (a, b, c): |T| = ((b − a) × (c − a)) / 2, ∫x = |T| s / 3,
  // ∫x xᵀ = |T| / 12 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c.
  double area = 0.0;
  Point<2> first{};
  double s00 = 0.0, s01 = 0.0, s11 = 0.0;
  const Point<2>& a = q[0];
  for (int k = 1; k + 1 < n_vertices_; ++k) {
    const Point<2>& b = q[k];
    const Point<2>& c = q[k + 1];
    const double t = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    const Point<2> s{a[0] + b[0] + c[0], a[1] + b[1] + c[1]};
    area += t;
    first[0] += t * s[0] / 3.0;
    first[1] += t * s[1] / 3.0;
    const double w = t / 12.0;
    s00 += w * (a[0] * a[0] + b[0] * b[0] + c[0] * c[0] + s[0] * s[0]);
    s01 += w * (a[0] * a[1] + b[0] * b[1] + c[0] * c[1] + s[0] * s[1]);
    s11 += w * (a[1] * a[1] + b[1] * b[1] + c[1] * c[1] + s[1] * s[1]);
  }
  return central_moments<2>(area, center, first, {Point<2>{s00, s01}, Point<2>{s01, s11}});
}

int ConvexPolygon::quadrature(QuadraturePoint<2>* points) const {
  int n = 0;
  const Point<2>& a = vertices_[0];
  for (int k = 1; k + 1 < n_vertices_; ++k) {
    const Point<2>& b = vertices_[k];
    const Point<2>& c = vertices_[k + 1];
    const Point<2> ab{b[0] - a[0], b[1] - a[1]}, ac{c[0] - a[0], c[1] - a[1]};
    const double area = 0.5 * (ab[0] * ac[1] - ab[1] * ac[0]);
    if (!(area > 0.0)) continue;
    // x = a + ξ (b − a) + η (c − a) at (ξ, η) ∈ {(1/6, 1/6), (2/3, 1/6), (1/6, 2/3)}
    const std::array<std::array<double, 2>, 3> local{{{kTriangleOther, kTriangleOther},
                                                      {kTriangleOwn, kTriangleOther},
                                                      {kTriangleOther, kTriangleOwn}}};
    for (const auto& [xi, eta] : local) {
      points[n].point = {a[0] + xi * ab[0] + eta * ac[0], a[1] + xi * ab[1] + eta * ac[1]};
      points[n].weight = area / 3.0;
      ++n;
    }
  }
  return n;
}

// ================================================================================================
// Convex polyhedron (3D): clipping of a vertex graph by half-spaces (the scheme of r3d,
// Powell & Abel, J. Comput. Phys. 2015).
//
// Representation. Every vertex has exactly three neighbours, stored counter-clockwise as
// seen from outside. A face is a cycle found by walking: arriving at w from v, where
// neighbors(w)[j] == v, the next vertex of the same face is neighbors(w)[(j + 1) % 3];
// these walks go clockwise seen from outside. A vertex where more than three faces meet
// (a tetrahedron apex touching a plane, coplanar faces, ...) is represented by several
// coincident vertices joined by zero-length edges, so the graph stays 3-regular whatever
// the geometry and every operation below is purely combinatorial once the vertices are
// classified.
//
// Storage. A clip appends its new vertices to the buffer and leaves the clipped ones where
// they are; the vertices in use are the list in_use_ of buffer slots (kept vertices in their
// old order, then the new ones in creation order, which is the numbering vertex(v) and
// neighbors(v) expose). Besides its neighbours, each vertex stores back_[v][k], the slot of v
// in the list of neighbors_[v][k], so walking a face is a table look-up per step.
//
// Clip by {d(x) ≥ 0}. (1) Compute d at every vertex, snap |d| ≤ tol to exactly 0. No vertex
// strictly outside: unchanged. No vertex strictly inside: empty (zero volume is left).
// (2) For every edge (v kept, w clipped, i.e. d(v) ≥ 0 > d(w)) add a vertex n at
// x = x_v + t (x_w − x_v), t = d_v / (d_v − d_w) ∈ [0, 1), with neighbors(n)[0] = v, and
// make v point to n instead of w. (3) Link the new vertices: from each new vertex s, step to
// its kept neighbour and walk along the face until the next new vertex e; then
// neighbors(s)[2] = e and neighbors(e)[1] = s. This closes every cut face and builds the
// cap face(s) on the plane with the right orientation. (4) The kept and the new vertices
// are the vertices in use; the clipped ones are no longer referenced.
//
// Planes touched. planes_[v] has a bit per plane v lies on: the starting faces through v,
// the plane of every labelled clip that classified v at distance 0, and for a new vertex the
// clip's own plane and the planes both ends of its edge lie on (the edge lies in them).
//
// Invariants. The graph is 3-regular with a consistent rotation after every clip, for any
// pattern of clipped vertices (step 3 pairs the two new vertices that bound each run of
// kept vertices along each face), so the fan decomposition below always describes closed
// surfaces and the volume is never lost or double counted by the topology. Vertices on
// the plane are kept as they are (their new neighbour coincides with them): as in 2D, a
// point on a shared plane is classified the same way from both sides. No division by zero.
//
// Size bound. With V vertices (E = 3V/2 edges), a clip adds one vertex per (kept, clipped)
// edge: at most 3·min(kept, clipped) ≤ 3V/2 new, so V' = kept + new ≤ 2V: V ≤ 8, 16, 32, 64
// after 1..4 clips of a tetrahedron, and the buffer, which keeps the clipped vertices, holds
// at most 4 + 6 + 12 + 24 + 48 = 94 vertices. Geometrically tet ∩ tet has at most 8 faces and
// 2·8 − 4 = 12 vertices; the larger bound covers coincident vertices and round-off.
//
// Moments and quadrature: each face cycle (f_0, f_1, ..., f_m) not through vertex 0 is cut
// into triangles (f_0, f_k+1, f_k) (outward orientation), each coned to vertex 0 into a
// tetrahedron (the faces through vertex 0 would give flat ones). The polyhedron is convex,
// so all these volumes are ≥ 0 up to round-off. At most Σ_faces (m_f − 2) = 2V − 4
// tetrahedra, minus those of the three faces through vertex 0.
// ================================================================================================

namespace {
constexpr std::array<int, 3> kNextSlot{1, 2, 0};
}  // namespace

void ConvexPolyhedron::assign_tetrahedron(const std::array<Point<3>, 4>& vertices) {
  const Point<3> e1{vertices[1][0] - vertices[0][0], vertices[1][1] - vertices[0][1],
                    vertices[1][2] - vertices[0][2]};
  const Point<3> e2{vertices[2][0] - vertices[0][0], vertices[2][1] - vertices[0][1],
                    vertices[2][2] - vertices[0][2]};
  const Point<3> e3{vertices[3][0] - vertices[0][0], vertices[3][1] - vertices[0][1],
                    vertices[3][2] - vertices[0][2]};
  const bool positive = dot(e1, cross(e2, e3)) >= 0.0;
  positions_[0] = vertices[0];
  positions_[1] = positive ? vertices[1] : vertices[2];
  positions_[2] = positive ? vertices[2] : vertices[1];
  positions_[3] = vertices[3];
  // Counter-clockwise neighbours seen from outside for a positively oriented tetrahedron,
  // and the slot of each vertex in its neighbours' lists.
  neighbors_[0] = {1, 3, 2};
  neighbors_[1] = {2, 3, 0};
  neighbors_[2] = {0, 3, 1};
  neighbors_[3] = {1, 2, 0};
  back_[0] = {2, 2, 0};
  back_[1] = {2, 0, 0};
  back_[2] = {2, 1, 0};
  back_[3] = {1, 1, 1};
  in_use_[0] = 0;
  in_use_[1] = 1;
  in_use_[2] = 2;
  in_use_[3] = 3;
  // vertex v lies on every face but the one opposite it (1 and 2 swapped with the vertices)
  planes_[0] = 0b1110;
  planes_[1] = positive ? 0b1101 : 0b1011;
  planes_[2] = positive ? 0b1011 : 0b1101;
  planes_[3] = 0b0111;
  n_vertices_ = 4;
  n_made_ = 4;
  n_clips_ = 0;
}

void ConvexPolyhedron::assign_unit_tetrahedron() {
  assign_tetrahedron({Point<3>{0.0, 0.0, 0.0}, Point<3>{1.0, 0.0, 0.0}, Point<3>{0.0, 1.0, 0.0},
                      Point<3>{0.0, 0.0, 1.0}});
}

std::array<int, 3> ConvexPolyhedron::neighbors(int v) const {
  std::array<int, 3> numbers{};
  for (int k = 0; k < 3; ++k) {
    const int slot = neighbors_[in_use_[v]][k];
    int number = 0;
    while (number < n_vertices_ && in_use_[number] != slot) ++number;
    numbers[k] = number < n_vertices_ ? number : -1;
  }
  return numbers;
}

unsigned ConvexPolyhedron::touched_planes() const {
  unsigned touched = 0;
  for (int u = 0; u < n_vertices_; ++u) touched |= planes_[in_use_[u]];
  return touched;
}

bool ConvexPolyhedron::clip(const HalfSpace<3>& half_space, double tolerance, int label) {
  if (n_vertices_ == 0) return false;
  COAPT_ASSERT(label >= -1 && label < 4, "a clipping plane label lies in [0, 4)");
  const unsigned char plane = label < 0 ? 0 : static_cast<unsigned char>(1u << (4 + label));
  // (1) classify (as classify() above, through the list of vertices in use)
  bool any_inside = false, any_outside = false;
  for (int u = 0; u < n_vertices_; ++u) {
    const int v = in_use_[u];
    double d = half_space.distance(positions_[v]);
    if (std::fabs(d) <= tolerance) {
      d = 0.0;
      planes_[v] |= plane;
    }
    distances_[v] = d;
    any_inside |= d > 0.0;
    any_outside |= d < 0.0;
  }
  if (!any_outside) return true;
  if (!any_inside) {
    n_vertices_ = 0;
    return false;
  }
  COAPT_ASSERT(n_clips_ < max_clips, "a tetrahedron is clipped by at most 4 half-spaces");

  // (2) one new vertex on every (kept, clipped) edge; the kept vertices stay in use, in order
  const int first_new = n_made_;
  int n = n_made_;
  int kept = 0;
  for (int u = 0; u < n_vertices_; ++u) {
    const int v = in_use_[u];
    const double dv = distances_[v];
    if (dv < 0.0) continue;
    in_use_[kept++] = v;
    for (int k = 0; k < 3; ++k) {
      const int w = neighbors_[v][k];
      const double dw = distances_[w];
      if (dw >= 0.0) continue;
      // (the size bound above; checked per clip below, per vertex in Debug builds)
      COAPT_DEBUG_ASSERT(n < buffer_size, "polyhedron clipping exceeded its size bound");
      const double t = dv / (dv - dw);
      const Point<3>& x = positions_[v];
      const Point<3>& y = positions_[w];
      positions_[n] = {x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1]),
                       x[2] + t * (y[2] - x[2])};
      neighbors_[n][0] = v;
      back_[n][0] = k;
      distances_[n] = 0.0;
      planes_[n] = static_cast<unsigned char>((planes_[v] & planes_[w]) | plane);
      neighbors_[v][k] = n;
      back_[v][k] = 0;
      ++n;
    }
  }
  COAPT_ASSERT(n <= buffer_size && kept + n - first_new <= max_vertices,
               "polyhedron clipping exceeded its size bound");

  // (3) link consecutive new vertices along each face
  for (int start = first_new; start < n; ++start) {
    int current = start;
    int slot = 0;
    [[maybe_unused]] int steps = 0;
    do {
      const int next = neighbors_[current][slot];
      slot = kNextSlot[back_[current][slot]];
      current = next;
      // (the walk ends: the graph is 3-regular with a consistent rotation, see above)
      COAPT_DEBUG_ASSERT(++steps <= n, "polyhedron graph is inconsistent");
    } while (current < first_new);
    neighbors_[start][2] = current;
    back_[start][2] = 1;
    neighbors_[current][1] = start;
    back_[current][1] = 2;
  }

  // (4) the new vertices join the kept ones
  for (int v = first_new; v < n; ++v) in_use_[kept++] = v;
  n_vertices_ = kept;
  n_made_ = n;
  ++n_clips_;
  return true;
}

// Calls visit(a, b, c) with the buffer slots of every fan tetrahedron (apex, a, b, c),
// positively oriented, apex = vertex 0. The faces through the apex would give flat
// tetrahedra and are skipped.
template <class Visit>
void ConvexPolyhedron::for_each_fan_tetrahedron(Visit&& visit) const {
  const int apex = in_use_[0];
  std::array<unsigned char, buffer_size> visited;  // bit k: the edge (v, neighbors(v)[k]) walked
  for (int u = 0; u < n_vertices_; ++u) visited[in_use_[u]] = 0;
  // Walks the face to the left of the directed edge (start, neighbors(start)[slot]),
  // marking its edges, and gives its fan triangles (start, next, current) to `triangle`.
  const auto walk = [&](int start, int slot, auto&& triangle) {
    visited[start] |= static_cast<unsigned char>(1u << slot);
    int current = neighbors_[start][slot];
    int back = back_[start][slot];
    for ([[maybe_unused]] int steps = 0;; ++steps) {
      COAPT_DEBUG_ASSERT(steps < n_vertices_, "polyhedron graph is inconsistent");  // as in clip()
      const int out = kNextSlot[back];
      visited[current] |= static_cast<unsigned char>(1u << out);
      const int next = neighbors_[current][out];
      if (next == start) return;
      triangle(start, next, current);  // the walk is clockwise from outside
      back = back_[current][out];
      current = next;
    }
  };
  const auto skip = [](int, int, int) {};
  for (int slot = 0; slot < 3; ++slot) walk(apex, slot, skip);
  for (int u = 1; u < n_vertices_; ++u) {
    // A walk from `start` returns before it reaches `start` again, so the edges of `start`
    // left to walk are known before the first one.
    const int start = in_use_[u];
    const unsigned todo = ~visited[start] & 7u;
    if (todo & 1u) walk(start, 0, visit);
    if (todo & 2u) walk(start, 1, visit);
    if (todo & 4u) walk(start, 2, visit);
  }
}

Moments<3> ConvexPolyhedron::moments() const {
  if (n_vertices_ < 4) return {};
  const Point<3> center = positions_[in_use_[0]];
  // Tetrahedron (0, a, b, c): |T| = a · (b × c) / 6, ∫x = |T| s / 4,
  // ∫x xᵀ = |T| / 20 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c, positions relative to the apex.
  std::array<Point<3>, buffer_size> q;
  for (int u = 0; u < n_vertices_; ++u)
    for (int c = 0; c < 3; ++c) q[in_use_[u]][c] = positions_[in_use_[u]][c] - center[c];
  double volume = 0.0;
  Point<3> first{};
  std::array<double, 6> s{};  // xx, yy, zz, xy, xz, yz
  for_each_fan_tetrahedron([&](int ia, int ib, int ic) {
    const Point<3>& a = q[ia];
    const Point<3>& b = q[ib];
    const Point<3>& c = q[ic];
    const double t = dot(a, cross(b, c)) / 6.0;
    const Point<3> sum{a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]};
    volume += t;
    const double w1 = 0.25 * t;
    for (int k = 0; k < 3; ++k) first[k] += w1 * sum[k];
    const double w2 = t / 20.0;
    const auto product = [&](int i, int j) {
      return a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + sum[i] * sum[j];
    };
    s[0] += w2 * product(0, 0);
    s[1] += w2 * product(1, 1);
    s[2] += w2 * product(2, 2);
    s[3] += w2 * product(0, 1);
    s[4] += w2 * product(0, 2);
    s[5] += w2 * product(1, 2);
  });
  return central_moments<3>(
      volume, center, first,
      {Point<3>{s[0], s[3], s[4]}, Point<3>{s[3], s[1], s[5]}, Point<3>{s[4], s[5], s[2]}});
}

int ConvexPolyhedron::quadrature(QuadraturePoint<3>* points) const {
  if (n_vertices_ < 4) return 0;
  const Point<3> center = positions_[in_use_[0]];
  std::array<Point<3>, buffer_size> q;
  for (int u = 0; u < n_vertices_; ++u)
    for (int c = 0; c < 3; ++c) q[in_use_[u]][c] = positions_[in_use_[u]][c] - center[c];
  int n = 0;
  for_each_fan_tetrahedron([&](int ia, int ib, int ic) {
    const Point<3>& a = q[ia];
    const Point<3>& b = q[ib];
    const Point<3>& c = q[ic];
    const double volume = dot(a, cross(b, c)) / 6.0;
    if (!(volume > 0.0)) return;
    // vertex k of (0, a, b, c) gets α x_k + β (sum of the others) = β s + (α − β) x_k
    const Point<3> sum{a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]};
    const Point<3> zero{};
    for (const Point<3>* x : {&zero, &a, &b, &c}) {
      for (int k = 0; k < 3; ++k)
        points[n].point[k] = center[k] + kTetrahedronOther * sum[k] +
                             (kTetrahedronOwn - kTetrahedronOther) * (*x)[k];
      points[n].weight = 0.25 * volume;
      ++n;
    }
  });
  return n;
}

}  // namespace coapt::transfer
