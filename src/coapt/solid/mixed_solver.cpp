#include "coapt/solid/mixed_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "coapt/core/error.hpp"

namespace coapt::solid {
namespace {

/// Sets the option -name to value unless it was given (the user's options win).
void default_option(const std::string& name, const char* value) {
  PetscBool given = PETSC_FALSE;
  COAPT_PETSC_CHECK(PetscOptionsHasName(nullptr, nullptr, name.c_str(), &given));
  if (!given) COAPT_PETSC_CHECK(PetscOptionsSetValue(nullptr, name.c_str(), value));
}

}  // namespace

fem::LinearSolverDefaults mixed_solver_defaults(int dim) {
  // 3D: an inexact Newton step to 1e-8 keeps the Newton residual histories of LU down to the
  // Newton tolerance (docs/verification/solid.md). 2D: the meshes are small enough for LU.
  if (dim == 3) return fem::LinearSolverDefaults{"gmres", "fieldsplit", 1e-8, 1e-50, 2000};
  return fem::LinearSolverDefaults{"preonly", "lu", 1e-10, 1e-50, 2000};
}

MixedLinearSolver::MixedLinearSolver(const mesh::Mesh& mesh, Vec pressure_mass)
    : solver_(mesh.comm, "solid_", mixed_solver_defaults(mesh.dim)) {
  COAPT_PETSC_CHECK(VecDuplicate(pressure_mass, pressure_mass_.out()));
  COAPT_PETSC_CHECK(VecCopy(pressure_mass, pressure_mass_));
  configure(mesh);
}

void MixedLinearSolver::configure(const mesh::Mesh& mesh) {
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(solver_.ksp(), &pc));
  PetscBool fieldsplit = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCFIELDSPLIT, &fieldsplit));
  fieldsplit_ = fieldsplit;
  if (!fieldsplit_) {
    PetscBool given = PETSC_FALSE;
    COAPT_PETSC_CHECK(PetscOptionsHasName(nullptr, "solid_", "-pc_factor_mat_solver_type", &given));
    PetscBool lu = PETSC_FALSE;
    COAPT_PETSC_CHECK(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCLU, &lu));
    if (!given && lu) COAPT_PETSC_CHECK(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    return;
  }
  // The splits by index sets: the owned rows are whole vertices (u_1..u_Dim, p), so the
  // displacement split has the layout of a Dim-component vertex vector.
  const int dim = mesh.dim, m = dim + 1;
  const PetscInt start = static_cast<PetscInt>(mesh.vertex_offset) * m;
  std::vector<PetscInt> displacement, pressure;
  for (int v = 0; v < mesh.n_owned_vertices; ++v) {
    for (int i = 0; i < dim; ++i) displacement.push_back(start + v * m + i);
    pressure.push_back(start + v * m + dim);
  }
  COAPT_PETSC_CHECK(ISCreateGeneral(mesh.comm, static_cast<PetscInt>(displacement.size()),
                                    displacement.data(), PETSC_COPY_VALUES,
                                    displacement_dofs_.out()));
  COAPT_PETSC_CHECK(ISSetBlockSize(displacement_dofs_, dim));
  COAPT_PETSC_CHECK(ISCreateGeneral(mesh.comm, static_cast<PetscInt>(pressure.size()),
                                    pressure.data(), PETSC_COPY_VALUES, pressure_dofs_.out()));
  // The rigid-body modes of the displacement block, which PCFIELDSPLIT hands to the split's
  // matrix (the "nearnullspace" of its index set) and GAMG builds its coarse spaces from.
  {
    OwnedVec coordinates;
    COAPT_PETSC_CHECK(VecCreateMPI(mesh.comm, static_cast<PetscInt>(displacement.size()),
                                   PETSC_DETERMINE, coordinates.out()));
    COAPT_PETSC_CHECK(VecSetBlockSize(coordinates, dim));
    PetscScalar* data = nullptr;
    COAPT_PETSC_CHECK(VecGetArray(coordinates, &data));
    std::copy_n(mesh.coordinates.begin(), displacement.size(), data);
    COAPT_PETSC_CHECK(VecRestoreArray(coordinates, &data));
    MatNullSpace null_space = nullptr;
    COAPT_PETSC_CHECK(MatNullSpaceCreateRigidBody(coordinates, &null_space));
    const PetscErrorCode status =
        PetscObjectCompose(reinterpret_cast<PetscObject>(displacement_dofs_.get()), "nearnullspace",
                           reinterpret_cast<PetscObject>(null_space));
    MatNullSpaceDestroy(&null_space);
    COAPT_PETSC_CHECK(status);
  }
  COAPT_PETSC_CHECK(PCFieldSplitSetIS(pc, "u", displacement_dofs_));
  COAPT_PETSC_CHECK(PCFieldSplitSetIS(pc, "p", pressure_dofs_));
  COAPT_PETSC_CHECK(PCFieldSplitSetType(pc, PC_COMPOSITE_SCHUR));
  COAPT_PETSC_CHECK(PCFieldSplitSetSchurFactType(pc, PC_FIELDSPLIT_SCHUR_FACT_UPPER));
  default_option("-solid_fieldsplit_u_ksp_type", "preonly");
  default_option("-solid_fieldsplit_u_pc_type", "gamg");
  default_option("-solid_fieldsplit_p_ksp_type", "preonly");
  default_option("-solid_fieldsplit_p_pc_type", "jacobi");
  PetscBool given = PETSC_FALSE;
  COAPT_PETSC_CHECK(
      PetscOptionsHasName(nullptr, nullptr, "-solid_pc_fieldsplit_schur_precondition", &given));
  PetscReal mass_scale = mass_scale_;
  COAPT_PETSC_CHECK(
      PetscOptionsGetReal(nullptr, "solid_", "-schur_mass_scale", &mass_scale, nullptr));
  mass_scale_ = mass_scale;
  // The user's options override the set-up above (factorisation, sub-solvers, ...).
  COAPT_PETSC_CHECK(KSPSetFromOptions(solver_.ksp()));
  PCCompositeType type = PC_COMPOSITE_SCHUR;
  COAPT_PETSC_CHECK(PCFieldSplitGetType(pc, &type));
  user_schur_ = !given && type == PC_COMPOSITE_SCHUR;
}

