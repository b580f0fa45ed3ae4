// The fit's local linear model (docs/calibration.md, "Fitting scheme"): the
// continuous bond parameters in log space,
//   u = (ln E_b, ln kn/ks, ln sigma_b, ln c/sigma_b, ln lambda),
// lambda the flat joint's tension softening (held at its value unless the
// toughness is a target: StepRuleN::free), against the four targets,
//   y = (ln E, nu, ln UCS, ln T),
// and, when the toughness is a target, a fifth, ln K_IC (Ny = 5),
// linearised as y(u + du) ~ y(u) + J du. J is estimated from the iterations
// made so far (all differences to the last one: a multi-secant,
// "generalised Broyden" estimate; Fang & Saad 2009, Numer. Linear Algebra
// Appl. 16, eq. 3), regularised towards a prior J0 (ridge regression: a
// difference that is mostly noise cannot turn a slope round), and the step
// is the damped Gauss-Newton step of Levenberg (1944) / Marquardt (1963)
// with bounds on the parameters (active set: a parameter that would leave
// its bounds is fixed there and the others re-solved).
// Pure arithmetic, no engine: tested in tests/driver/test_local_model.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace mill::calibrate {

inline constexpr size_t kNu = 5;  // parameters u
inline constexpr size_t kNy = 4;  // responses y of the four macro targets
using ParamVec = std::array<double, kNu>;
// Ny responses (4: E, nu, UCS, T; 5: and the toughness K_IC).
template <size_t Ny>
using VecN = std::array<double, Ny>;
template <size_t Ny>
using MatN = std::array<ParamVec, Ny>;  // [response][parameter]
using Mat4 = MatN<4>;

// One iteration's point: its parameters and responses.
template <size_t Ny>
struct ModelPointN {
  ParamVec u{};
  VecN<Ny> y{};
};
using ModelPoint = ModelPointN<4>;

// The Jacobian from the points (the last is the current one): per response
// row i, minimises sum_k (dy_ik - J_i . du_k)^2 + lambda sum_m (J_im -
// J0_im)^2 over the differences du_k = u_k - u_last, dy_k = y_k - y_last.
// With no other point it is J0. Afterwards each entry is kept within
// [lo, hi] (per entry; the sign and size physics allows).
template <size_t Ny>
MatN<Ny> estimate_jacobian(const std::vector<ModelPointN<Ny>>& pts, const MatN<Ny>& prior,
                           double lambda, const MatN<Ny>& lo, const MatN<Ny>& hi);

// Settings of one step.
template <size_t Ny>
struct StepRuleN {
  VecN<Ny>
      weight{};     // per response: 1 / its tolerance (errors in tolerance units; 0: not a target)
  double mu = 0.1;  // Levenberg-Marquardt damping
  ParamVec scale{};           // per parameter: its prior slope on its own target, weighted
  ParamVec max_step{};        // |du_m| at most this (a trust region per parameter)
  ParamVec lower{}, upper{};  // bounds of u_m + du_m
  // 0: the parameter takes its held value this step (the softening is held
  // unless a step frees it)
  ParamVec free{1, 1, 1, 1, 0};
  ParamVec held{};  // the step of a parameter that is not free
};
using StepRule = StepRuleN<4>;

// The step du minimising sum_i (w_i (J du - e)_i)^2 + mu sum_m
// (scale_m du_m)^2 with e = target - y, each du_m within its max_step
// and u_m + du_m within its bounds (a component past them is fixed there and
// the rest re-solved, at most 5 rounds). Components with free = 0 take
// their held value.
template <size_t Ny>
ParamVec damped_step(const MatN<Ny>& J, const VecN<Ny>& e, const ParamVec& u,
                     const StepRuleN<Ny>& rule);

// J du (the responses' predicted change).
template <size_t Ny>
VecN<Ny> predict(const MatN<Ny>& J, const ParamVec& du);

// Solves the n x n system A x = b (n <= kNu) by Gaussian elimination with
// partial pivoting; false if A is singular (pivot below 1e-300).
bool solve_small(std::vector<std::vector<double>> A, std::vector<double> b,
                 std::vector<double>& x);

}  // namespace mill::calibrate
