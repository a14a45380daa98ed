#pragma once
// Shared pieces of coapt-bench: the sub-commands' entry points and memory measurement.

#include <mpi.h>

#include <string>
#include <vector>

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

struct TransferBenchOptions {
  int n = 16;
  std::string case_name = "jitter";  ///< "jitter" or "rotated"
};
/// `coapt-bench transfer`: search, intersection and assembly of the variational transfer
/// operators (unit cube against a jittered copy or a rotated inner cube), and a re-assembly
/// after a small motion of the master. Collective.
io::Json transfer(const Context& context, const TransferBenchOptions& options);

struct FluidBenchOptions {
  int n = 8;
  int repeat = 3;
};
/// `coapt-bench fluid`: residual and Jacobian assembly of the stabilised Navier–Stokes operator
/// and one steady Newton solve on a 3D box channel (bench_fluid.cpp). Collective.
io::Json fluid(const Context& context, const FluidBenchOptions& options);

struct SolidBenchOptions {
  int n = 44;
  std::string formulation = "displacement";  ///< or "mixed"
};
/// `coapt-bench solid`: Newton iterations of the nearly incompressible Neo-Hookean solid on the
/// unit cube (n³ · 6 tets): time per iteration, assembly and solve (bench_solid.cpp).
/// Collective.
io::Json solid(const Context& context, const SolidBenchOptions& options);

struct ContactBenchOptions {
  std::string case_file = COAPT_SOURCE_DIR "/cases/contact/plates3d.yaml";
  int level = 1;
  double size = 0;  ///< mesh.size [m]; 0: the case's
  int steps = 0;    ///< the first this many of the case's load steps (0: all)
};
/// `coapt-bench contact`: the quasi-static press-and-slide of two plates with frictionless
/// mortar contact: time per load step, Newton iterations and active-set changes
/// (bench_contact.cpp). Collective.
io::Json contact(const Context& context, const ContactBenchOptions& options);

struct FsciBenchOptions {
  std::string case_file = COAPT_SOURCE_DIR "/cases/valve2d.yaml";
  int level = 0;                          ///< mesh.level
  int steps = 5;                          ///< time steps (end_time = steps · time.step)
  std::string output = "bench-fsci-run";  ///< the run folder
  std::vector<std::string> assignments;   ///< --set key=value
};
/// `coapt-bench fsci`: a transient coupled run of a case for some steps, the wall time per
/// stage of the coupled problem (bench_fsci.cpp). Collective.
io::Json fsci(const Context& context, const FsciBenchOptions& options);

}  // namespace coapt::bench
