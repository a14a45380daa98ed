#pragma once
/// @file intersection.hpp
/// Element–element intersection for the variational transfer (exact-intersection L2
/// projection between non-matching P1 meshes): the intersection A ∩ B of two triangles
/// (2D) or two tetrahedra (3D), the local mortar integrals on it, and a quadrature on it
/// exact for degree 2 (products of two P1 functions).
///
/// The interface, per dimension d ∈ {2, 3}:
///   Simplex<d> = make_simplex<d>(vertices)          once per element (geometry.hpp)
///   IntersectionWorkspace<d>                        one per thread, reused for every pair
///   local_integrals(a, b, workspace, out) -> bool   |A∩B|, ∫λ^A_i, ∫λ^B_j, ∫λ^A_i λ^B_j
///   intersection_quadrature(a, b, workspace)        points and weights on A∩B
///   intersection_moments(a, b, workspace, out)      |A∩B|, centroid, second moment
/// and the dual-basis conversion dual_mass / dual_integrals. Nothing here allocates; the
/// functions are serial and thread-safe given one workspace per thread.
///
/// Contract for every pair: the result is finite, 0 ≤ |A∩B| ≤ min(|A|, |B|), and a pair
/// whose intersection has zero measure (disjoint, touching at a vertex, edge or face,
/// degenerate element) returns false / no points. Pairs are rejected cheaply first: by
/// bounding boxes, then by a separating face plane of the larger simplex (all vertices of the
/// smaller one on or outside it; one of the smaller simplex leaves nothing of the clipping),
/// and the smaller simplex inside the larger is recognised without clipping. See
/// intersection.cpp for the algorithm.

#include <span>

#include "coapt/transfer/clipping.hpp"
#include "coapt/transfer/geometry.hpp"

