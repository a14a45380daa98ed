#pragma once
/// @file kernels.hpp
/// Element kernels of the incompressible Navier–Stokes equations on P1-P1 simplices with
/// SUPG/PSPG/LSIC stabilisation, header-only and apart from assembly.
///
/// Unknowns per vertex, interleaved: (u_1, .., u_Dim, p), n = Dim + 1 (node-major dofs a·n + i).
/// With density ρ [kg/m³], dynamic viscosity μ [Pa s], u̇ the BDF time derivative
/// u̇ = α₀/Δt u + h (h the known part from earlier steps; 0 and α₀ = 0 when steady), and the
/// strong momentum residual r_M = ρ(u̇ + u·∇u) + ∇p (−μΔu vanishes on P1 elements), the element
/// residual tested with (w, q) is
///
///   R_w = ∫_T ρ w·(u̇ + u·∇u) + μ ∇w:∇u − p ∇·w                 (Galerkin, Laplace form)
///       + ∫_T τ_M (u·∇w)·r_M                                    (SUPG)
///       + ∫_T ρ τ_C (∇·w)(∇·u)                                   (LSIC)
///   R_q = ∫_T q ∇·u + (τ_M/ρ) ∇q·r_M                            (Galerkin + PSPG)
///
/// The Laplace form μ∇w:∇u makes the natural condition μ ∂_n u − p n = 0: the DFG
/// "do-nothing" outflow (Schäfer & Turek 1996). The symmetric (stress) form replaces it by
/// 2μ ∇w:ε(u) = μ ∇w:(∇u + ∇uᵀ), whose natural condition is the traction σ(u, p) n = 0 with
/// σ = −p I + 2μ ε(u), the one traction outlets and fluid–structure forces need. The two agree
/// for divergence-free u with Dirichlet data (∫ ∇w:∇uᵀ = ∫ (∇·w)(∇·u) after integration by
/// parts), so they differ only through the natural boundary condition and the discrete ∇·u_h. With
/// τ_M [s] and τ_C [m²/s] every term of R_w has the unit of ρ a·w and every term of R_q that of
/// q/s.
///
/// Stabilisation parameters (Bazilevs et al. 2007, element metric form):
///   τ_M = ((2/Δt)² + u·G·u + C_I ν² G:G)^(−1/2),  τ_C = 1/(τ_M tr G),  ν = μ/ρ,
/// with G = 4 J⁻ᵀJ⁻¹, J the Jacobian of p1.hpp's map from the unit reference simplex; the
/// factor 4 makes G the metric of the map from the reference simplex scaled by 2 (the
/// parent-domain [−1, 1] scaling of the formula). C_I from the 1D limits: a segment of length
/// h has G = 4/h², so τ_M → h/(2|u|) when advection dominates (the nodally exact
/// SUPG value) and τ_M → h²/(4√C_I ν) when diffusion dominates; the nodally exact value is
/// h²/(12ν) (the Pe → 0 limit of h/(2|u|)(coth Pe − 1/Pe)), hence C_I = 9 (kDefaultCInverse).
/// The transient term is dropped for steady problems. τ is frozen within a Newton step: it is
/// computed from the current iterate's element-mean velocity and held constant while the
/// residual is differentiated (everything else, including u in the SUPG test function u·∇w, is
/// linearised exactly).
///
/// The Jacobian is the exact derivative of the element residual (with τ frozen), written out
/// in element_residual_and_jacobian and checked against forward-mode differentiation with the
/// small Dual type below (which the backflow term uses); the residual is integrated exactly
/// (its integrand is at most quadratic) by degree-2 rules.

#include <array>
#include <cmath>

