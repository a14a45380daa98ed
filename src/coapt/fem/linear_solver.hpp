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
  /// Sets (or resets after re-assembly) the operator. The preconditioner is rebuilt, unless
  /// `keep_preconditioner`: then the last one (built for an earlier matrix) preconditions the
  /// Krylov method on this one.
  void set_operator(Mat matrix, bool keep_preconditioner = false);
  /// Whether the preconditioner is a factorisation (LU or Cholesky).
  bool is_factorisation() const;
  /// Solves A x = b; throws ConvergenceError naming the prefix, the reason and the iterations.
  /// A failed factorisation (LU, Cholesky) is discarded first, so that the next solve analyses
  /// and factors afresh: MUMPS refuses every later numeric factorisation of an instance whose
  /// last one failed, which would make a retried step fail at its first solve whatever its
  /// matrix.
  /// `max_iterations` > 0 caps this solve's iterations below the configured limit.
  SolveStats solve(Vec rhs, Vec solution, int max_iterations = 0);
  KSP ksp() const { return ksp_.get(); }
  /// A one-line description ("cg + gamg").
  std::string describe() const;

 private:
  void reset_factorisation();
  OwnedKSP ksp_;
  std::string prefix_;
};

}  // namespace coapt::fem