namespace coapt::transfer {

/// Classification tolerance, in units of barycentric coordinates (so relative to the height
/// of the element whose face plane is tested): a point with |λ_j| ≤ this is on face j.
inline constexpr double kPlaneTolerance = 1e-13;
/// Intersections with |A∩B| ≤ this · min(|A|, |B|) are reported as empty (round-off of a
/// touching pair).
inline constexpr double kMeasureTolerance = 1e-14;

namespace detail {
template <int dim>
struct PolytopeOf;
template <>
struct PolytopeOf<2> {
  using type = ConvexPolygon;
};
template <>
struct PolytopeOf<3> {
  using type = ConvexPolyhedron;
};
}  // namespace detail

/// Scratch space of the intersection kernels: fixed size (about 0.7 KB in 2D and 19 KB in
/// 3D, mostly the quadrature buffer), never allocates. Create one per thread and reuse it for
/// every pair; the span returned by intersection_quadrature points into it and is valid
/// until the next call with the same workspace.
template <int dim>
struct IntersectionWorkspace {
  using Polytope = typename detail::PolytopeOf<dim>::type;
  static constexpr int max_quadrature_points = Polytope::max_quadrature_points;
  Polytope polytope;
  std::array<QuadraturePoint<dim>, max_quadrature_points> quadrature{};
  /// false: local_integrals() leaves LocalIntegrals::moments.second zero (a caller that only
  /// needs the integrals saves the physical second moment; the integrals do not use it).
  bool second_moment = true;
};

/// The local integrals of the transfer operators for one pair (A, B), over A ∩ B.
template <int dim>
struct LocalIntegrals {
  Moments<dim> moments;           ///< |A∩B| [m^dim], centroid [m], second moment
  NodalVector<dim> integral_a{};  ///< ∫ λ^A_i [m^dim]
  NodalVector<dim> integral_b{};  ///< ∫ λ^B_j [m^dim]
  NodalMatrix<dim> mass{};        ///< M_ij = ∫ λ^A_i λ^B_j [m^dim], row i: A, column j: B
  /// The faces of B an advancing front has to cross (search.hpp), set by
  /// local_integrals_contact() for every pair not separated. Bit j clear: A∩B does not touch
  /// face j of B (3D overlapping pair that needed clipping: no vertex of the clipped polytope on
  /// that plane), or no vertex of A lies strictly beyond face plane j (λ^B_j ≥ −tol, from the
  /// kernel's own β / γ). All bits set: not known.
  unsigned crossed_faces_b = ~0u;
  double measure() const { return moments.measure; }
};

/// What the kernel's rejection tests say of a pair (A, B).
enum class Contact {
  separated,    ///< degenerate element, disjoint boxes or a separating face plane (step 1–4)
  touching,     ///< passed those tests, but |A∩B| has zero measure (edge–edge contact, ...)
  overlapping,  ///< |A∩B| > 0: local_integrals() returns true
};

/// Moments of A ∩ B (measure, centroid, central second moment). Returns false, with `out`
/// zeroed, when the intersection has zero measure.
bool intersection_moments(const Simplex<2>& a, const Simplex<2>& b,
                          IntersectionWorkspace<2>& workspace, Moments<2>& out);
bool intersection_moments(const Simplex<3>& a, const Simplex<3>& b,
                          IntersectionWorkspace<3>& workspace, Moments<3>& out);

/// The local integrals over A ∩ B (what the operator assembly needs). Returns false, with
/// `out` zeroed, when the intersection has zero measure. Exact up to round-off.
bool local_integrals(const Simplex<2>& a, const Simplex<2>& b, IntersectionWorkspace<2>& workspace,
                     LocalIntegrals<2>& out);
bool local_integrals(const Simplex<3>& a, const Simplex<3>& b, IntersectionWorkspace<3>& workspace,
                     LocalIntegrals<3>& out);

/// local_integrals(), also telling a pair the rejection tests dropped (Contact::separated: no
/// part of A∩B of positive measure, the advancing front does not cross it) from one that passed
/// them but has zero measure. `out` as local_integrals(); overlapping ⇔ local_integrals() true.
Contact local_integrals_contact(const Simplex<2>& a, const Simplex<2>& b,
                                IntersectionWorkspace<2>& workspace, LocalIntegrals<2>& out);
Contact local_integrals_contact(const Simplex<3>& a, const Simplex<3>& b,
                                IntersectionWorkspace<3>& workspace, LocalIntegrals<3>& out);

/// Quadrature on A ∩ B exact for polynomials of degree ≤ 2: physical points [m] and
/// positive weights [m^dim] summing to |A∩B| (a degree-2 rule per sub-simplex of a fan
/// decomposition; 3 or 4 points when one element contains the other). Empty span when the
/// intersection has zero measure. The span lives in `workspace` until its next use.
std::span<const QuadraturePoint<2>> intersection_quadrature(const Simplex<2>& a,
                                                            const Simplex<2>& b,
                                                            IntersectionWorkspace<2>& workspace);
std::span<const QuadraturePoint<3>> intersection_quadrature(const Simplex<3>& a,
                                                            const Simplex<3>& b,
                                                            IntersectionWorkspace<3>& workspace);

/// Dual basis on A: ψ^A_i = (d + 2) λ^A_i − 1 (biorthogonal on whole elements). From
/// primal integrals ∫ λ^A_i φ_j and ∫ φ_j over the same region, returns
/// ∫ ψ^A_i φ_j = (d + 2) ∫ λ^A_i φ_j − ∫ φ_j.
template <int dim>
NodalMatrix<dim> dual_mass(const NodalMatrix<dim>& primal, const NodalVector<dim>& integral_phi) {
  NodalMatrix<dim> dual;
  for (int i = 0; i <= dim; ++i)
    for (int j = 0; j <= dim; ++j) dual[i][j] = (dim + 2) * primal[i][j] - integral_phi[j];
  return dual;
}

/// ∫_{A∩B} ψ^A_i λ^B_j = (d + 2) M_ij − ∫_{A∩B} λ^B_j (the B-operator block of the pair).
template <int dim>
NodalMatrix<dim> dual_mass(const LocalIntegrals<dim>& local) {
  return dual_mass<dim>(local.mass, local.integral_b);
}

/// ∫_{A∩B} ψ^A_i = (d + 2) ∫ λ^A_i − |A∩B| (the lumped D-operator entries of the pair; can
/// be small or negative on a cut element, see the method notes).
template <int dim>
NodalVector<dim> dual_integrals(const LocalIntegrals<dim>& local) {
  NodalVector<dim> dual;
  for (int i = 0; i <= dim; ++i) dual[i] = (dim + 2) * local.integral_a[i] - local.moments.measure;
  return dual;
}

}  // namespace coapt::transfer
