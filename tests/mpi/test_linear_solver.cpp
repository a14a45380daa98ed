// The linear solver wrapper on any number of ranks: a direct solve that fails on a singular
// matrix throws, and the next solve with a regular matrix of the same pattern succeeds (a
// failed MUMPS factorisation must not poison the retries of a time step).
#include <gtest/gtest.h>

#include <cmath>

#include "coapt/core/error.hpp"
#include "coapt/core/petsc.hpp"
#include "coapt/fem/linear_solver.hpp"

namespace {

using coapt::ConvergenceError;
using coapt::fem::LinearSolver;
using coapt::fem::LinearSolverDefaults;

/// The tridiagonal matrix tridiag(−1, 2, −1) of size n whose first row and column are scaled
/// by `first` (0: a zero row and column, singular; the pattern stays).
void fill(Mat matrix, PetscInt n, double first) {
  PetscInt start = 0, end = 0;
  COAPT_PETSC_CHECK(MatGetOwnershipRange(matrix, &start, &end));
  for (PetscInt i = start; i < end; ++i) {
    const double row = i == 0 ? first : 1.0;
    COAPT_PETSC_CHECK(MatSetValue(matrix, i, i, 2.0 * row * row, INSERT_VALUES));
    if (i > 0)
      COAPT_PETSC_CHECK(
          MatSetValue(matrix, i, i - 1, -row * (i - 1 == 0 ? first : 1.0), INSERT_VALUES));
    if (i < n - 1) COAPT_PETSC_CHECK(MatSetValue(matrix, i, i + 1, -row, INSERT_VALUES));
  }
  COAPT_PETSC_CHECK(MatAssemblyBegin(matrix, MAT_FINAL_ASSEMBLY));
  COAPT_PETSC_CHECK(MatAssemblyEnd(matrix, MAT_FINAL_ASSEMBLY));
}

TEST(LinearSolver, DirectSolveRecoversAfterAFailedFactorisation) {
  const PetscInt n = 12;
  coapt::OwnedMat matrix;
  COAPT_PETSC_CHECK(MatCreateAIJ(MPI_COMM_WORLD, PETSC_DECIDE, PETSC_DECIDE, n, n, 3, nullptr, 2,
                                 nullptr, matrix.out()));
  coapt::OwnedVec rhs, solution;
  COAPT_PETSC_CHECK(MatCreateVecs(matrix, solution.out(), rhs.out()));
  LinearSolverDefaults defaults;
  defaults.ksp_type = "preonly";
  defaults.pc_type = "lu";
  LinearSolver solver(MPI_COMM_WORLD, "linear_solver_test_", defaults);
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(solver.ksp(), &pc));
  COAPT_PETSC_CHECK(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));

  // A zero first row and column: singular.
  fill(matrix, n, 0.0);
  COAPT_PETSC_CHECK(VecSet(rhs, 1.0));
  solver.set_operator(matrix);
  EXPECT_THROW(solver.solve(rhs, solution), ConvergenceError);

  // The same pattern, regular: solved to round-off, twice.
  for (int attempt = 0; attempt < 2; ++attempt) {
    fill(matrix, n, 1.0);
    solver.set_operator(matrix);
    COAPT_PETSC_CHECK(VecSet(solution, 0.0));
    ASSERT_NO_THROW(solver.solve(rhs, solution));
    coapt::OwnedVec residual;
    COAPT_PETSC_CHECK(VecDuplicate(rhs, residual.out()));
    COAPT_PETSC_CHECK(MatMult(matrix, solution, residual));
    COAPT_PETSC_CHECK(VecAXPY(residual, -1.0, rhs));
    PetscReal norm = 0;
    COAPT_PETSC_CHECK(VecNorm(residual, NORM_2, &norm));
    EXPECT_LT(norm, 1e-12);
  }
}

}  // namespace