void MixedLinearSolver::set_operator(Mat matrix) {
  solver_.set_operator(matrix);
  if (!fieldsplit_ || !user_schur_) return;
  // S_p = −C − w M_p/μ: the pressure block of K (−C) with the lumped mass subtracted.
  COAPT_PETSC_CHECK(MatCreateSubMatrix(matrix, pressure_dofs_, pressure_dofs_, MAT_INITIAL_MATRIX,
                                       schur_preconditioner_.out()));
  Vec mass = nullptr;
  COAPT_PETSC_CHECK(VecGetSubVector(pressure_mass_, pressure_dofs_, &mass));
  OwnedVec scaled;
  COAPT_PETSC_CHECK(VecDuplicate(mass, scaled.out()));
  COAPT_PETSC_CHECK(VecAXPBY(scaled, -mass_scale_, 0.0, mass));
  COAPT_PETSC_CHECK(VecRestoreSubVector(pressure_mass_, pressure_dofs_, &mass));
  COAPT_PETSC_CHECK(MatDiagonalSet(schur_preconditioner_, scaled, ADD_VALUES));
  PC pc = nullptr;
  COAPT_PETSC_CHECK(KSPGetPC(solver_.ksp(), &pc));
  COAPT_PETSC_CHECK(
      PCFieldSplitSetSchurPre(pc, PC_FIELDSPLIT_SCHUR_PRE_USER, schur_preconditioner_));
}

fem::SolveStats MixedLinearSolver::solve(Vec rhs, Vec solution) {
  return solver_.solve(rhs, solution);
}

std::string MixedLinearSolver::describe() const {
  if (!fieldsplit_) return solver_.describe();
  const auto option = [](const char* name) {
    char value[64] = "";
    PetscBool found = PETSC_FALSE;
    PetscOptionsGetString(nullptr, "solid_", name, value, sizeof value, &found);
    return std::string(found ? value : "?");
  };
  return fmt::format(
      "{}, Schur complement: u {} (rigid-body near-null space), p {} on S_p = -(1/kappa + "
      "{:g}/mu) M_p - tau L_p",
      solver_.describe(), option("-fieldsplit_u_pc_type"), option("-fieldsplit_p_pc_type"),
      mass_scale_);
}

}  // namespace coapt::solid
