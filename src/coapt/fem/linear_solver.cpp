#include "coapt/fem/linear_solver.hpp"

#include <fmt/format.h>

#include "coapt/core/error.hpp"

namespace coapt::fem {

LinearSolver::LinearSolver(MPI_Comm comm, const std::string& prefix,
                           const LinearSolverDefaults& defaults)
    : prefix_(prefix) {
  COAPT_PETSC_CHECK(KSPCreate(comm, ksp_.out()));
  COAPT_PETSC_CHECK(KSPSetOptionsPrefix(ksp_, prefix.c_str()));
  COAPT_PETSC_CHECK(KSPSetType(ksp_, defaults.ksp_type.c_str()));
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(ksp_, &pc));
  COAPT_PETSC_CHECK(PCSetType(pc, defaults.pc_type.c_str()));
  COAPT_PETSC_CHECK(KSPSetTolerances(ksp_, defaults.relative_tolerance, defaults.absolute_tolerance,
                                     PETSC_DEFAULT, defaults.max_iterations));
  COAPT_PETSC_CHECK(KSPSetFromOptions(ksp_));
}

void LinearSolver::set_operator(Mat matrix, bool keep_preconditioner) {
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(ksp_, &pc));
  COAPT_PETSC_CHECK(PCSetReusePreconditioner(pc, keep_preconditioner ? PETSC_TRUE : PETSC_FALSE));
  COAPT_PETSC_CHECK(KSPSetOperators(ksp_, matrix, matrix));
}

bool LinearSolver::is_factorisation() const {
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(ksp_, &pc));
  PetscBool factor = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscObjectTypeCompareAny(reinterpret_cast<PetscObject>(pc), &factor, PCLU, PCCHOLESKY, ""));
  return factor == PETSC_TRUE;
}

SolveStats LinearSolver::solve(Vec rhs, Vec solution, int max_iterations) {
  PetscReal rtol = 0, atol = 0, dtol = 0;
  PetscInt configured = 0;
  COAPT_PETSC_CHECK(KSPGetTolerances(ksp_, &rtol, &atol, &dtol, &configured));
  const bool capped = max_iterations > 0 && max_iterations < configured;
  if (capped) COAPT_PETSC_CHECK(KSPSetTolerances(ksp_, rtol, atol, dtol, max_iterations));
  const PetscErrorCode code = KSPSolve(ksp_, rhs, solution);
  if (capped) COAPT_PETSC_CHECK(KSPSetTolerances(ksp_, rtol, atol, dtol, configured));
  COAPT_PETSC_CHECK(code);
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  PetscInt iterations = 0;
  PetscReal residual = 0;
  COAPT_PETSC_CHECK(KSPGetConvergedReason(ksp_, &reason));
  COAPT_PETSC_CHECK(KSPGetIterationNumber(ksp_, &iterations));
  COAPT_PETSC_CHECK(KSPGetResidualNorm(ksp_, &residual));
  SolveStats stats{static_cast<int>(iterations), static_cast<double>(residual),
                   KSPConvergedReasons[reason]};
  if (reason == KSP_DIVERGED_PC_FAILED) reset_factorisation();
  if (reason < 0)
    throw ConvergenceError(fmt::format(
        "linear solver -{} did not converge: {} after {} iterations, residual norm {:.3e}", prefix_,
        stats.reason, stats.iterations, stats.residual_norm));
  return stats;
}

void LinearSolver::reset_factorisation() {
  if (!is_factorisation()) return;
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(ksp_, &pc));
  // PCReset drops the operators with the factor: keep them alive and set them again.
  Mat matrix = nullptr, preconditioner = nullptr;
  COAPT_PETSC_CHECK(KSPGetOperators(ksp_, &matrix, &preconditioner));
  COAPT_PETSC_CHECK(PetscObjectReference(reinterpret_cast<PetscObject>(matrix)));
  COAPT_PETSC_CHECK(PetscObjectReference(reinterpret_cast<PetscObject>(preconditioner)));
  COAPT_PETSC_CHECK(PCReset(pc));
  COAPT_PETSC_CHECK(KSPSetOperators(ksp_, matrix, preconditioner));
  COAPT_PETSC_CHECK(MatDestroy(&matrix));
  COAPT_PETSC_CHECK(MatDestroy(&preconditioner));
}

std::string LinearSolver::describe() const {
  KSPType ksp_type = nullptr;
  PCType pc_type = nullptr;
  PC pc = nullptr;
  KSPGetType(ksp_, &ksp_type);
  KSPGetPC(ksp_, &pc);
  PCGetType(pc, &pc_type);
  return fmt::format("{} + {} (options prefix -{})", ksp_type ? ksp_type : "?",
                     pc_type ? pc_type : "?", prefix_);
}

}  // namespace coapt::fem
