// The fit's local linear model: multi-secant Jacobian, damped bounded step.
#include "stages/calibrate/local_model.h"

#include <algorithm>
#include <cmath>

namespace mill::calibrate {

bool solve_small(std::vector<std::vector<double>> A, std::vector<double> b,
                 std::vector<double>& x) {
  const size_t n = b.size();
  for (size_t c = 0; c < n; ++c) {
    size_t piv = c;
    for (size_t r = c + 1; r < n; ++r)
      if (std::abs(A[r][c]) > std::abs(A[piv][c])) piv = r;
    if (std::abs(A[piv][c]) < 1e-300) return false;
    std::swap(A[piv], A[c]);
    std::swap(b[piv], b[c]);
    for (size_t r = c + 1; r < n; ++r) {
      const double f = A[r][c] / A[c][c];
      for (size_t k = c; k < n; ++k) A[r][k] -= f * A[c][k];
      b[r] -= f * b[c];
    }
  }
  x.assign(n, 0.0);
  for (size_t r = n; r-- > 0;) {
    double s = b[r];
    for (size_t k = r + 1; k < n; ++k) s -= A[r][k] * x[k];
    x[r] = s / A[r][r];
  }
  return true;
}

template <size_t Ny>
MatN<Ny> estimate_jacobian(const std::vector<ModelPointN<Ny>>& pts, const MatN<Ny>& prior,
                           double lambda, const MatN<Ny>& lo, const MatN<Ny>& hi) {
  MatN<Ny> J = prior;
  if (pts.size() < 2) return J;
  const ModelPointN<Ny>& last = pts.back();
  // Per row i: (sum_k du_k du_k^T + lambda I) J_i = sum_k du_k dy_ik + lambda J0_i.
  std::vector<std::vector<double>> A(kNu, std::vector<double>(kNu, 0.0));
  for (size_t k = 0; k + 1 < pts.size(); ++k)
    for (size_t a = 0; a < kNu; ++a)
      for (size_t b = 0; b < kNu; ++b)
        A[a][b] += (pts[k].u[a] - last.u[a]) * (pts[k].u[b] - last.u[b]);
  for (size_t a = 0; a < kNu; ++a) A[a][a] += lambda;
  for (size_t i = 0; i < Ny; ++i) {
    std::vector<double> rhs(kNu, 0.0), row;
    for (size_t a = 0; a < kNu; ++a) {
      for (size_t k = 0; k + 1 < pts.size(); ++k)
        rhs[a] += (pts[k].u[a] - last.u[a]) * (pts[k].y[i] - last.y[i]);
      rhs[a] += lambda * prior[i][a];
    }
    if (!solve_small(A, rhs, row)) continue;  // lambda > 0 keeps A positive definite
    for (size_t a = 0; a < kNu; ++a) J[i][a] = std::clamp(row[a], lo[i][a], hi[i][a]);
  }
  return J;
}

template <size_t Ny>
VecN<Ny> predict(const MatN<Ny>& J, const ParamVec& du) {
  VecN<Ny> dy{};
  for (size_t i = 0; i < Ny; ++i)
    for (size_t m = 0; m < kNu; ++m) dy[i] += J[i][m] * du[m];
  return dy;
}

template <size_t Ny>
ParamVec damped_step(const MatN<Ny>& J, const VecN<Ny>& e, const ParamVec& u,
                     const StepRuleN<Ny>& rule) {
  ParamVec du{};
  std::array<bool, kNu> fixed{};
  for (size_t m = 0; m < kNu; ++m) {
    fixed[m] = rule.free[m] == 0.0;
    if (fixed[m]) du[m] = rule.held[m];
  }
  for (size_t round = 0; round <= kNu; ++round) {
    // Normal equations of the free components, the fixed ones moved to the
    // right-hand side: (J_f^T W^2 J_f + D) du_f = J_f^T W^2 (e - J_x du_x).
    std::vector<size_t> idx;
    for (size_t m = 0; m < kNu; ++m)
      if (!fixed[m]) idx.push_back(m);
    if (idx.empty()) break;
    VecN<Ny> r = e;
    for (size_t i = 0; i < Ny; ++i)
      for (size_t m = 0; m < kNu; ++m)
        if (fixed[m]) r[i] -= J[i][m] * du[m];
    const size_t n = idx.size();
    std::vector<std::vector<double>> A(n, std::vector<double>(n, 0.0));
    std::vector<double> b(n, 0.0), x;
    for (size_t a = 0; a < n; ++a) {
      for (size_t c = 0; c < n; ++c)
        for (size_t i = 0; i < Ny; ++i)
          A[a][c] += rule.weight[i] * rule.weight[i] * J[i][idx[a]] * J[i][idx[c]];
      A[a][a] += rule.mu * rule.scale[idx[a]] * rule.scale[idx[a]];
      for (size_t i = 0; i < Ny; ++i) b[a] += rule.weight[i] * rule.weight[i] * J[i][idx[a]] * r[i];
    }
    if (!solve_small(A, b, x)) break;
    // The component farthest past its limits (as a share of its step) is
    // fixed at the limit; the others are solved again.
    double worst = 0.0;
    size_t worst_m = kNu;
    for (size_t a = 0; a < n; ++a) {
      const size_t m = idx[a];
      du[m] = x[a];
      const double hi = std::min(rule.max_step[m], rule.upper[m] - u[m]);
      const double lo = std::max(-rule.max_step[m], rule.lower[m] - u[m]);
      // The share of the step that lies past the limit.
      const double over = x[a] > hi   ? (x[a] - hi) / std::abs(x[a])
                          : x[a] < lo ? (lo - x[a]) / std::abs(x[a])
                                      : 0.0;
      if (over > 0.0 && (worst_m == kNu || over > worst)) {
        worst = over;
        worst_m = m;
      }
    }
    if (worst_m == kNu) return du;
    const size_t m = worst_m;
    du[m] = std::clamp(du[m], std::max(-rule.max_step[m], rule.lower[m] - u[m]),
                       std::min(rule.max_step[m], rule.upper[m] - u[m]));
    fixed[m] = true;
  }
  for (size_t m = 0; m < kNu; ++m)
    if (rule.free[m] != 0.0)
      du[m] = std::clamp(du[m], std::max(-rule.max_step[m], rule.lower[m] - u[m]),
                         std::min(rule.max_step[m], rule.upper[m] - u[m]));
  return du;
}

// The fit's two models: the four macro targets, and those with the toughness.
template MatN<4> estimate_jacobian<4>(const std::vector<ModelPointN<4>>&, const MatN<4>&, double,
                                      const MatN<4>&, const MatN<4>&);
template MatN<5> estimate_jacobian<5>(const std::vector<ModelPointN<5>>&, const MatN<5>&, double,
                                      const MatN<5>&, const MatN<5>&);
template VecN<4> predict<4>(const MatN<4>&, const ParamVec&);
template VecN<5> predict<5>(const MatN<5>&, const ParamVec&);
template ParamVec damped_step<4>(const MatN<4>&, const VecN<4>&, const ParamVec&,
                                 const StepRuleN<4>&);
template ParamVec damped_step<5>(const MatN<5>&, const VecN<5>&, const ParamVec&,
                                 const StepRuleN<5>&);

}  // namespace mill::calibrate
