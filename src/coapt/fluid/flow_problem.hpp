#pragma once
/// @file flow_problem.hpp
/// `problem: navier_stokes`: incompressible flow on a mesh from the case with velocity
/// boundary conditions (constant or parabolic profiles, optional smooth ramp in time), no-slip
/// walls and outlets (do-nothing, fixed pressure, or an RCR Windkessel coupled implicitly, with
/// backflow stabilisation), solved steady or with BDF1-then-BDF2 steps; benchmark
/// quantities for the lid-driven cavity (centreline profiles against a reference table) and
/// flow around a body (drag/lift coefficients, pressure difference), and the RCR relation of a
/// Windkessel outlet.
///
///   coapt run cases/cavity/re100.yaml --set mesh.level=2
///   coapt run cases/dfg/2d1.yaml --set mesh.level=1 -- -fluid_ksp_monitor
///   coapt run cases/tube_windkessel.yaml --output out/tube

#include <memory>

#include "coapt/run/problem.hpp"

namespace coapt::fluid {

/// `problem: navier_stokes` (options prefix -fluid_). Collective on `comm`.
std::unique_ptr<run::Problem> create_flow_problem(const config::Section& root, MPI_Comm comm);

}  // namespace coapt::fluid
