// The fit's local linear model (stages/calibrate/local_model.h) against
// closed forms: the small solver, the multi-secant Jacobian on exactly
// linear data, the damped step and its bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "stages/calibrate/local_model.h"

using namespace mill::calibrate;

namespace {

Mat4 identity() {
  Mat4 m{};
  for (size_t i = 0; i < 4; ++i) m[i][i] = 1.0;
  return m;
}

Mat4 filled(double v) {
  Mat4 m{};
  for (auto& r : m) r.fill(v);
  return m;
}

StepRule plain_rule() {
  StepRule r;
  r.weight = {1, 1, 1, 1};
  r.mu = 0.0;
  r.scale = {1, 1, 1, 1, 1};
  r.max_step = {10, 10, 10, 10, 10};
  r.lower = {-1e300, -1e300, -1e300, -1e300, -1e300};
  r.upper = {1e300, 1e300, 1e300, 1e300, 1e300};
  return r;
}

}  // namespace

// A 3 x 3 system with a zero first pivot (needs the row swap); exact to 1e-12.
TEST(LocalModel, SolveSmallPivots) {
  std::vector<std::vector<double>> A{{0, 2, 1}, {1, 1, 0}, {2, 0, 3}};
  const std::vector<double> x_true{1.5, -2.0, 0.25};
  std::vector<double> b(3, 0.0), x;
  for (size_t r = 0; r < 3; ++r)
    for (size_t c = 0; c < 3; ++c) b[r] += A[r][c] * x_true[c];
  ASSERT_TRUE(solve_small(A, b, x));
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(x[i], x_true[i], 1e-12);
  EXPECT_FALSE(solve_small({{1, 2}, {2, 4}}, {1, 2}, x));
}

// One point: no difference to learn from, the prior comes back unchanged.
TEST(LocalModel, OnePointGivesThePrior) {
  const Mat4 prior = identity();
  const Mat4 J = estimate_jacobian({ModelPoint{}}, prior, 0.02, filled(-5), filled(5));
  for (size_t i = 0; i < 4; ++i)
    for (size_t m = 0; m < 4; ++m) EXPECT_EQ(J[i][m], prior[i][m]);
}

// Five points of an exactly linear map whose four differences span the
// parameters: with a vanishing ridge the map comes back to 1e-6.
TEST(LocalModel, RecoversALinearMap) {
  const Mat4 Jt{{{1.1, -0.3, 0.0, 0.05}, {0.02, 0.12, 0.0, 0.03}, {0.1, 0.2, 0.9, 0.6},
                 {0.0, -0.1, 1.0, 0.45}}};
  const VecN<4> y0{3.0, 0.2, 1.0, -1.0};
  const std::vector<ParamVec> us{{0.1, 0.2, 0.3, 0.4},
                                 {0.5, 0.1, -0.2, 0.3},
                                 {0.0, 0.6, 0.1, -0.1},
                                 {-0.3, 0.2, 0.7, 0.2},
                                 {0.2, -0.4, 0.1, 0.9}};
  std::vector<ModelPoint> pts;
  for (const ParamVec& u : us)
    pts.push_back({u, [&] {
                     VecN<4> y = predict(Jt, u);
                     for (size_t i = 0; i < 4; ++i) y[i] += y0[i];
                     return y;
                   }()});
  const Mat4 J = estimate_jacobian(pts, identity(), 1e-12, filled(-5), filled(5));
  for (size_t i = 0; i < 4; ++i)
    for (size_t m = 0; m < 4; ++m) EXPECT_NEAR(J[i][m], Jt[i][m], 1e-6) << i << "," << m;
}

// One difference along the first parameter: that column follows the data
// (slope 2 from the ridge solution 2 d^2 / (d^2 + lambda) with d = 0.5,
// lambda = 0.02 pulling towards the prior's 1: (2 * 0.25 + 0.02) / 0.27),
// the other columns keep the prior; a clamp caps what the data says.
TEST(LocalModel, OneDifferenceMovesOneColumn) {
  const Mat4 prior = identity();
  std::vector<ModelPoint> pts(2);
  pts[0].u = {0.5, 0, 0, 0};
  pts[0].y = {1.0, 0, 0, 0};
  const Mat4 J = estimate_jacobian(pts, prior, 0.02, filled(-5), filled(5));
  EXPECT_NEAR(J[0][0], (2.0 * 0.25 + 0.02) / 0.27, 1e-12);
  EXPECT_NEAR(J[1][1], 1.0, 1e-12);
  EXPECT_NEAR(J[0][1], 0.0, 1e-12);
  Mat4 hi = filled(5);
  hi[0][0] = 1.5;
  EXPECT_EQ(estimate_jacobian(pts, prior, 0.02, filled(-5), hi)[0][0], 1.5);
}

