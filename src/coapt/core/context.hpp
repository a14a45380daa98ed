#pragma once
/// @file context.hpp
/// The process-wide MPI/PETSc context: initialised once per program, finalised at exit.

#include <mpi.h>

#include <string>
#include <vector>

namespace coapt {

/// Initialises PETSc (and MPI) in its constructor and finalises it in its destructor.
/// `petsc_arguments` are PETSc options (e.g. {"-fluid_ksp_type", "gmres"}). Collective.
class Context {
 public:
  Context(int* argc, char*** argv);
  Context(const std::vector<std::string>& petsc_arguments);
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  ~Context();

  MPI_Comm comm() const { return MPI_COMM_WORLD; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  /// PETSc options given but never queried by any solver (typos, unused settings).
  static std::vector<std::string> unused_petsc_options();

 private:
  void init(int* argc, char*** argv);
  int rank_ = 0;
  int size_ = 1;
};

/// The command-line words after "--" (PETSc options); `n_ours` is set to the number of
/// words before it (all of argc when there is no "--").
std::vector<std::string> split_petsc_arguments(int argc, char** argv, int& n_ours);

/// Rank of this process in `comm`.
int rank_of(MPI_Comm comm);
/// Number of processes in `comm`.
int size_of(MPI_Comm comm);

}  // namespace coapt
