#pragma once
// Shared pieces of coapt-bench: the sub-commands' entry points and memory measurement.

#include <mpi.h>

#include "coapt/core/context.hpp"
#include "coapt/io/json.hpp"

namespace coapt::bench {

/// Peak resident memory of this process, maximum over the ranks [MB]. Collective.
double peak_rss_mb(MPI_Comm comm);

struct AssemblyOptions {
  int n = 32;
  int repeat = 5;
};
/// `coapt-bench assembly`: first assembly (pattern + values) and re-assembly (values into
/// the existing matrix) of the P1 Laplacian and elasticity stiffness. Collective.
io::Json assembly(const Context& context, const AssemblyOptions& options);

}  // namespace coapt::bench