namespace coapt::fluid {

/// C_I of τ_M for P1 simplices with G = 4 J⁻ᵀJ⁻¹ (see the file comment).
inline constexpr double kDefaultCInverse = 9.0;

/// A forward-mode dual number with N derivative directions (value v, derivatives d).
template <int N>
struct Dual {
  double v = 0;
  std::array<double, N> d{};
  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT: constants mix with duals in the kernels
};

template <int N>
inline Dual<N> operator+(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v + b.v);
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] + b.d[k];
  return r;
}
template <int N>
inline Dual<N> operator-(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v - b.v);
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] - b.d[k];
  return r;
}
template <int N>
inline Dual<N> operator*(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v * b.v);
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
  return r;
}
template <int N>
inline Dual<N> operator*(double a, const Dual<N>& b) {
  Dual<N> r(a * b.v);
  for (int k = 0; k < N; ++k) r.d[k] = a * b.d[k];
  return r;
}
template <int N>
inline Dual<N>& operator+=(Dual<N>& a, const Dual<N>& b) {
  a.v += b.v;
  for (int k = 0; k < N; ++k) a.d[k] += b.d[k];
  return a;
}

/// The value of a double or a Dual (for branches on the value).
inline double value_of(double a) {
  return a;
}
template <int N>
inline double value_of(const Dual<N>& a) {
  return a.v;
}

/// Form of the viscous term: Laplace μ∇w:∇u, or symmetric (stress) 2μ∇w:ε(u).
enum class ViscousForm { laplace, stress };

/// Everything an element residual needs besides the unknowns; all doubles (frozen in Newton).
template <int Dim>
struct ElementData {
  double gradients[Dim + 1][Dim];  ///< ∇λ_a [1/m]
  double measure = 0;              ///< |T| [m^Dim]
  double density = 1;              ///< ρ [kg/m³]
  double viscosity = 1;            ///< μ [Pa s]
  double mass_coefficient = 0;     ///< α₀/Δt [1/s] (0: steady)
  double history[Dim + 1][Dim]{};  ///< known part of u̇ at each vertex [m/s²]
  bool convection = true;          ///< false: Stokes (u·∇u dropped, also from τ)
  ViscousForm viscous_form = ViscousForm::laplace;  ///< the viscous term (file comment)
  double tau_m = 0;                                 ///< τ_M [s]
  double tau_c = 0;                                 ///< τ_C [m²/s]
};

/// BDF weights (α₀, α₁, α₂) with u̇ⁿ⁺¹ ≈ (α₀uⁿ⁺¹ + α₁uⁿ + α₂uⁿ⁻¹)/Δtₙ for ω = Δtₙ/Δtₙ₋₁:
/// α₀ = (1+2ω)/(1+ω), α₁ = −(1+ω), α₂ = ω²/(1+ω) (BDF2 with a changing step); order 1 gives
/// backward Euler (1, −1, 0).
inline std::array<double, 3> bdf_weights(int order, double omega) {
  if (order == 1) return {1.0, -1.0, 0.0};
  return {(1 + 2 * omega) / (1 + omega), -(1 + omega), omega * omega / (1 + omega)};
}

/// The metric G = 4 J⁻ᵀJ⁻¹ from the barycentric gradients (rows of J⁻¹ are ∇λ_1..∇λ_Dim).
template <int Dim>
inline void element_metric(const double (&g)[Dim + 1][Dim], double (&G)[Dim][Dim]) {
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) {
      double sum = 0;
      for (int k = 1; k <= Dim; ++k) sum += g[k][i] * g[k][j];
      G[i][j] = 4.0 * sum;
    }
}

/// Sets data.tau_m and data.tau_c from the convective velocity `u` [m/s] (the element mean of
/// the current iterate), the step Δt [s] (≤ 0: steady, no transient term) and C_I.
template <int Dim>
inline void set_stabilisation(ElementData<Dim>& data, const double (&u)[Dim], double time_step,
                              double c_inverse) {
  double G[Dim][Dim];
  element_metric<Dim>(data.gradients, G);
  const double nu = data.viscosity / data.density;
  double uGu = 0, GG = 0, trace = 0;
  for (int i = 0; i < Dim; ++i) {
    trace += G[i][i];
    for (int j = 0; j < Dim; ++j) {
      uGu += u[i] * G[i][j] * u[j];
      GG += G[i][j] * G[i][j];
    }
  }
  double sum = c_inverse * nu * nu * GG;
  if (data.convection) sum += uGu;
  if (time_step > 0) sum += 4.0 / (time_step * time_step);
  data.tau_m = 1.0 / std::sqrt(sum);
  data.tau_c = 1.0 / (data.tau_m * trace);
}

