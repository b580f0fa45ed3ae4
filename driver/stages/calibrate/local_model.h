// The fit's local linear model (docs/calibration.md, "Fitting scheme"): the
// four continuous bond parameters in log space,
//   u = (ln E_b, ln kn/ks, ln sigma_b, ln c/sigma_b),
// against the four targets,
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

inline constexpr size_t kNu = 4;  // parameters u
inline constexpr size_t kNy = 4;  // responses y of the four macro targets
using Vec4 = std::array<double, 4>;
// Ny responses (4: E, nu, UCS, T; 5: and the toughness K_IC).
template <size_t Ny>
using VecN = std::array<double, Ny>;
template <size_t Ny>
using MatN = std::array<Vec4, Ny>;  // [response][parameter]
using Mat4 = MatN<4>;

// One iteration's point: its parameters and responses.
template <size_t Ny>
struct ModelPointN {
  Vec4 u{};
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
  Vec4 scale{};     // per parameter: its prior slope on its own target, weighted
  Vec4 max_step{};  // |du_m| at most this (a trust region per parameter)
  Vec4 lower{}, upper{};  // bounds of u_m + du_m
  Vec4 free{1, 1, 1, 1};  // 0: the parameter takes its held value this step
  Vec4 held{};            // the step of a parameter that is not free
};
using StepRule = StepRuleN<4>;

// The step du minimising sum_i (w_i (J du - e)_i)^2 + mu sum_m
// (scale_m du_m)^2 with e = target - y, each du_m within its max_step
// and u_m + du_m within its bounds (a component past them is fixed there and
// the rest re-solved, at most 4 rounds). Components with free = 0 take
// their held value.
template <size_t Ny>
Vec4 damped_step(const MatN<Ny>& J, const VecN<Ny>& e, const Vec4& u, const StepRuleN<Ny>& rule);

// J du (the responses' predicted change).
template <size_t Ny>
VecN<Ny> predict(const MatN<Ny>& J, const Vec4& du);

// Solves the n x n system A x = b (n <= 4) by Gaussian elimination with
// partial pivoting; false if A is singular (pivot below 1e-300).
bool solve_small(std::vector<std::vector<double>> A, std::vector<double> b,
                 std::vector<double>& x);

}  // namespace mill::calibrate
