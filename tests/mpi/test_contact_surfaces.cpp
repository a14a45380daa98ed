// Contact surfaces on 1, 2 and 3 ranks: a surface gathered from a distributed mesh is the same
// on every rank and the same as the one gathered from the whole mesh on one rank (nodes,
// keys, coordinates, facets), so the mortar operators computed from it are identical; values
// of a distributed vertex vector are gathered at the surface nodes correctly.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../support/mesh_transforms.hpp"
#include "coapt/contact/mortar.hpp"
#include "coapt/contact/surface.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace {

using coapt::contact::Surface;
using coapt::mesh::Mesh;

Surface surface_of(const Mesh& m, const std::string& group) {
  const int tag = m.group(group).tag;
  return coapt::contact::gather_surface(m, std::span<const int>(&tag, 1), group);
}

void expect_same_surface(const Surface& a, const Surface& b) {
  ASSERT_EQ(a.n_nodes(), b.n_nodes());
  ASSERT_EQ(a.n_facets(), b.n_facets());
  EXPECT_EQ(a.key, b.key);
  EXPECT_EQ(a.reference, b.reference);
  EXPECT_EQ(a.facets, b.facets);
}

TEST(ContactSurfacesMpi, GatheredSurfacesAndMortarMatchTheSerialOnes) {
  struct Case {
    Mesh slave_whole, master_whole;
    std::string slave_group, master_group;
  };
  std::vector<Case> cases;
  cases.push_back(
      {coapt::mesh::structured_box(0, 0, 0.01, 1, 1, 1, 6, 5, 3),
       coapt::testing::rotated(coapt::mesh::structured_box(-0.5, -0.5, -1, 1.5, 1.5, 0, 7, 8, 2),
                               0.2, {0, 0, 1}, {0.5, 0.5, 0}),
       "bottom", "top"});
  cases.push_back({coapt::mesh::structured_rectangle(0, 0.02, 1, 1, 13, 4),
                   coapt::mesh::structured_rectangle(-0.3, -1, 1.4, 0, 9, 3), "bottom", "top"});
  for (const auto& c : cases) {
    const Mesh slave = coapt::mesh::distribute(c.slave_whole, MPI_COMM_WORLD);
    const Mesh master =
        coapt::mesh::distribute(c.master_whole, MPI_COMM_WORLD, coapt::mesh::Partitioner::blocks);
    const Surface s = surface_of(slave, c.slave_group), m = surface_of(master, c.master_group);
    const Surface s1 = surface_of(c.slave_whole, c.slave_group);
    const Surface m1 = surface_of(c.master_whole, c.master_group);
    expect_same_surface(s, s1);
    expect_same_surface(m, m1);
    coapt::contact::MortarOptions options;
    options.search_distance = 0.2;
    const auto op = coapt::contact::assemble_mortar(s, s.reference, m, m.reference, options);
    const auto op1 = coapt::contact::assemble_mortar(s1, s1.reference, m1, m1.reference, options);
    EXPECT_EQ(op.dual_mass, op1.dual_mass);
    EXPECT_EQ(op.weighted_gap, op1.weighted_gap);
    ASSERT_EQ(op.master_coupling.size(), op1.master_coupling.size());
    for (std::size_t k = 0; k < op.master_coupling.size(); ++k)
      EXPECT_EQ(op.master_coupling[k].value, op1.master_coupling[k].value);

    // Gather x·(1, 2, 3) + i from a distributed vector at the slave nodes.
    const int dim = slave.dim;
    auto vector = coapt::fem::create_vertex_vector(slave, dim);
    PetscScalar* data = nullptr;
    VecGetArray(vector, &data);
    for (int v = 0; v < slave.n_owned_vertices; ++v)
      for (int i = 0; i < dim; ++i) {
        double value = i;
        for (int k = 0; k < dim; ++k) value += (k + 1) * slave.point(v)[k];
        data[v * dim + i] = value;
      }
    VecRestoreArray(vector, &data);
    coapt::contact::SurfaceGather gather(s, vector);
    std::vector<double> values;
    gather.gather(vector, values);
    ASSERT_EQ(values.size(), static_cast<std::size_t>(s.n_nodes() * dim));
    for (int n = 0; n < s.n_nodes(); ++n)
      for (int i = 0; i < dim; ++i) {
        double value = i;
        for (int k = 0; k < dim; ++k) value += (k + 1) * s.reference[n * dim + k];
        EXPECT_NEAR(values[n * dim + i], value, 1e-13);
      }
  }
}

}  // namespace