/// Reference points (barycentric) and weights (fractions of |T|) of the degree-2 rules.
template <int Dim>
struct Degree2Rule;
template <>
struct Degree2Rule<2> {
  static constexpr int n = 3;
  static double lambda(int q, int a) { return q == a ? 2.0 / 3.0 : 1.0 / 6.0; }
  static constexpr double weight = 1.0 / 3.0;
};
template <>
struct Degree2Rule<3> {
  static constexpr int n = 4;
  static double lambda(int q, int a) { return q == a ? 0.5854101966249685 : 0.1381966011250105; }
  static constexpr double weight = 0.25;
};

/// The element residual (see the file comment): x holds the (Dim+1)² unknowns node-major
/// (u_1..u_Dim, p per vertex), r receives the (Dim+1)² residual entries. S is double or Dual.
template <int Dim, class S>
inline void element_residual(const ElementData<Dim>& e, const S* x, S* r) {
  constexpr int n = Dim + 1;
  const auto& g = e.gradients;
  for (int k = 0; k < n * n; ++k) r[k] = S(0.0);
  // Constant gradients of u (grad_u[i][j] = ∂_j u_i) and p, and div u.
  S grad_u[Dim][Dim], grad_p[Dim], div(0.0);
  for (int i = 0; i < Dim; ++i) {
    grad_p[i] = S(0.0);
    for (int j = 0; j < Dim; ++j) grad_u[i][j] = S(0.0);
  }
  for (int a = 0; a < n; ++a)
    for (int j = 0; j < Dim; ++j) {
      for (int i = 0; i < Dim; ++i) grad_u[i][j] += g[a][j] * x[a * n + i];
      grad_p[j] += g[a][j] * x[a * n + Dim];
    }
  for (int i = 0; i < Dim; ++i) div += grad_u[i][i];
  const double rho = e.density, mu = e.viscosity;
  // Terms with constant integrands: viscous, LSIC, continuity's Galerkin part uses the mean.
  const bool stress = e.viscous_form == ViscousForm::stress;
  for (int a = 0; a < n; ++a)
    for (int i = 0; i < Dim; ++i) {
      S viscous(0.0);
      for (int j = 0; j < Dim; ++j) {
        viscous += g[a][j] * grad_u[i][j];
        if (stress) viscous += g[a][j] * grad_u[j][i];  // ∇w:∇uᵀ
      }
      r[a * n + i] += (e.measure * mu) * viscous + (e.measure * rho * e.tau_c * g[a][i]) * div;
    }
  using Rule = Degree2Rule<Dim>;
  for (int q = 0; q < Rule::n; ++q) {
    const double w = Rule::weight * e.measure;
    double lambda[n];
    for (int a = 0; a < n; ++a) lambda[a] = Rule::lambda(q, a);
    S u[Dim], udot[Dim], p(0.0);
    for (int i = 0; i < Dim; ++i) {
      u[i] = S(0.0);
      udot[i] = S(0.0);
    }
    for (int a = 0; a < n; ++a) {
      for (int i = 0; i < Dim; ++i) {
        u[i] += lambda[a] * x[a * n + i];
        udot[i] += S(lambda[a] * e.history[a][i]) + (lambda[a] * e.mass_coefficient) * x[a * n + i];
      }
      p += lambda[a] * x[a * n + Dim];
    }
    S acceleration[Dim], strong[Dim];  // ρ(u̇ + u·∇u) and r_M
    for (int i = 0; i < Dim; ++i) {
      S convective(0.0);
      if (e.convection)
        for (int j = 0; j < Dim; ++j) convective += u[j] * grad_u[i][j];
      acceleration[i] = rho * (udot[i] + convective);
      strong[i] = acceleration[i] + grad_p[i];
    }
    for (int a = 0; a < n; ++a) {
      S advect_w(0.0);  // u·∇λ_a (SUPG test direction)
      if (e.convection)
        for (int j = 0; j < Dim; ++j) advect_w += g[a][j] * u[j];
      S pspg(0.0);
      for (int i = 0; i < Dim; ++i) {
        r[a * n + i] += (w * lambda[a]) * acceleration[i] - (w * g[a][i]) * p +
                        (w * e.tau_m) * (advect_w * strong[i]);
        pspg += g[a][i] * strong[i];
      }
      r[a * n + Dim] += (w * lambda[a]) * div + (w * e.tau_m / rho) * pspg;
    }
  }
}