// Undamped and within bounds, the step solves J du = e exactly (1e-12).
TEST(LocalModel, UndampedStepIsNewtons) {
  const Mat4 J{{{1.0, 0.2, 0, 0}, {0, 0.1, 0, 0}, {0, 0, 1.0, 0.8}, {0, 0, 1.0, 0.35}}};
  const VecN<4> e{0.3, -0.02, 0.4, 0.1};
  const ParamVec du = damped_step(J, e, ParamVec{}, plain_rule());
  const VecN<4> dy = predict(J, du);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(dy[i], e[i], 1e-12);
}

// Damping on a diagonal J: du_m = w^2 J e / (w^2 J^2 + mu s^2) (Marquardt
// 1963 for one parameter), 1e-12.
TEST(LocalModel, DampedStepOnADiagonal) {
  Mat4 J = identity();
  J[1][1] = 0.1;
  StepRule r = plain_rule();
  r.weight = {10, 20, 10, 10};
  r.scale = {10, 2, 10, 10};
  r.mu = 0.1;
  const VecN<4> e{0.3, 0.05, -0.2, 0.1};
  const ParamVec du = damped_step(J, e, ParamVec{}, r);
  for (size_t m = 0; m < 4; ++m) {
    const double w = r.weight[m], j = J[m][m], s = r.scale[m];
    EXPECT_NEAR(du[m], w * w * j * e[m] / (w * w * j * j + r.mu * s * s), 1e-12) << m;
  }
}

// A step past its cap is fixed at the cap and the others re-solved: two
// strengths that both follow u2 (slope 1) and the ratio u3 (slopes 0.8 and
// 0.35); the Newton step wants du3 = (e2 - e3) / 0.45 = 1.54 > cap 1.
// With du3 = 1, du2 minimises (du2 + 0.8 - e2)^2 + (du2 + 0.35 - e3)^2:
// du2 = (e2 + e3 - 1.15) / 2.
TEST(LocalModel, CappedComponentIsFixedAndTheRestResolved) {
  const Mat4 J{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1.0, 0.8}, {0, 0, 1.0, 0.35}}};
  StepRule r = plain_rule();
  r.max_step = {10, 10, 10, 1.0, 10};
  const VecN<4> e{0, 0, std::log(2.0), 0.0};
  const ParamVec du = damped_step(J, e, ParamVec{}, r);
  EXPECT_NEAR(du[3], 1.0, 1e-12);
  EXPECT_NEAR(du[2], (std::log(2.0) + 0.0 - 1.15) / 2.0, 1e-12);
  // A bound on the value acts the same way: u3 = 0.5 with an upper bound 1.2.
  r.max_step = {10, 10, 10, 10, 10};
  r.upper[3] = 1.2;
  const ParamVec dv = damped_step(J, e, ParamVec{0, 0, 0, 0.5, 0}, r);
  EXPECT_NEAR(dv[3], 0.7, 1e-12);
  EXPECT_NEAR(dv[2], (std::log(2.0) - 0.7 * 1.15) / 2.0, 1e-12);
  // A parameter that is not free does not move.
  r.free[3] = 0.0;
  const ParamVec dw = damped_step(J, e, ParamVec{}, r);
  EXPECT_EQ(dw[3], 0.0);
  EXPECT_NEAR(dw[2], std::log(2.0) / 2.0, 1e-12);
}

