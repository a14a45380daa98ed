#pragma once
// Shared fixtures of the element tests (test_elements.cpp, test_mixed_elements.cpp): a skewed
// reference cell and two fibre families in the x–y plane (valid in 2D and 3D).
#include "coapt/solid/elements.hpp"

namespace coapt::solid::testing {

/// Two fibre families, neither along an axis.
inline FibreDirections two_fibre_families() {
  FibreDirections f;
  f.a0[0] = Vector3(1.0, 1.0, 0.0).normalized();
  f.a0[1] = Vector3(1.0, -0.5, 0.0).normalized();
  return f;
}

/// A skewed, positively oriented reference simplex (vertex coordinates, node-major).
template <int Dim>
NodalValues<Dim> reference_cell() {
  NodalValues<Dim> x;
  if constexpr (Dim == 2)
    x << 0.1, 0.0, 1.2, 0.2, 0.3, 0.9;
  else
    x << 0.0, 0.1, 0.0, 1.1, 0.0, 0.2, 0.2, 0.9, 0.1, 0.1, 0.3, 1.0;
  return x;
}

}  // namespace coapt::solid::testing
