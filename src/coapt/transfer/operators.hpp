#pragma once
/// @file operators.hpp
/// The operators of the variational transfer (exact-intersection L2 projection between
/// non-matching, arbitrarily distributed P1 meshes), pipeline stage 3 (stages 1–2: search.hpp;
/// the element–element integrals: intersection.hpp).
///
/// Meshes: the slave S (the fluid; it carries the Lagrange multiplier) and the master M (the
/// solid), distributed independently over the same communicator. λ_i is the P1 basis of S,
/// ψ_i = (d + 2) λ_i − 1 its dual basis (biorthogonal on whole elements: ∫_T ψ_i λ_k =
/// δ_ik ∫_T λ_k), φ_j the P1 basis of M. Over the overlap Ω = S ∩ M:
///
///   B_ij = ∫_Ω ψ_i φ_j      MPIAIJ matrix, rows: slave global vertex numbers (the slave
///                           mesh's layout), columns: master global vertex numbers (the
///                           master mesh's layout); one component (see below for vectors)
///   D_i  = ∫_Ω ψ_i          Vec in the slave layout (the diagonal mortar matrix). Σ_j B_ij = D_i
///                           exactly, because Σ_j φ_j = 1 on M.
///   c_i  = ∫_Ω λ_i / ∫_S λ_i  covered fraction of node i's support (Vec, slave layout)
///   |T ∩ M| / |T|           covered fraction of each owned slave cell T (local values)
///   T    = D⁻¹ B            the transfer master → slave, on the constrained rows only
///
/// Covered-node rule. Biorthogonality holds on whole slave elements only: on an element cut
/// by the master's boundary D_i can be small or negative and D⁻¹B is meaningless there. A
/// slave node i is *constrained* when c_i ≥ coverage_threshold (default 1 − 1e-10: its whole
/// support lies in the master, up to round-off). T is defined on the constrained rows only;
/// there D_i = ∫_S λ_i > 0, and T reproduces every field that is linear over the node's
/// support exactly (∫ ψ_i x = x_i D_i by biorthogonality, and P1 on M is exact for linear
/// fields). Rows of partly covered nodes are still assembled in B and D (for the coupled
/// problem's bookkeeping) but are not constrained: the fluid there is left free.
/// Lowering the threshold constrains partly covered nodes with the same formula T = D⁻¹B;
/// it is the caller's choice and is not exact for linear fields.
///
/// The "standard" variant (TransferOptions::standard) assembles, for comparison, B^std_ij =
/// ∫_Ω λ_i φ_j and the consistent slave mass matrix restricted to the overlap,
/// M_S,ij = ∫_Ω λ_i λ_j (rows of nodes with no overlap at all get 1 on the diagonal so the
/// matrix is invertible); apply_standard_transfer solves M_S x = B^std m by CG.
///
/// Vector fields: apply the scalar operators per component; for interleaved dofs (vertex v,
/// component k at v·n + k) MatCreateMAIJ(coupling(), n, ...) gives B ⊗ I_n without copies.
///
/// Parallel assembly: every intersecting pair (owned slave cell, master cell) is integrated
/// once, by the rank that owns the slave cell; the rank sums its contributions per (slave
/// vertex, master vertex) locally, and rows of slave vertices owned by other ranks reach
/// them through PETSc's COO assembly (MatSetPreallocationCOO / MatSetValuesCOO, which adds
/// repeated entries). The CSR pattern is kept: a re-assembly whose pattern is unchanged only
/// writes values (MatSetValuesCOO), otherwise the matrix is re-created.

#include <mpi.h>
#include <petscis.h>
#include <petscmat.h>
#include <petscvec.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "coapt/core/petsc.hpp"
#include "coapt/mesh/mesh.hpp"
#include "coapt/transfer/search.hpp"

namespace coapt::transfer {

/// Options of the transfer operators.
struct TransferOptions {
  /// A slave node is constrained when its covered fraction c_i is at least this (0 < t ≤ 1).
  double coverage_threshold = 1.0 - 1e-10;
  /// Search margin [m] for a moving master (SearchOptions::margin).
  double search_margin = 0.0;
  /// Also assemble the standard (primal) coupling and the overlap mass matrix.
  bool standard = false;
  /// Also assemble the standard coupling B^std, without the overlap mass matrix (the
  /// partial-coverage coupling, coupling::ImmersedConstraint, weighs with it).
  bool primal = false;
};

/// What the last assembly (constructor or update_master) did on this rank.
struct TransferStatistics {
  SearchStatistics search;
  std::int64_t intersecting_pairs = 0;  ///< pairs with |S ∩ M| > 0 (this rank)
  std::int64_t local_entries = 0;       ///< (slave vertex, master vertex) entries summed here
  double search_seconds = 0;            ///< exchange, grid and face neighbours (not the front)
  double intersection_seconds = 0;  ///< the front fused with local_integrals (PairSearch::sweep)
  double assembly_seconds = 0;      ///< pattern, sums, PETSc assembly, vectors, constrained set
  bool pattern_reused = false;      ///< B (and B^std) re-filled without re-creation
};

namespace detail {
class TransferEngine;  // dimension-specific search and integration (operators.cpp)
}

/// The transfer operators between a slave and a master mesh; see the file comment.
class VariationalTransfer {
 public:
  /// Searches and assembles. Both meshes must outlive this object, share a communicator (or
  /// both be whole serial meshes) and have the same dimension (2 or 3). Collective.
  VariationalTransfer(const mesh::Mesh& slave, const mesh::Mesh& master,
                      const TransferOptions& options = {});
  VariationalTransfer(const VariationalTransfer&) = delete;
  VariationalTransfer& operator=(const VariationalTransfer&) = delete;
  ~VariationalTransfer();

