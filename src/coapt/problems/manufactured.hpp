#pragma once
/// @file manufactured.hpp
/// Verification of the finite-element core by manufactured solutions: the Poisson equation
/// −Δu = f and linear elasticity −div σ(u) = f on a mesh from the case, with Dirichlet data
/// and f from a smooth exact solution; the L2 and H1 errors are the benchmark quantities.

#include <memory>

#include "coapt/run/problem.hpp"

namespace coapt::problems {

/// `problem: poisson` (options prefix -poisson_).
std::unique_ptr<run::Problem> create_poisson(const config::Section& root, MPI_Comm comm);
/// `problem: elasticity` (options prefix -elasticity_).
std::unique_ptr<run::Problem> create_elasticity(const config::Section& root, MPI_Comm comm);

}  // namespace coapt::problems
