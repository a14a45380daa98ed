#pragma once
// Rigid motions of test meshes (shared by the serial and MPI transfer tests).

#include <array>
#include <cmath>

#include "coapt/mesh/mesh.hpp"

namespace coapt::testing {

/// Rotates the mesh's coordinates by `angle` [rad] about the axis through `centre` (Rodrigues'
/// formula); a 2D mesh is rotated in its plane whatever `axis` says.
inline mesh::Mesh rotated(mesh::Mesh m, double angle, std::array<double, 3> axis = {0, 0, 1},
                          std::array<double, 3> centre = {0.5, 0.5, 0.5}) {
  if (m.dim == 2) axis = {0, 0, 1};
  const double norm = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  for (double& a : axis) a /= norm;
  const double c = std::cos(angle), s = std::sin(angle);
  const auto& u = axis;
  const double r[3][3] = {{c + u[0] * u[0] * (1 - c), u[0] * u[1] * (1 - c) - u[2] * s,
                           u[0] * u[2] * (1 - c) + u[1] * s},
                          {u[1] * u[0] * (1 - c) + u[2] * s, c + u[1] * u[1] * (1 - c),
                           u[1] * u[2] * (1 - c) - u[0] * s},
                          {u[2] * u[0] * (1 - c) - u[1] * s, u[2] * u[1] * (1 - c) + u[0] * s,
                           c + u[2] * u[2] * (1 - c)}};
  const int d = m.dim;
  for (int v = 0; v < m.n_vertices(); ++v) {
    double x[3] = {0, 0, 0}, y[3] = {0, 0, 0};
    for (int k = 0; k < d; ++k) x[k] = m.coordinates[v * d + k] - centre[k];
    for (int i = 0; i < d; ++i)
      for (int k = 0; k < d; ++k) y[i] += r[i][k] * x[k];
    for (int k = 0; k < d; ++k) m.coordinates[v * d + k] = y[k] + centre[k];
  }
  return m;
}

}  // namespace coapt::testing
