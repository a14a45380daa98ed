#pragma once
/// @file line_search.hpp
/// Backtracking on a residual norm for the Newton iterations of the solid and the fluid
/// (`newton.line_search` of either).

#include <cmath>
#include <limits>

#include "coapt/core/config.hpp"

namespace coapt::fem {

/// The `line_search` key of a `newton:` section (the solid's and the fluid's): the number of
/// halvings, 0 for full steps.
inline int read_line_search(const config::Section& newton) {
  return newton.get<int>(
      "line_search", 0,
      {"",
       "halvings of a Newton update that raises the residual norm (backtracking while it stays "
       "above the last iterate's; the trial with the smallest norm is kept); 0: full updates",
       config::Bounds::closed(0, 20)});
}

/// What backtrack() kept: the residual norm there and the step length.
struct Backtracking {
  double norm = 0;
  double length = 1;
};

/// The iterate is x + `length` δ with residual norm `norm`, above `previous` (the last
/// iterate's). Halves the step while the norm stays above `previous` (at most `halvings`
/// times), then moves to the trial with the smallest finite norm and evaluates there again,
/// so that whatever `evaluate` leaves behind (the residual vector, a hook's state) belongs to
/// the iterate kept. `move(from, to)` changes the iterate from x + from δ to x + to δ;
/// `evaluate()` returns the residual norm of the current iterate (+∞ or NaN where it has none).
template <class Move, class Evaluate>
Backtracking backtrack(int halvings, double length, double norm, double previous, Move&& move,
                       Evaluate&& evaluate) {
  Backtracking best{std::isfinite(norm) ? norm : std::numeric_limits<double>::infinity(), length};
  for (int k = 0; k < halvings && !(norm <= previous); ++k) {
    move(length, 0.5 * length);
    length *= 0.5;
    norm = evaluate();
    if (std::isfinite(norm) && norm < best.norm) best = {norm, length};
  }
  if (length != best.length) {
    move(length, best.length);
    length = best.length;
    norm = evaluate();
  }
  return {norm, length};
}

}  // namespace coapt::fem