  /// The master moved: `master` is the same mesh (cells, partition, numbering) with new
  /// coordinates on owned and ghost vertices. Reuses the search structure while the motion
  /// stays within TransferOptions::search_margin, re-integrates and re-assembles. Collective.
  void update_master(const mesh::Mesh& master);

  /// B (slave rows × master columns).
  Mat coupling() const { return coupling_.get(); }
  /// D_i = ∫_Ω ψ_i (slave layout).
  Vec dual_mass() const { return dual_mass_.get(); }
  /// c_i = ∫_Ω λ_i / ∫_S λ_i (slave layout).
  Vec coverage() const { return coverage_.get(); }
  /// ∫_Ω λ_i = Σ_j B^std_ij (slave layout).
  Vec covered_integral() const { return covered_integral_.get(); }
  /// Per owned slave cell T (local index): |T ∩ M| / |T|, the fraction of the cell the master
  /// covers.
  const std::vector<double>& cell_coverage() const { return cell_coverage_; }
  /// Owned global slave rows of the constrained nodes (ascending).
  const std::vector<PetscInt>& constrained_rows() const { return constrained_rows_; }
  /// The same as an IS on the slave communicator.
  IS constrained_set() const { return constrained_set_.get(); }
  /// Number of constrained nodes over all ranks.
  PetscInt n_constrained() const { return n_constrained_; }

  /// slave_values_i = (B master_values)_i / D_i on the constrained rows; other rows of
  /// slave_values are left as they are. Vectors in the master / slave layouts. Collective.
  void apply_transfer(Vec master_values, Vec slave_values) const;
  /// T = D⁻¹B as a matrix (rows of unconstrained nodes are zero). Collective.
  OwnedMat explicit_transfer() const;

  /// B^std_ij = ∫_Ω λ_i φ_j (TransferOptions::standard or primal only, else null).
  Mat standard_coupling() const { return standard_coupling_.get(); }
  /// M_S,ij = ∫_Ω λ_i λ_j, 1 on the diagonal of rows without overlap (standard only).
  Mat overlap_mass() const { return overlap_mass_.get(); }
  /// slave_values = M_S⁻¹ B^std master_values on every row (0 where there is no overlap), by
  /// CG with Jacobi (options prefix "transfer_standard_"; default relative tolerance 1e-14).
  /// Throws ConvergenceError if CG fails. Standard only. Collective.
  void apply_standard_transfer(Vec master_values, Vec slave_values) const;

  /// New vectors in the slave / master layouts. Collective.
  OwnedVec create_slave_vector() const;
  OwnedVec create_master_vector() const;

  const TransferStatistics& statistics() const { return statistics_; }
  const TransferOptions& options() const { return options_; }

 private:
  void assemble();
  void assemble_matrix(OwnedMat& matrix, std::vector<PetscInt>* rows,
                       std::vector<PetscInt>* columns, const std::vector<double>& values);

  const mesh::Mesh* slave_;
  const mesh::Mesh* master_;
  TransferOptions options_;
  std::unique_ptr<detail::TransferEngine> engine_;
  TransferStatistics statistics_;

  std::uint64_t pattern_hash_ =
      0;  ///< of B's local COO pattern (global numbers), to detect changes
  std::size_t pattern_size_ = 0;
  OwnedMat coupling_, standard_coupling_, overlap_mass_;
  OwnedVec dual_mass_, coverage_, covered_integral_, work_slave_;
  std::vector<double> cell_coverage_;  ///< per owned slave cell
  std::vector<PetscInt> constrained_rows_;
  std::vector<int> constrained_local_;  ///< owned local indices of constrained_rows_
  std::vector<double> inverse_dual_;    ///< 1 / D_i on constrained_local_
  OwnedIS constrained_set_;
  PetscInt n_constrained_ = 0;
  OwnedKSP standard_solver_;
};

}  // namespace coapt::transfer
