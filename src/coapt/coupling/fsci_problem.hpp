#pragma once
/// @file fsci_problem.hpp
/// `problem: fsci`: the immersed coupling of a fluid (fluid::FluidModel, on a fixed mesh that
/// also fills the solids' regions) with solids given as their own meshes. Per step the solids'
/// velocities are transferred to the fluid nodes they cover (ImmersedConstraint: v_f = T v_s),
/// the fluid is solved with that constraint, and the constraint reactions give the multiplier
/// λ = r/D and the force on each solid, Bᵀλ (method/paper.md §2–3).
///
/// Solids: `rigid: true` with a prescribed translation velocity (zero: a fixed body, e.g.
/// the immersed DFG cylinder). Deformable solids (solid::SolidModel in a block Gauss–Seidel
/// loop) and contact are the next steps; the case format has their place (`solids`,
/// `coupling`).
///
///   coapt run cases/dfg/2d1_immersed.yaml --set mesh.level=1
///   mpirun -np 2 coapt run cases/dfg/2d1_immersed.yaml --set coupling.coverage_threshold=0.5

#include <memory>

#include "coapt/run/problem.hpp"

namespace coapt::coupling {

/// `problem: fsci` (fluid options prefix -fluid_). Collective on `comm`.
std::unique_ptr<run::Problem> create_fsci_problem(const config::Section& root, MPI_Comm comm);

}  // namespace coapt::coupling