/// The element residual r ((Dim+1)² entries, may be null) and its Jacobian K by forward-mode
/// differentiation of element_residual (row-major, K[row·(Dim+1)² + col] = ∂r_row/∂x_col), τ
/// frozen as in `e`: the reference for element_residual_and_jacobian (tests/unit/fluid).
template <int Dim>
inline void element_residual_and_jacobian_by_differentiation(const ElementData<Dim>& e,
                                                             const double* x, double* r,
                                                             double* K) {
  constexpr int m = (Dim + 1) * (Dim + 1);
  Dual<m> xd[m], rd[m];
  for (int k = 0; k < m; ++k) {
    xd[k].v = x[k];
    xd[k].d[k] = 1.0;
  }
  element_residual<Dim, Dual<m>>(e, xd, rd);
  for (int row = 0; row < m; ++row) {
    if (r) r[row] = rd[row].v;
    for (int col = 0; col < m; ++col) K[row * m + col] = rd[row].d[col];
  }
}

/// The element residual r ((Dim+1)² entries, may be null) and its Jacobian K (row-major,
/// (Dim+1)²×(Dim+1)², K[row·(Dim+1)² + col] = ∂r_row/∂x_col) at the unknowns x, τ frozen as in
/// `e`. K is the derivative of element_residual written out term by term (the same as
/// differentiating it, about a tenth of the cost: the quadrature sums below are formed as
/// (Dim+1)×(Dim+1) tables first, then every entry is written once). With D_b = λ_b α₀/Δt + u·∇λ_b
/// (the derivative of ρ⁻¹ r_M,i with respect to u_i at vertex b, besides λ_b ∂_k u_i from u·∇u), at
/// each quadrature point (weight w):
///   ∂R_(a,i)/∂u_(b,k) += w ρ (λ_a + τ_M u·∇λ_a)(δ_ik D_b + λ_b ∂_k u_i) + w τ_M λ_b ∂_k λ_a r_M,i
///   ∂R_(a,i)/∂p_b     += −w λ_b ∂_i λ_a + w τ_M (u·∇λ_a) ∂_i λ_b
///   ∂R_(a,p)/∂u_(b,k) += w λ_a ∂_k λ_b + w τ_M (∂_k λ_a D_b + λ_b Σ_i ∂_i λ_a ∂_k u_i)
///   ∂R_(a,p)/∂p_b     += (w τ_M / ρ) ∇λ_a·∇λ_b
/// (the terms with u·∇ dropped for Stokes), plus the constant viscous and LSIC terms
/// |T| μ (δ_ik ∇λ_a·∇λ_b [+ ∂_k λ_a ∂_i λ_b, stress form]) + |T| ρ τ_C ∂_i λ_a ∂_k λ_b.
template <int Dim>
inline void element_residual_and_jacobian(const ElementData<Dim>& e, const double* x, double* r,
                                          double* K) {
  constexpr int n = Dim + 1, m = n * n;
  if (r) element_residual<Dim, double>(e, x, r);
  const auto& g = e.gradients;
  const double rho = e.density, mu = e.viscosity, tau = e.tau_m;
  const bool convection = e.convection, stress = e.viscous_form == ViscousForm::stress;
  // Constant gradients: grad_u[i][k] = ∂_k u_i, grad_p, and the products ∇λ_a·∇λ_b and
  // gu[a][k] = Σ_i ∂_i λ_a ∂_k u_i.
  double grad_u[Dim][Dim] = {}, grad_p[Dim] = {};
  for (int a = 0; a < n; ++a)
    for (int k = 0; k < Dim; ++k) {
      for (int i = 0; i < Dim; ++i) grad_u[i][k] += g[a][k] * x[a * n + i];
      grad_p[k] += g[a][k] * x[a * n + Dim];
    }
  double gg[n][n], gu[n][Dim];
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      double sum = 0;
      for (int i = 0; i < Dim; ++i) sum += g[a][i] * g[b][i];
      gg[a][b] = sum;
    }
    for (int k = 0; k < Dim; ++k) {
      double sum = 0;
      for (int i = 0; i < Dim; ++i) sum += g[a][i] * grad_u[i][k];
      gu[a][k] = sum;
    }
  }
  // The quadrature sums, so that the (Dim+1)⁴ entries are written once:
  //   TD[a][b] = Σ w (λ_a + τ u·∇λ_a) D_b,  TL[a][b] = Σ w (λ_a + τ u·∇λ_a) λ_b,
  //   SL[b][i] = Σ w λ_b r_M,i,  A[a] = Σ w u·∇λ_a,  DS[b] = Σ w D_b  (Σ w λ_b = |T|/n).
  double TD[n][n] = {}, TL[n][n] = {}, SL[n][Dim] = {}, A[n] = {}, DS[n] = {};
  using Rule = Degree2Rule<Dim>;
  for (int q = 0; q < Rule::n; ++q) {
    const double w = Rule::weight * e.measure;
    double lambda[n];
    for (int a = 0; a < n; ++a) lambda[a] = Rule::lambda(q, a);
    double u[Dim] = {}, udot[Dim] = {};
    for (int a = 0; a < n; ++a)
      for (int i = 0; i < Dim; ++i) {
        u[i] += lambda[a] * x[a * n + i];
        udot[i] += lambda[a] * e.history[a][i] + lambda[a] * e.mass_coefficient * x[a * n + i];
      }
    double strong[Dim];  // r_M
    for (int i = 0; i < Dim; ++i) {
      double convective = 0;
      if (convection)
        for (int j = 0; j < Dim; ++j) convective += u[j] * grad_u[i][j];
      strong[i] = rho * (udot[i] + convective) + grad_p[i];
    }
    double d[n], test[n];  // D_a, w (λ_a + τ u·∇λ_a)
    for (int a = 0; a < n; ++a) {
      double advect = 0;  // u·∇λ_a
      if (convection)
        for (int j = 0; j < Dim; ++j) advect += g[a][j] * u[j];
      d[a] = lambda[a] * e.mass_coefficient + advect;
      test[a] = w * (lambda[a] + tau * advect);
      A[a] += w * advect;
      DS[a] += w * d[a];
      for (int i = 0; i < Dim; ++i) SL[a][i] += w * lambda[a] * strong[i];
    }
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        TD[a][b] += test[a] * d[b];
        TL[a][b] += test[a] * lambda[b];
      }
  }
  // Every entry once: the quadrature sums plus the constant viscous and LSIC terms.
  const double mean = e.measure / n;  // Σ w λ_b
  const double viscous = e.measure * mu, lsic = e.measure * rho * e.tau_c;
  for (int a = 0; a < n; ++a) {
    for (int i = 0; i < Dim; ++i) {
      double* row = K + (a * n + i) * m;
      for (int b = 0; b < n; ++b) {
        for (int k = 0; k < Dim; ++k) {
          double value = lsic * g[a][i] * g[b][k];
          if (stress) value += viscous * g[a][k] * g[b][i];
          if (convection) value += rho * grad_u[i][k] * TL[a][b] + tau * g[a][k] * SL[b][i];
          if (k == i) value += viscous * gg[a][b] + rho * TD[a][b];
          row[b * n + k] = value;
        }
        row[b * n + Dim] = -mean * g[a][i] + tau * A[a] * g[b][i];
      }
    }
    double* row = K + (a * n + Dim) * m;
    for (int b = 0; b < n; ++b) {
      for (int k = 0; k < Dim; ++k) {
        double value = mean * g[b][k] + tau * g[a][k] * DS[b];
        if (convection) value += tau * mean * gu[a][k];
        row[b * n + k] = value;
      }
      row[b * n + Dim] = tau / rho * e.measure * gg[a][b];
    }
  }
}

