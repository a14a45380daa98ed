// Distribution and assembly on any number of ranks: every cell owned once, contiguous global
// numbering, a complete ghost layer, ghost updates, and the communication-free CSR assembly
// equal to a plain MatSetValues assembly.
#include <gtest/gtest.h>

#include <cmath>

#include "coapt/core/context.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/kernels.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace {

using coapt::mesh::Mesh;
using coapt::mesh::Partitioner;

Mesh distributed_box(Partitioner partitioner, int n = 5) {
  Mesh whole;
  if (coapt::rank_of(MPI_COMM_WORLD) == 0)
    whole = coapt::mesh::structured_box(0, 0, 0, 1, 2, 3, n, n + 1, n + 2);
  return coapt::mesh::distribute(whole, MPI_COMM_WORLD, partitioner);
}

Mesh distributed_square(Partitioner partitioner, int n = 9) {
  Mesh whole;
  if (coapt::rank_of(MPI_COMM_WORLD) == 0)
    whole = coapt::mesh::structured_rectangle(0, 0, 2, 1, n, n + 2);
  return coapt::mesh::distribute(whole, MPI_COMM_WORLD, partitioner);
}

double sum_over_ranks(double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return value;
}

class Distribution : public ::testing::TestWithParam<Partitioner> {};

TEST_P(Distribution, OwnsEveryCellAndVertexOnce) {
  for (const Mesh& mesh : {distributed_box(GetParam()), distributed_square(GetParam())}) {
    const double volume = mesh.dim == 3 ? 6.0 : 2.0;
    double owned_measure = 0;
    for (int c = 0; c < mesh.n_owned_cells; ++c)
      owned_measure += std::abs(coapt::mesh::cell_signed_measure(mesh, c));
    EXPECT_NEAR(sum_over_ranks(owned_measure), volume, 1e-12);
    EXPECT_EQ(sum_over_ranks(mesh.n_owned_cells), static_cast<double>(mesh.n_global_cells));
    EXPECT_EQ(sum_over_ranks(mesh.n_owned_vertices), static_cast<double>(mesh.n_global_vertices));
    // Contiguous ownership: rank r owns [offset_r, offset_r + n_owned_r).
    PetscInt offset = 0, n_owned = mesh.n_owned_vertices;
    MPI_Exscan(&n_owned, &offset, 1, MPIU_INT, MPI_SUM, MPI_COMM_WORLD);
    if (coapt::rank_of(MPI_COMM_WORLD) == 0) offset = 0;
    EXPECT_EQ(mesh.vertex_offset, offset);
    for (int v = 0; v < mesh.n_owned_vertices; ++v) EXPECT_EQ(mesh.global_vertex[v], offset + v);
    for (int v = mesh.n_owned_vertices; v < mesh.n_vertices(); ++v)
      EXPECT_TRUE(mesh.global_vertex[v] < offset || mesh.global_vertex[v] >= offset + n_owned);
    // Complete ghost layer: every owned vertex sees the full measure of its surrounding cells,
    // so the lumped mass summed over local cells equals the owned vertices' share of the volume.
    std::vector<double> lumped(static_cast<std::size_t>(mesh.n_vertices()), 0.0);
    for (int c = 0; c < mesh.n_cells(); ++c)
      for (int v : mesh.cell(c))
        lumped[v] += std::abs(coapt::mesh::cell_signed_measure(mesh, c)) / (mesh.dim + 1);
    double owned_lumped = 0;
    for (int v = 0; v < mesh.n_owned_vertices; ++v) owned_lumped += lumped[v];
    EXPECT_NEAR(sum_over_ranks(owned_lumped), volume, 1e-12);
    // Boundary facets: each counted once through its owned cell; the boundary measure is known.
    double boundary = 0;
    for (int f = 0; f < mesh.n_facets(); ++f) {
      if (mesh.facet_cell[f] >= mesh.n_owned_cells) continue;
      const int* v = mesh.facets.data() + static_cast<std::size_t>(f) * mesh.dim;
      if (mesh.dim == 2) {
        boundary += std::hypot(mesh.point(v[1])[0] - mesh.point(v[0])[0],
                               mesh.point(v[1])[1] - mesh.point(v[0])[1]);
      } else {
        double a[3], b[3];
        for (int d = 0; d < 3; ++d) {
          a[d] = mesh.point(v[1])[d] - mesh.point(v[0])[d];
          b[d] = mesh.point(v[2])[d] - mesh.point(v[0])[d];
        }
        boundary += 0.5 * std::sqrt(std::pow(a[1] * b[2] - a[2] * b[1], 2) +
                                    std::pow(a[2] * b[0] - a[0] * b[2], 2) +
                                    std::pow(a[0] * b[1] - a[1] * b[0], 2));
      }
    }
    EXPECT_NEAR(sum_over_ranks(boundary), mesh.dim == 3 ? 22.0 : 6.0, 1e-12);
  }
}

