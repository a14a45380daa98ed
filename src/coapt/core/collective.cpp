#include "coapt/core/collective.hpp"

#include <algorithm>
#include <vector>

namespace coapt {

void rethrow_collectively(MPI_Comm comm, const std::string& message, bool input) {
  // The lowest rank that failed speaks for all.
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int failed_rank = message.empty() ? size : rank;
  int first = size;
  MPI_Allreduce(&failed_rank, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return;
  int length = static_cast<int>(message.size());
  int kind = input ? 1 : 0;
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  MPI_Bcast(&kind, 1, MPI_INT, first, comm);
  std::string text = message;
  text.resize(static_cast<std::size_t>(length));
  if (length > 0) MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  if (kind == 1) throw InputError(text);
  throw Error(text);
}

}  // namespace coapt
