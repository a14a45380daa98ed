/// @file intersection.cpp
/// Triangle–triangle and tetrahedron–tetrahedron intersection: rejection, inclusion,
/// clipping, and the local integrals.

#include "coapt/transfer/intersection.hpp"

#include <cmath>

namespace coapt::transfer {

// ================================================================================================
// Intersection of two simplices A, B (same kernel for d = 2 and d = 3).
//
// Algorithm.
//  1. Degenerate element (measure 0) or disjoint bounding boxes: empty.
//  2. Let S be the simplex of smaller measure (A on a tie) and L the other.
//  3. β_jk = λ^L_j(s_k), the barycentric coordinates in L of the vertices of S. If for
//     some j all β_jk ≤ tol, face plane j of L separates: empty. Planes with some
//     β_jk < −tol cut S; if none does, S ⊂ L and A∩B = S.
//  4. The vertices of L are not tested against the faces of S up front: L ⊂ S needs
//     |L| ≤ |S|, so only S = L, which step 3 has found as S ⊂ L; and with an advancing
//     front nearly every pair that gets this far overlaps. A separating face plane of S
//     leaves nothing of the clipping of step 5, which then computes γ_ik = λ^S_i(l_k) to
//     tell the pair separated (some face plane of S with all γ_ik ≤ tol) from touching.
//  5. Otherwise clip S in its own reference coordinates ξ (x = s_0 + J ξ, S = the unit
//     simplex) by the half-spaces {λ^L_j ≥ 0} of the cutting planes only, where
//     λ^L_j(ξ) = β_j0 + Σ_k (β_jk − β_j0) ξ_k is known from step 3 (clipping.cpp). The
//     planes that cut off more vertices of S (β_jk < −tol) go first, so that the later
//     clips work on a small polytope (the result does not depend on the order, up to
//     round-off). In 3D the clipped polytope also says which face planes of S and of L its
//     vertices lie on (ConvexPolyhedron::touched_planes): the faces of B that A∩B touches,
//     the only ones an advancing front has to cross (LocalIntegrals::crossed_faces_b).
//  6. Moments of the clipped polytope in ξ (measure V_ξ, centroid ξ̄, central second
//     moment C_ξ); with u = (1 − Σξ, ξ) = λ^S and its covariance C_u,
//       ∫ λ^S_i λ^L_j = d!|S| Σ_k (V_ξ ū_i ū_k + C_u,ik) β_jk,
//       ∫ λ^S_i = d!|S| V_ξ ū_i,  ∫ λ^L_j = d!|S| V_ξ Σ_k β_jk ū_k,
//     exact for affine λ. When S ⊂ L the single-simplex formula
//     ∫_T λ_k λ_l = |T| (1 + δ_kl) / ((d+1)(d+2)) gives them from β directly.
//  7. Measures ≤ kMeasureTolerance · min(|A|, |B|) are reported as empty; a measure above
//     min(|A|, |B|) (round-off) is scaled back to it with all the integrals.
//
// Why reference coordinates: on a sliver S (height h ≪ size ℓ) the physical second
// moment has an eigenvalue ~ h² that round-off at the scale ℓ² wipes out, and the
// contraction with ∇λ ~ 1/h amplifies that error by (ℓ/h)². In ξ the polytope has size
// O(1) whatever the shape of S, and only L's conditioning enters, once (through β).
//
// Invariants. λ is dimensionless, so tol = kPlaneTolerance is relative to the height of
// the element owning the plane; the same snapping rule (|λ| ≤ tol counts as on the plane)
// is used by the rejection, the inclusion and the clipping tests, so a point on a shared
// face is on the same side for both elements and a mesh of cells partitions any element's
// volume (no gap, no overlap beyond tol · height). Choosing S by measure makes (A, B) and
// (B, A) perform the same arithmetic, so the results are symmetric to the bit except on
// ties. Only convex combinations and divisions by strictly positive numbers occur: no NaN
// from finite input.
// ================================================================================================

namespace {

template <int dim>
using Polytope = typename detail::PolytopeOf<dim>::type;

constexpr double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}

template <int dim>
struct Overlap {
  enum class Kind { empty, small_inside, clipped };
  Kind kind = Kind::empty;
  bool separated = true;     ///< empty by the rejection tests (false: passed them)
  unsigned b_crossed = ~0u;  ///< bit j: a vertex of A has λ^B_j < −tol (all bits: not known)
  unsigned b_touched = ~0u;  ///< bit j: A∩B may touch face j of B (clipped in 3D: it does)
  bool a_is_small = true;
  const Simplex<dim>* small = nullptr;  ///< S (A until the pair is classified)
  const Simplex<dim>* large = nullptr;  ///< L
  NodalMatrix<dim> beta;                ///< β_jk = λ^L_j(s_k) (set unless empty)
};

// table[j][k] = λ^T_j(p_k) for the vertices p_k of P, as T.barycentric(j, p_k) (same
// operations in the same order), with P's coordinates relative to the anchors transposed
// first so that the loop over the vertices is a vector operation; lowest[j] and highest[j] are the
// extremes of row j.
template <int dim>
void barycentric_table(const Simplex<dim>& t, const Simplex<dim>& p, NodalMatrix<dim>& table,
                       NodalVector<dim>& lowest, NodalVector<dim>& highest) {
  // [c][k]: coordinate c of p_k − t_1 (the anchor of λ_0) and of p_k − t_0 (that of the
  // others), formed once instead of once per row
  static_assert(Simplex<dim>::anchor(0) == 1 && Simplex<dim>::anchor(1) == 0);
  std::array<NodalVector<dim>, dim> from_1, from_0;
  for (int k = 0; k <= dim; ++k)
    for (int c = 0; c < dim; ++c) {
      from_1[c][k] = p.vertices[k][c] - t.vertices[1][c];
      from_0[c][k] = p.vertices[k][c] - t.vertices[0][c];
    }
  for (int j = 0; j <= dim; ++j) {
    const std::array<NodalVector<dim>, dim>& relative = j == 0 ? from_1 : from_0;
    const Point<dim>& gradient = t.gradients[j];
    NodalVector<dim> value{};
    for (int c = 0; c < dim; ++c)
      for (int k = 0; k <= dim; ++k) value[k] += gradient[c] * relative[c][k];
    table[j] = value;
  }
  // extremes over k for all j at once (not fmin/fmax: those are library calls here)
  for (int j = 0; j <= dim; ++j) lowest[j] = highest[j] = table[j][0];
  for (int k = 1; k <= dim; ++k)
    for (int j = 0; j <= dim; ++j) {
      lowest[j] = table[j][k] < lowest[j] ? table[j][k] : lowest[j];
      highest[j] = table[j][k] > highest[j] ? table[j][k] : highest[j];
    }
}

template <int dim>
Overlap<dim> find_overlap(const Simplex<dim>& a, const Simplex<dim>& b, Polytope<dim>& polytope) {
  using Kind = typename Overlap<dim>::Kind;
  constexpr double tol = kPlaneTolerance;
  Overlap<dim> overlap;
  overlap.small = &a;  // never null, even for an empty overlap
  overlap.large = &b;
  if (a.degenerate() || b.degenerate()) return overlap;
  for (int k = 0; k < dim; ++k)
    if (a.box_upper[k] < b.box_lower[k] || b.box_upper[k] < a.box_lower[k]) return overlap;

  overlap.a_is_small = a.measure <= b.measure;
  const Simplex<dim>& small = overlap.a_is_small ? a : b;
  const Simplex<dim>& large = overlap.a_is_small ? b : a;
  overlap.small = &small;
  overlap.large = &large;

  // 3. faces of L against the vertices of S
  NodalVector<dim> lowest, highest;
  barycentric_table(large, small, overlap.beta, lowest, highest);
  unsigned cutting = 0;
  for (int j = 0; j <= dim; ++j) {
    if (!(highest[j] > tol)) return overlap;  // separating plane
    if (lowest[j] < -tol) cutting |= 1u << j;
  }
  if (overlap.a_is_small) overlap.b_crossed = cutting;  // B = L
  overlap.separated = false;
  if (cutting == 0) {
    overlap.kind = Kind::small_inside;
    return overlap;
  }

  // 5. clip the unit simplex (S in its reference coordinates) by λ^L_j ≥ 0
  if constexpr (dim == 2) {
    polytope.assign_triangle({Point<2>{0.0, 0.0}, Point<2>{1.0, 0.0}, Point<2>{0.0, 1.0}});
  } else {
    polytope.assign_unit_tetrahedron();
  }
  // Cutting planes in the order of the number of vertices of S they cut off, most first
  // (ties in face order): the polytope the later clips work on is then small.
  std::array<int, dim + 1> order{}, cut_off{};
  int n_planes = 0;
  for (int j = 0; j <= dim; ++j) {
    if (!((cutting >> j) & 1u)) continue;
    for (int k = 0; k <= dim; ++k) cut_off[j] += overlap.beta[j][k] < -tol ? 1 : 0;
    int position = n_planes++;
    for (; position > 0 && cut_off[order[position - 1]] < cut_off[j]; --position)
      order[position] = order[position - 1];
    order[position] = j;
  }
  for (int p = 0; p < n_planes; ++p) {
    const int j = order[p];
    HalfSpace<dim> plane;
    plane.offset = overlap.beta[j][0];
    for (int k = 0; k < dim; ++k) plane.normal[k] = overlap.beta[j][k + 1] - overlap.beta[j][0];
    bool left;
    if constexpr (dim == 2) {
      left = polytope.clip(plane, tol);
    } else {
      left = polytope.clip(plane, tol, j);
    }
    if (!left) {
      // Nothing left. The vertices of L against the face planes of S tell whether one of
      // those separates (as in step 3: the front then does not go on from this pair) and,
      // when B = S, which faces of B they cross.
      NodalMatrix<dim> gamma;  // γ_ik = λ^S_i(l_k)
      barycentric_table(small, large, gamma, lowest, highest);
      unsigned crossed = 0;
      for (int i = 0; i <= dim; ++i) {
        if (!(highest[i] > tol)) overlap.separated = true;
        if (lowest[i] < -tol) crossed |= 1u << i;
      }
      if (!overlap.a_is_small) overlap.b_crossed = crossed;
      return overlap;
    }
  }
  overlap.kind = Kind::clipped;
  // The faces of B that A∩B touches (in 2D not known: all).
  if constexpr (dim == 3) {
    const unsigned touched = polytope.touched_planes();  // bits 0–3: faces of S, 4–7: of L
    overlap.b_touched = overlap.a_is_small ? touched >> 4 : touched & 0xFu;
  }
  return overlap;
}

// x = s_0 + J ξ, J = [s_1 − s_0, ..., s_d − s_0]
template <int dim>
Point<dim> to_physical(const Simplex<dim>& s, const Point<dim>& xi) {
  Point<dim> x = s.vertices[0];
  for (int c = 0; c < dim; ++c)
    for (int r = 0; r < dim; ++r) x[r] += (s.vertices[c + 1][r] - s.vertices[0][r]) * xi[c];
  return x;
}

// Physical moments of a region given by its moments in the reference coordinates of s:
// |Ω| = d!|S| V_ξ, x̄ = x(ξ̄), ∫(x − x̄)(x − x̄)ᵀ = d!|S| J C_ξ Jᵀ.
template <int dim>
Moments<dim> physical_moments(const Simplex<dim>& s, const Moments<dim>& reference,
                              bool second = true) {
  const double jacobian = factorial(dim) * s.measure;
  Moments<dim> m;
  m.measure = jacobian * reference.measure;
  m.centroid = to_physical<dim>(s, reference.centroid);
  if (!second) return m;
  std::array<Point<dim>, dim> jc{};  // J C_ξ
  for (int r = 0; r < dim; ++r)
    for (int c = 0; c < dim; ++c)
      for (int k = 0; k < dim; ++k)
        jc[r][c] += (s.vertices[k + 1][r] - s.vertices[0][r]) * reference.second[k][c];
  for (int r = 0; r < dim; ++r)
    for (int c = 0; c < dim; ++c) {
      double value = 0.0;
      for (int k = 0; k < dim; ++k) value += jc[r][k] * (s.vertices[k + 1][c] - s.vertices[0][c]);
      m.second[r][c] = jacobian * value;
    }
  return m;
}

// Measure and vertex centroid of a simplex (simplex_moments without the second moment).
template <int dim>
Moments<dim> first_moments(const Simplex<dim>& s) {
  Moments<dim> m;
  m.measure = s.measure;
  for (const auto& v : s.vertices)
    for (int k = 0; k < dim; ++k) m.centroid[k] += v[k] / (dim + 1);
  return m;
}

// Rejects round-off-sized results and scales a measure above min(|A|, |B|) back to it;
// returns the factor to apply to every integral (0 when the intersection is empty).
template <int dim>
double admissible_scale(double measure, const Simplex<dim>& a, const Simplex<dim>& b) {
  // (not std::fmin: a library call here; the measures are finite and positive)
  const double limit = a.measure < b.measure ? a.measure : b.measure;
  if (!(measure > kMeasureTolerance * limit) || !std::isfinite(measure)) return 0.0;
  return measure > limit ? limit / measure : 1.0;
}

template <int dim>
bool moments_of_intersection(const Simplex<dim>& a, const Simplex<dim>& b,
                             IntersectionWorkspace<dim>& workspace, Moments<dim>& out) {
  using Kind = typename Overlap<dim>::Kind;
  const Overlap<dim> overlap = find_overlap(a, b, workspace.polytope);
  Moments<dim> m;
  switch (overlap.kind) {
    case Kind::empty:
      break;
    case Kind::small_inside:
      m = simplex_moments(*overlap.small);
      break;
    case Kind::clipped:
      m = physical_moments(*overlap.small, workspace.polytope.moments());
      break;
  }
  const double scale = admissible_scale(m.measure, a, b);
  if (scale == 0.0) {
    out = {};
    return false;
  }
  m.measure *= scale;
  for (auto& row : m.second)
    for (double& value : row) value *= scale;
  out = m;
  return true;
}

template <int dim>
Contact integrals_of_intersection(const Simplex<dim>& a, const Simplex<dim>& b,
                                  IntersectionWorkspace<dim>& workspace, LocalIntegrals<dim>& out) {
  using Kind = typename Overlap<dim>::Kind;
  const Overlap<dim> overlap = find_overlap(a, b, workspace.polytope);
  const Simplex<dim>& small = *overlap.small;
  constexpr double pair_factor = 1.0 / ((dim + 1) * (dim + 2));
  Moments<dim> moments;
  NodalMatrix<dim> mass;  // ∫ λ^S_i λ^L_j
  NodalVector<dim> integral_s, integral_l;
  switch (overlap.kind) {
    case Kind::empty:
      out = {};
      out.crossed_faces_b = overlap.b_crossed;
      return overlap.separated ? Contact::separated : Contact::touching;
    case Kind::small_inside: {  // Ω = S: ∫_S λ^S_i λ^L_j = |S| (β_ji + Σ_k β_jk) / ((d+1)(d+2))
      moments = workspace.second_moment ? simplex_moments(small) : first_moments(small);
      for (int j = 0; j <= dim; ++j) {
        double sum = 0.0;
        for (int k = 0; k <= dim; ++k) sum += overlap.beta[j][k];
        integral_l[j] = small.measure * sum / (dim + 1);
        for (int i = 0; i <= dim; ++i)
          mass[i][j] = small.measure * pair_factor * (overlap.beta[j][i] + sum);
      }
      for (int i = 0; i <= dim; ++i) integral_s[i] = small.measure / (dim + 1);
      break;
    }
    case Kind::clipped: {
      const Moments<dim> reference = workspace.polytope.moments();
      moments = physical_moments(small, reference, workspace.second_moment);
      // ū = λ^S(ξ̄) = (1 − Σ_k ξ̄_k, ξ̄). λ^L_j(ξ) = β_j0 + Σ_l g_jl ξ_l with
      // g_jl = β_j(l+1) − β_j0 (the normal of the clipping plane j), so the covariance
      // ∫(λ^S_i − ū_i)(λ^L_j − λ^L_j(ξ̄)) / d!|S| is (C_ξ g_j)_(i−1) for i ≥ 1 and, as
      // Σ_i λ^S_i = 1, minus the sum of those for i = 0.
      NodalVector<dim> u_bar;
      u_bar[0] = 1.0;
      for (int k = 0; k < dim; ++k) {
        u_bar[k + 1] = reference.centroid[k];
        u_bar[0] -= reference.centroid[k];
      }
      const double jacobian = factorial(dim) * small.measure;
      const double volume = jacobian * reference.measure;
      for (int j = 0; j <= dim; ++j) {
        double l_bar = 0.0;  // λ^L_j(ξ̄)
        for (int k = 0; k <= dim; ++k) l_bar += overlap.beta[j][k] * u_bar[k];
        integral_l[j] = volume * l_bar;
        Point<dim> g;
        for (int l = 0; l < dim; ++l) g[l] = overlap.beta[j][l + 1] - overlap.beta[j][0];
        double rest = 0.0;
        for (int k = 0; k < dim; ++k) {
          double spread = 0.0;
          for (int l = 0; l < dim; ++l) spread += reference.second[k][l] * g[l];
          mass[k + 1][j] = volume * u_bar[k + 1] * l_bar + jacobian * spread;
          rest += spread;
        }
        mass[0][j] = volume * u_bar[0] * l_bar - jacobian * rest;
      }
      for (int i = 0; i <= dim; ++i) integral_s[i] = volume * u_bar[i];
      break;
    }
  }
  const double scale = admissible_scale(moments.measure, a, b);
  if (scale == 0.0) {
    out = {};
    out.crossed_faces_b = overlap.b_crossed;
    return Contact::touching;
  }
  if (scale != 1.0) {  // nearly always 1: then nothing to multiply
    moments.measure *= scale;
    for (auto& row : moments.second)
      for (double& value : row) value *= scale;
    for (int i = 0; i <= dim; ++i) {
      integral_s[i] *= scale;
      integral_l[i] *= scale;
      for (int j = 0; j <= dim; ++j) mass[i][j] *= scale;
    }
  }
  out.crossed_faces_b = overlap.b_crossed & overlap.b_touched;
  out.moments = moments;
  if (overlap.a_is_small) {
    out.integral_a = integral_s;
    out.integral_b = integral_l;
    out.mass = mass;
  } else {
    out.integral_a = integral_l;
    out.integral_b = integral_s;
    for (int i = 0; i <= dim; ++i)
      for (int j = 0; j <= dim; ++j) out.mass[i][j] = mass[j][i];
  }
  return Contact::overlapping;
}

template <int dim>
std::span<const QuadraturePoint<dim>> quadrature_of_intersection(
    const Simplex<dim>& a, const Simplex<dim>& b, IntersectionWorkspace<dim>& workspace) {
  using Kind = typename Overlap<dim>::Kind;
  const Overlap<dim> overlap = find_overlap(a, b, workspace.polytope);
  QuadraturePoint<dim>* points = workspace.quadrature.data();
  int n = 0;
  switch (overlap.kind) {
    case Kind::empty:
      return {};
    case Kind::small_inside:
      n = simplex_quadrature(*overlap.small, points);
      break;
    case Kind::clipped: {
      n = workspace.polytope.quadrature(points);
      const double jacobian = factorial(dim) * overlap.small->measure;
      for (int q = 0; q < n; ++q) {
        points[q].point = to_physical<dim>(*overlap.small, points[q].point);
        points[q].weight *= jacobian;
      }
      break;
    }
  }
  double measure = 0.0;
  for (int q = 0; q < n; ++q) measure += points[q].weight;
  if (admissible_scale(measure, a, b) == 0.0) return {};
  return {points, static_cast<std::size_t>(n)};
}

}  // namespace