TEST_P(Distribution, GhostUpdateBringsOwnersValues) {
  const Mesh mesh = distributed_box(GetParam());
  auto vector = coapt::fem::create_vertex_vector(mesh, 2);
  PetscScalar* data = nullptr;
  VecGetArray(vector, &data);
  for (int v = 0; v < mesh.n_owned_vertices; ++v)
    for (int i = 0; i < 2; ++i)
      data[2 * v + i] = 10.0 * static_cast<double>(mesh.global_vertex[v]) + i;
  VecRestoreArray(vector, &data);
  coapt::fem::update_ghosts(vector);
  coapt::fem::LocalValues local(vector);
  ASSERT_EQ(local.values().size(), static_cast<std::size_t>(mesh.n_vertices()) * 2);
  for (int v = 0; v < mesh.n_vertices(); ++v)
    for (int i = 0; i < 2; ++i)
      EXPECT_EQ(local[2 * v + i], 10.0 * static_cast<double>(mesh.global_vertex[v]) + i);
}

TEST_P(Distribution, CellGhostUpdateBringsOwnersValues) {
  // Owned cells numbered rank by rank (contiguous, matching a PETSc layout), and a ghost cell
  // receives its owner's value: the owner's original cell number is this cell's.
  for (const Mesh& mesh : {distributed_box(GetParam()), distributed_square(GetParam())}) {
    ASSERT_EQ(mesh.global_cell.size(), static_cast<std::size_t>(mesh.n_cells()));
    PetscInt offset = 0, n_owned = mesh.n_owned_cells;
    MPI_Exscan(&n_owned, &offset, 1, MPIU_INT, MPI_SUM, MPI_COMM_WORLD);
    if (coapt::rank_of(MPI_COMM_WORLD) == 0) offset = 0;
    for (int c = 0; c < mesh.n_owned_cells; ++c) EXPECT_EQ(mesh.global_cell[c], offset + c);
    auto vector = coapt::fem::create_cell_vector(mesh);
    PetscScalar* data = nullptr;
    VecGetArray(vector, &data);
    for (int c = 0; c < mesh.n_owned_cells; ++c)
      data[c] = static_cast<double>(mesh.original_cell[c]);
    VecRestoreArray(vector, &data);
    coapt::fem::update_ghosts(vector);
    coapt::fem::LocalValues local(vector);
    ASSERT_EQ(local.values().size(), static_cast<std::size_t>(mesh.n_cells()));
    for (int c = 0; c < mesh.n_cells(); ++c)
      EXPECT_EQ(local[c], static_cast<double>(mesh.original_cell[c]));
  }
}