/// One outlet facet of a cell, for the backflow term: the positions (0..Dim) of its vertices
/// in the cell, its unit outward normal and measure, and the coefficient β ρ / 2.
template <int Dim>
struct OutletFacet {
  int local[Dim];                   ///< facet vertex a is cell vertex local[a]
  double normal[Dim];               ///< unit normal out of the domain
  double measure = 0;               ///< |F| [m^(Dim−1)]
  double backflow_coefficient = 0;  ///< β ρ / 2 [kg/m³]
};

/// Backflow stabilisation (Esmaily-Moghadam, Bazilevs, Hsia, Vignon-Clementel & Marsden 2011,
/// Comput. Mech. 48:277) on one outlet facet, added to the cell residual r:
///
///   R_w += −(β ρ / 2) ∫_F min(u·n, 0) (u·w)
///
/// Where fluid enters through the outlet (u·n < 0) this removes the convective energy it
/// brings in: tested with w = u the term is −(βρ/2) min(u·n, 0)|u|² ≥ 0. It is zero where the
/// flow leaves, so a forward-flowing outlet is untouched. The integrand is not polynomial
/// (the kink of min), so the rule is the degree-2 one of the facet: 2-point Gauss on a
/// segment, the 3-point interior rule on a triangle. x and r are the cell's (Dim+1)² unknowns
/// and residual entries (node-major); S is double or Dual.
template <int Dim, class S>
inline void backflow_facet_residual(const OutletFacet<Dim>& f, const S* x, S* r) {
  constexpr int n = Dim + 1;
  constexpr int n_points = Dim == 2 ? 2 : 3;
  for (int q = 0; q < n_points; ++q) {
    double lambda[Dim];
    if constexpr (Dim == 2) {
      const double g = 0.5 / std::sqrt(3.0);
      lambda[0] = q == 0 ? 0.5 - g : 0.5 + g;
      lambda[1] = 1.0 - lambda[0];
    } else {
      for (int a = 0; a < 3; ++a) lambda[a] = a == q ? 2.0 / 3.0 : 1.0 / 6.0;
    }
    const double w = f.measure / n_points;
    S u[Dim], normal_velocity(0.0);
    for (int i = 0; i < Dim; ++i) {
      u[i] = S(0.0);
      for (int a = 0; a < Dim; ++a) u[i] += lambda[a] * x[f.local[a] * n + i];
      normal_velocity += f.normal[i] * u[i];
    }
    if (!(value_of(normal_velocity) < 0.0)) continue;
    for (int a = 0; a < Dim; ++a)
      for (int i = 0; i < Dim; ++i)
        r[f.local[a] * n + i] +=
            (-f.backflow_coefficient * w * lambda[a]) * (normal_velocity * u[i]);
  }
}

/// The backflow term of one facet added to the cell residual r (may be null) and Jacobian K
/// (layout of element_residual_and_jacobian).
template <int Dim>
inline void backflow_facet_residual_and_jacobian(const OutletFacet<Dim>& f, const double* x,
                                                 double* r, double* K) {
  constexpr int m = (Dim + 1) * (Dim + 1);
  Dual<m> xd[m], rd[m];
  for (int k = 0; k < m; ++k) {
    xd[k].v = x[k];
    xd[k].d[k] = 1.0;
  }
  backflow_facet_residual<Dim, Dual<m>>(f, xd, rd);
  for (int row = 0; row < m; ++row) {
    if (r) r[row] += rd[row].v;
    for (int col = 0; col < m; ++col) K[row * m + col] += rd[row].d[col];
  }
}

}  // namespace coapt::fluid
