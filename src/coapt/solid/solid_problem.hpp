#pragma once
/// @file solid_problem.hpp
/// `problem: solid`: finite-strain elasticity on P1 simplices (total Lagrangian, plane strain
/// in 2D), one or more bodies with their own material, Dirichlet conditions, dead tractions
/// and gravity, either quasi-static (loads applied in load steps) or dynamic (Newmark
/// β = 1/4, γ = 1/2 with a consistent mass matrix, dynamics.hpp), Newton's method per step
/// with the linear solves through the "solid_" PETSc options prefix (static default GMRES +
/// GAMG, dynamic default MUMPS LU). Case format: solid_parameters.hpp.
///
///   coapt run cases/cook/linear.yaml --set mesh.level=2
///   coapt run cases/cook/neohookean.yaml -solid_pc_type lu   (a direct solver instead of GAMG)
///   coapt run cases/turek_hron/csm3.yaml --set mesh.level=2  (dynamics: series.csv has the
///       probe displacements and the energies per time step)

#include <mpi.h>

#include <memory>

#include "coapt/core/config.hpp"
#include "coapt/run/problem.hpp"

namespace coapt::solid {

/// Reads the case (all keys), loads and distributes the mesh. Collective on `comm`.
std::unique_ptr<run::Problem> create_solid_problem(const config::Section& root, MPI_Comm comm);

}  // namespace coapt::solid