TEST_P(Distribution, CsrAssemblyEqualsPlainAssembly) {
  const Mesh mesh = distributed_box(GetParam());
  for (int n : {1, 3}) {
    coapt::fem::P1Matrix matrix(mesh, n);
    auto kernel = [&](int c, double* element) {
      const double* points[4];
      for (int a = 0; a < 4; ++a) points[a] = mesh.point(mesh.cell(c)[a]).data();
      if (n == 1)
        coapt::fem::element_laplacian<3>(points, element);
      else
        coapt::fem::element_elasticity<3>(points, 2.0, 0.7, element);
    };
    matrix.assemble(kernel);
    matrix.assemble(kernel);  // re-assembly must not accumulate
    Mat plain = nullptr;
    MatCreateAIJ(MPI_COMM_WORLD, mesh.n_owned_vertices * n, mesh.n_owned_vertices * n,
                 PETSC_DETERMINE, PETSC_DETERMINE, 100, nullptr, 100, nullptr, &plain);
    std::vector<double> element(static_cast<std::size_t>(16 * n * n));
    std::vector<PetscInt> dofs(static_cast<std::size_t>(4 * n));
    for (int c = 0; c < mesh.n_owned_cells; ++c) {
      kernel(c, element.data());
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < n; ++i) dofs[a * n + i] = mesh.global_vertex[mesh.cell(c)[a]] * n + i;
      MatSetValues(plain, 4 * n, dofs.data(), 4 * n, dofs.data(), element.data(), ADD_VALUES);
    }
    MatAssemblyBegin(plain, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(plain, MAT_FINAL_ASSEMBLY);
    PetscReal reference = 0, difference = 0;
    MatNorm(plain, NORM_FROBENIUS, &reference);
    MatAXPY(plain, -1.0, matrix.mat(), DIFFERENT_NONZERO_PATTERN);
    MatNorm(plain, NORM_FROBENIUS, &difference);
    EXPECT_LT(difference, 1e-13 * reference) << "components " << n;
    MatDestroy(&plain);
  }
}

TEST_P(Distribution, DirichletKeepsTheSystemSymmetric) {
  const Mesh mesh = distributed_square(GetParam());
  coapt::fem::P1Matrix matrix(mesh, 2);
  matrix.assemble([&](int c, double* element) {
    const double* points[3];
    for (int a = 0; a < 3; ++a) points[a] = mesh.point(mesh.cell(c)[a]).data();
    coapt::fem::element_elasticity<2>(points, 1.0, 1.0, element);
  });
  auto rhs = coapt::fem::create_vertex_vector(mesh, 2);
  auto values = coapt::fem::create_vertex_vector(mesh, 2);
  VecSet(values, 0.25);
  const auto dofs = coapt::fem::boundary_dofs(mesh, 2, mesh.group("left").tag);
  coapt::fem::apply_dirichlet(matrix.mat(), rhs, dofs, values);
  PetscBool symmetric = PETSC_FALSE;
  MatIsSymmetric(matrix.mat(), 1e-12, &symmetric);
  EXPECT_TRUE(symmetric);
  // The boundary rows now say u = 0.25 (scaled by the chosen diagonal).
  int n_dofs = static_cast<int>(dofs.size());
  MPI_Allreduce(MPI_IN_PLACE, &n_dofs, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(n_dofs, 2 * 12);  // 12 vertices on x = 0, two components
  auto solution = coapt::fem::create_vertex_vector(mesh, 2);
  KSP ksp = nullptr;
  KSPCreate(MPI_COMM_WORLD, &ksp);
  KSPSetOperators(ksp, matrix.mat(), matrix.mat());
  KSPSetType(ksp, KSPCG);
  KSPSetTolerances(ksp, 1e-13, 1e-50, PETSC_DEFAULT, 2000);
  KSPSolve(ksp, rhs, solution);
  KSPDestroy(&ksp);
  // No load, u = 0.25 on the left: the solution is the rigid translation u = (0.25, 0.25).
  PetscReal low = 0, high = 0;
  VecMin(solution, nullptr, &low);
  VecMax(solution, nullptr, &high);
  EXPECT_NEAR(low, 0.25, 1e-9);
  EXPECT_NEAR(high, 0.25, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Partitioners, Distribution,
                         ::testing::Values(Partitioner::metis, Partitioner::blocks));

TEST(Distribution, TooFewCellsIsAnInputErrorOnEveryRank) {
  if (coapt::size_of(MPI_COMM_WORLD) < 2) GTEST_SKIP() << "needs 2 ranks";
  Mesh whole;
  if (coapt::rank_of(MPI_COMM_WORLD) == 0)
    whole = coapt::mesh::structured_rectangle(0, 0, 1, 1, 1, 1);
  // 2 cells: fine on 2 ranks, too few on 3.
  if (coapt::size_of(MPI_COMM_WORLD) > 2)
    EXPECT_THROW(coapt::mesh::distribute(whole, MPI_COMM_WORLD), coapt::InputError);
  else
    EXPECT_NO_THROW(coapt::mesh::distribute(whole, MPI_COMM_WORLD));
}

}  // namespace
