#pragma once
/// @file quasi_newton.hpp
/// Interface quasi-Newton acceleration of a fixed-point iteration x ← H(x), IQN-ILS
/// (Degroote, Bathe and Vierendeels 2009; the least-squares form of the iteration used by
/// partitioned FSI codes): with x̃ᵏ = H(xᵏ) and the residual rᵏ = x̃ᵏ − xᵏ, the differences of
/// consecutive iterates
///   V = [rⁱ⁺¹ − rⁱ],  W = [x̃ⁱ⁺¹ − x̃ⁱ]
/// of this step and of the last `reuse_steps` converged steps give the next iterate
///   xᵏ⁺¹ = x̃ᵏ + W c,  c = argmin ‖V c + rᵏ‖₂,
/// which is Newton's step for an affine H on the span of the columns. The least-squares
/// problem is solved by modified Gram–Schmidt on the columns, newest first, dropping a column
/// whose orthogonal part is below `filter` times its norm (nearly dependent columns make it
/// ill-conditioned). Without columns (the first iteration of the first step) the update is
/// the relaxed xᵏ⁺¹ = xᵏ + ω rᵏ.
///
/// In the immersed coupling x is the force the solids are loaded with (the concatenated owned
/// entries of their force vectors on this rank) and H one pass of solid, transfer and fluid.
/// Vectors are this rank's part; dot products are summed over `comm`.

#include <mpi.h>

#include <cstddef>
#include <deque>
#include <span>
#include <vector>

namespace coapt::coupling {

/// IQN-ILS with reuse of past steps (see the file comment).
class InterfaceQuasiNewton {
 public:
  /// `reuse_steps`: converged steps whose columns are kept; `max_columns`: at most this many
  /// columns in all (the oldest go first); `filter`: the QR filter (relative).
  InterfaceQuasiNewton(MPI_Comm comm, int reuse_steps, int max_columns, double filter);

  /// A new step (or a retry of one): forgets this step's iterates and columns.
  void begin_step();
  /// The next iterate from xᵏ and x̃ᵏ = H(xᵏ) (all of the same length, this rank's entries);
  /// returns the number of columns used (0: the relaxed update with ω). Collective.
  int next(std::span<const double> x, std::span<const double> x_tilde, double omega,
           std::span<double> next_x);
  /// The step converged: its columns are kept for the next `reuse_steps` steps.
  void end_step();
  /// Forgets every column, this step's and the past steps' (a step that failed: the past
  /// iterates may no longer describe the map).
  void reset();
  /// Stops using the past steps' columns for the rest of this step, and forgets them when the
  /// step converges (the map changed in this step, e.g. the contact's active set: the past
  /// iterates describe another map).
  void drop_reused();
  /// Whether drop_reused() was called in this step.
  bool reused_dropped() const { return reused_dropped_; }

  /// The columns of one step: V and W, this rank's entries.
  struct Columns {
    std::vector<std::vector<double>> v, w;  ///< newest last
  };
  /// The past steps' columns kept for reuse, newest first (for a checkpoint, between steps).
  const std::deque<Columns>& reused() const { return previous_; }
  /// Replaces them (from a checkpoint; at most reuse_steps are kept).
  void restore_reused(std::deque<Columns> columns);

 private:
  double dot(std::span<const double> a, std::span<const double> b) const;

  MPI_Comm comm_;
  int reuse_steps_, max_columns_;
  double filter_;
  Columns current_;
  std::deque<Columns> previous_;  ///< newest first
  std::vector<double> last_residual_, last_x_tilde_;
  bool reused_dropped_ = false;  ///< drop_reused() in this step
};

}  // namespace coapt::coupling