// A fifth response (the toughness) with weight 0 changes no step: the same
// du as the four-response model, to the last bit. With its weight it pulls
// the step: five responses and four parameters, the least-squares step of
// the weighted normal equations (here: strengths u2 = 1 on T, K; K wants
// +0.4, T wants 0: du2 = 0.2 when both weigh 1, with the ratio u3 fixed).
TEST(LocalModel, FifthResponseCountsOnlyWithItsWeight) {
  const Mat4 J4{{{1.0, 0.2, 0, 0}, {0, 0.1, 0, 0}, {0, 0, 1.0, 0.8}, {0, 0, 1.0, 0.35}}};
  MatN<5> J5{};
  for (size_t i = 0; i < 4; ++i) J5[i] = J4[i];
  J5[4] = {0.0, -0.5, 1.0, 0.0};
  const VecN<4> e4{0.3, -0.02, 0.4, 0.1};
  const VecN<5> e5{0.3, -0.02, 0.4, 0.1, -0.7};
  StepRule r4 = plain_rule();
  r4.mu = 0.01;
  StepRuleN<5> r5;
  r5.weight = {1, 1, 1, 1, 0};
  r5.mu = r4.mu;
  r5.scale = r4.scale;
  r5.max_step = r4.max_step;
  r5.lower = r4.lower;
  r5.upper = r4.upper;
  const ParamVec a = damped_step(J4, e4, ParamVec{}, r4), b = damped_step(J5, e5, ParamVec{}, r5);
  for (size_t m = 0; m < 4; ++m) EXPECT_EQ(a[m], b[m]) << m;
  // Weighted: a T row and a K row on u2 alone, the others fixed.
  MatN<5> J{};
  J[3] = {0, 0, 1.0, 0};
  J[4] = {0, 0, 1.0, 0};
  StepRuleN<5> r = r5;
  r.mu = 0.0;
  r.weight = {0, 0, 0, 1, 1};
  r.free = {0, 0, 1, 0, 0};
  const ParamVec du = damped_step(J, VecN<5>{0, 0, 0, 0.0, 0.4}, ParamVec{}, r);
  EXPECT_NEAR(du[2], 0.2, 1e-12);
  r.weight[4] = 3.0;  // K weighs 9 x T in the squares: du2 = 9 x 0.4 / 10
  EXPECT_NEAR(damped_step(J, VecN<5>{0, 0, 0, 0.0, 0.4}, ParamVec{}, r)[2], 0.36, 1e-12);
}

// The fifth parameter, the flat joint's tension softening, is held unless
// the step frees it (StepRuleN::free defaults to {1, 1, 1, 1, 0}): held,
// the step is that of the same model without the fifth column, to the last
// bit. Freed, five responses and five parameters: a square system, whose
// undamped step solves J du = e exactly (1e-12): the strengths follow
// sigma_b (slope 1) and the softening (T 0.35, K_IC 0.55), the UCS the
// cohesion ratio too, so K_IC/T moves with the softening (and kn/ks).
TEST(LocalModel, SofteningIsHeldUnlessFreedAndThenSolvesTheToughness) {
  MatN<5> J{};
  J[0] = {1.0, 0.2, 0, 0, 0};
  J[1] = {0, 0.1, 0, 0, 0};
  J[2] = {0, 0, 1.0, 0.8, 0.17};
  J[3] = {0, 0, 1.0, 0.0, 0.35};
  J[4] = {0, -0.5, 1.0, 0.0, 0.55};
  const VecN<5> e{0.3, -0.02, 0.4, 0.1, 0.9};
  StepRuleN<5> r;
  r.weight = {1, 1, 1, 1, 1};
  r.mu = 0.0;
  r.scale = {1, 1, 1, 1, 1};
  r.max_step = {10, 10, 10, 10, 10};
  r.lower = {-1e300, -1e300, -1e300, -1e300, -1e300};
  r.upper = {1e300, 1e300, 1e300, 1e300, 1e300};
  const ParamVec held = damped_step(J, e, ParamVec{}, r);
  EXPECT_EQ(held[4], 0.0);
  MatN<5> J4 = J;
  for (auto& row : J4) row[4] = 0.0;
  const ParamVec same = damped_step(J4, e, ParamVec{}, r);
  for (size_t m = 0; m < 4; ++m) EXPECT_EQ(held[m], same[m]) << m;
  r.free[4] = 1.0;
  const ParamVec du = damped_step(J, e, ParamVec{}, r);
  const VecN<5> dy = predict(J, du);
  for (size_t i = 0; i < 5; ++i) EXPECT_NEAR(dy[i], e[i], 1e-12) << i;
  // K_IC - T = e4 - e3 = 0.8 = 0.2 dlambda - 0.5 dkn/ks.
  EXPECT_NEAR(du[4], (0.9 - 0.1 + 0.5 * du[1]) / 0.2, 1e-9);
  // Its bound: from brittle (u4 = 0) it does not go below 0.
  r.lower[4] = 0.0;
  EXPECT_GE(damped_step(J, VecN<5>{0, 0, 0, 0, -0.5}, ParamVec{}, r)[4], 0.0);
}
