#pragma once
/// @file linear_solver.hpp
/// A PETSc KSP with an options prefix ("poisson_", "fluid_", ...), coapt's defaults, the
/// user's PETSc options on top, and a convergence check that throws.

#include <petscksp.h>

#include <string>

#include "coapt/core/petsc.hpp"

namespace coapt::fem {

/// coapt's defaults for one solver; every one can be overridden with -<prefix>ksp_... options.
struct LinearSolverDefaults {
  std::string ksp_type = "cg";
  std::string pc_type = "gamg";
  double relative_tolerance = 1e-10;
  double absolute_tolerance = 1e-50;
  int max_iterations = 1000;
};

/// What one solve did.
struct SolveStats {
  int iterations = 0;
  double residual_norm = 0;
  std::string reason;
};

/// Krylov solver for one operator. Collective on its communicator.
class LinearSolver {
 public:
  LinearSolver(MPI_Comm comm, const std::string& prefix, const LinearSolverDefaults& defaults);
  /// Sets (or resets after re-assembly) the operator; the preconditioner is rebuilt.
  void set_operator(Mat matrix);
  /// Solves A x = b; throws ConvergenceError naming the prefix, the reason and the iterations.
  /// A failed factorisation (LU, Cholesky) is discarded first, so that the next solve analyses
  /// and factors afresh: MUMPS refuses every later numeric factorisation of an instance whose
  /// last one failed, which would make a retried step fail at its first solve whatever its
  /// matrix.
  SolveStats solve(Vec rhs, Vec solution);
  KSP ksp() const { return ksp_.get(); }
  /// A one-line description ("cg + gamg").
  std::string describe() const;

 private:
  void reset_factorisation();
  OwnedKSP ksp_;
  std::string prefix_;
};

}  // namespace coapt::fem
