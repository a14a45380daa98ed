#pragma once
/// @file contact_parameters.hpp
/// The `contact:` section of a solid case, read once:
///
///   contact:
///     pairs:                              one or more master/slave pairs of boundary groups
///       - {slave: cylinder_bottom, master: plane_top}
///     complementarity_constant: 0         c [Pa/m] of the active-set test λ_n − c g > 0;
///                                         0: from the stiffness (mean K_ii / D_jj on the
///                                         slave dofs at the first linear solve)
///     search_distance: 0                  [m] 0: 10 × the mean slave facet size
///     relative_gap_tolerance: 1e-8        gaps below this × mean slave facet size are closed
///     coverage_threshold: 0.99999999      fraction of a slave node's support the master must
///                                         cover for the node to be constrained (lower:
///                                         partly covered nodes, mortar.hpp)
///     boundary_modification: true         no multipliers on the slave surface's boundary
///     max_active_set_changes: 30          Newton iterations in which the active set may
///                                         still change (then the step fails: cycling)
///     linearisation: frozen               the Newton tangent of the contact rows: frozen
///                                         (normals and mortar integrals held at the iterate)
///                                         or finite_difference (their derivative too; see
///                                         contact_constraints.hpp)
///
/// A slave surface is usually the finer and the more curved of the two. A node may be a slave
/// node of one pair only.

#include <string>
#include <vector>

#include "coapt/core/config.hpp"

namespace coapt::contact {

/// One contact pair: boundary groups of the solid's mesh.
struct ContactPair {
  std::string slave;   ///< boundary group carrying the multipliers
  std::string master;  ///< boundary group it may touch
  std::string where;   ///< location in the case file, for messages
};

/// Everything the contact code reads from the case.
struct ContactParameters {
  std::vector<ContactPair> pairs;          ///< empty: no contact
  double complementarity_constant = 0.0;   ///< c [Pa/m]; 0: automatic
  double search_distance = 0.0;            ///< [m]; 0: automatic
  double relative_gap_tolerance = 1e-8;    ///< × mean slave facet size
  double coverage_threshold = 1.0 - 1e-8;  ///< (0, 1]
  bool boundary_modification = true;
  int max_active_set_changes = 30;
  bool finite_difference_geometry = false;  ///< linearisation: finite_difference
  std::string where;                        ///< location of the section

  bool enabled() const { return !pairs.empty(); }
  /// Reads `contact:` from the case root (absent: no contact). InputError at the key.
  static ContactParameters read(const config::Section& root);
};

}  // namespace coapt::contact
