#pragma once
/// @file transfer_problem.hpp
/// `problem: transfer` — the variational transfer as a case: two meshes (a slave and a
/// master, each a mesh section of its own, placed by an optional rigid motion), an analytic
/// field f(x) = value + gradient·x + amplitude·sin(2π wave·x) interpolated on the master,
/// transferred to the slave with T = D⁻¹B (and optionally the standard variant M_S⁻¹B^std),
/// and compared with f at the constrained slave nodes. The conservation is checked against
/// the same overlap integrals computed the other way round (a transfer with the roles of the
/// meshes swapped). Reports (summary.json → benchmark) the errors, the conservation, the
/// number of constrained nodes and the timings; writes both meshes with their fields as VTK.
///
///   mpirun -np 2 coapt run cases/transfer/analytic3d.yaml --set mesh.level=1

#include <memory>

#include "coapt/run/problem.hpp"

namespace coapt::transfer {

/// `problem: transfer` (standard-variant solver options prefix -transfer_standard_).
std::unique_ptr<run::Problem> create_transfer_problem(const config::Section& root, MPI_Comm comm);

}  // namespace coapt::transfer