bool intersection_moments(const Simplex<2>& a, const Simplex<2>& b,
                          IntersectionWorkspace<2>& workspace, Moments<2>& out) {
  return moments_of_intersection(a, b, workspace, out);
}
bool intersection_moments(const Simplex<3>& a, const Simplex<3>& b,
                          IntersectionWorkspace<3>& workspace, Moments<3>& out) {
  return moments_of_intersection(a, b, workspace, out);
}

bool local_integrals(const Simplex<2>& a, const Simplex<2>& b, IntersectionWorkspace<2>& workspace,
                     LocalIntegrals<2>& out) {
  return integrals_of_intersection(a, b, workspace, out) == Contact::overlapping;
}
bool local_integrals(const Simplex<3>& a, const Simplex<3>& b, IntersectionWorkspace<3>& workspace,
                     LocalIntegrals<3>& out) {
  return integrals_of_intersection(a, b, workspace, out) == Contact::overlapping;
}
Contact local_integrals_contact(const Simplex<2>& a, const Simplex<2>& b,
                                IntersectionWorkspace<2>& workspace, LocalIntegrals<2>& out) {
  return integrals_of_intersection(a, b, workspace, out);
}
Contact local_integrals_contact(const Simplex<3>& a, const Simplex<3>& b,
                                IntersectionWorkspace<3>& workspace, LocalIntegrals<3>& out) {
  return integrals_of_intersection(a, b, workspace, out);
}

std::span<const QuadraturePoint<2>> intersection_quadrature(const Simplex<2>& a,
                                                            const Simplex<2>& b,
                                                            IntersectionWorkspace<2>& workspace) {
  return quadrature_of_intersection(a, b, workspace);
}
std::span<const QuadraturePoint<3>> intersection_quadrature(const Simplex<3>& a,
                                                            const Simplex<3>& b,
                                                            IntersectionWorkspace<3>& workspace) {
  return quadrature_of_intersection(a, b, workspace);
}

}  // namespace coapt::transfer
