#pragma once
/// @file collective.hpp
/// Making errors collective: work done on one rank (reading a file on rank 0) must not leave
/// the other ranks waiting when it fails. The failure is broadcast and rethrown everywhere.

#include <mpi.h>

#include <string>

#include "coapt/core/error.hpp"

namespace coapt {

/// Rethrows on every rank of `comm` a failure recorded on any rank: `message` is empty
/// where nothing failed; `input` says whether it was an InputError. Collective.
void rethrow_collectively(MPI_Comm comm, const std::string& message, bool input);

/// Runs `work` on rank 0 of `comm`; if it throws a coapt::Error there, every rank throws
/// the same error. Collective.
template <class Work>
void run_on_root(MPI_Comm comm, Work&& work) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string message;
  bool input = false;
  if (rank == 0) {
    try {
      work();
    } catch (const InputError& e) {
      message = e.what();
      input = true;
    } catch (const Error& e) {
      message = e.what();
    }
  }
  rethrow_collectively(comm, message, input);
}

}  // namespace coapt
