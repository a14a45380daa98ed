#include "coapt/mesh/mesh.hpp"

#include "coapt/core/error.hpp"

namespace coapt::mesh {

const PhysicalGroup* Mesh::find_group(const std::string& name) const {
  for (const auto& g : groups)
    if (g.name == name) return &g;
  return nullptr;
}

const PhysicalGroup& Mesh::group(const std::string& name) const {
  if (const auto* g = find_group(name)) return *g;
  std::string known;
  for (const auto& g : groups) known += (known.empty() ? "" : ", ") + g.name;
  throw InputError(source + ": no physical group named '" + name +
                   "' (the mesh has: " + (known.empty() ? "none" : known) + ")");
}

double signed_measure(int dim, const double* const* p) {
  if (dim == 2) {
    const double ax = p[1][0] - p[0][0], ay = p[1][1] - p[0][1];
    const double bx = p[2][0] - p[0][0], by = p[2][1] - p[0][1];
    return 0.5 * (ax * by - ay * bx);
  }
  const double a[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
  const double b[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
  const double c[3] = {p[3][0] - p[0][0], p[3][1] - p[0][1], p[3][2] - p[0][2]};
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6.0;
}

double cell_signed_measure(const Mesh& mesh, int c) {
  const auto vertices = mesh.cell(c);
  const double* points[4] = {};
  for (int k = 0; k <= mesh.dim; ++k) points[k] = mesh.point(vertices[k]).data();
  return signed_measure(mesh.dim, points);
}

}  // namespace coapt::mesh
