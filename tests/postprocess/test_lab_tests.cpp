// Virtual lab tests on hand-made data: stress and strain of a load curve with
// known E, nu and peak; the Brazilian formula; the calibration step on
// analytic response models.
#include "postprocess/lab_tests.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

namespace mill::post {
namespace {

// A platen test of a specimen of gauge length L and area A with modulus E,
// Poisson's ratio nu: a seating toe, a linear part, softening to a peak at
// strain eps_p, then a drop. Forces of the two platens differ by +-1%.
LoadCurve MakeCurve(double E, double nu, double eps_p, double L, double A) {
  LoadCurve c;
  const int n = 400;
  for (int i = 0; i <= n; ++i) {
    const double eps = 1.5 * eps_p * i / n;
    double sigma;
    const double eps_toe = 0.05 * eps_p;
    if (eps < eps_toe)
      sigma = 0.5 * E * eps * eps / eps_toe;  // seating: stiffness rises from 0 to E
    else if (eps < 0.6 * eps_p)
      sigma = E * (eps - 0.5 * eps_toe);
    else if (eps <= eps_p) {
      const double s0 = E * (0.6 * eps_p - 0.5 * eps_toe), x = (eps - 0.6 * eps_p) / (0.4 * eps_p);
      sigma = s0 + E * 0.4 * eps_p * (x - 0.5 * x * x);  // tangent falls to 0 at the peak
    } else {
      sigma = E * (0.8 * eps_p - 0.5 * eps_toe) * std::exp(-(eps - eps_p) / (0.05 * eps_p));
    }
    c.time.push_back(i * 1e-5);
    c.displacement.push_back(eps * L);
    c.force_top.push_back(1.01 * sigma * A);
    c.force_bottom.push_back(0.99 * sigma * A);
    c.lateral_strain.push_back(eps < 0.6 * eps_p ? nu * eps : nu * eps + 2.0 * (eps - 0.6 * eps_p));
    c.broken_bonds.push_back(eps > 0.6 * eps_p ? i : 0);
  }
  return c;
}

TEST(LabTests, StressStrainFromPlatenForceAndClosure) {
  LoadCurve c;
  c.displacement = {0.0, 1e-5, 2e-5};
  c.force_top = {0.0, 110.0, 200.0};
  c.force_bottom = {0.0, 90.0, 200.0};
  c.lateral_strain = {0.0, 1e-5, 2e-5};
  const StressStrain s = ToStressStrain(c, 0.05, 1e-3);
  ASSERT_EQ(s.strain.size(), 3u);
  EXPECT_DOUBLE_EQ(s.strain[2], 2e-5 / 0.05);
  EXPECT_DOUBLE_EQ(s.stress[1], 100.0 / 1e-3);  // mean of the two platens
  EXPECT_DOUBLE_EQ(s.stress[2], 2e5);
  EXPECT_THROW(ToStressStrain(c, 0.0, 1e-3), std::invalid_argument);
}

TEST(LabTests, YoungsModulusPoissonRatioAndPeakOfAHandMadeCurve) {
  const double E = 18.69e9, nu = 0.18, eps_p = 2.5e-3, L = 0.04, A = M_PI * 0.01 * 0.01;
  const LoadCurve c = MakeCurve(E, nu, eps_p, L, A);
  const UcsResult r = AnalyseUcs(ToStressStrain(c, L, A));
  EXPECT_NEAR(r.youngs_modulus / E, 1.0, 1e-6);  // the 20-50% window lies on the linear part
  EXPECT_NEAR(r.poisson_ratio, nu, 1e-9);
  const double peak = E * (0.8 * eps_p - 0.025 * eps_p);
  EXPECT_NEAR(r.ucs / peak, 1.0, 1e-4);
  EXPECT_NEAR(r.strain_at_peak, eps_p, 1.5 * eps_p / 400);
  EXPECT_GT(r.fit.r2, 0.999999);
  EXPECT_NEAR(r.fit_stress_lo, 0.2 * r.ucs, 1e-6 * r.ucs);
}

TEST(LabTests, UcsWithoutLoadOrWithTooFewSamplesIsAnError) {
  StressStrain s;
  s.strain = {0, 1, 2};
  s.stress = {0, 0, 0};
  s.lateral_strain = {0, 0, 0};
  EXPECT_THROW(AnalyseUcs(s), std::runtime_error);
  s.stress = {0, 10, 5};  // a peak but nothing in the window
  EXPECT_THROW(AnalyseUcs(s), std::runtime_error);
}

TEST(LabTests, BrazilianFormula) {
  // 2 F / (pi D t): 10 kN on a 50 mm x 25 mm disc is 5.09 MPa.
  EXPECT_NEAR(BrazilianTensileStrength(10e3, 0.05, 0.025), 2 * 10e3 / (M_PI * 0.05 * 0.025), 1e-6);
  EXPECT_NEAR(BrazilianTensileStrength(10e3, 0.05, 0.025) / 1e6, 5.093, 1e-3);
  EXPECT_THROW(BrazilianTensileStrength(1.0, 0.0, 0.01), std::invalid_argument);
}

TEST(LabTests, BrazilianPeakLoad) {
  const LoadCurve c = MakeCurve(10e9, 0.0, 1e-3, 0.05, 1e-3);
  const BrazilianResult r = AnalyseBrazilian(c, 0.05, 0.025);
  EXPECT_NEAR(r.peak_force, 10e9 * 0.775e-3 * 1e-3, 1e-3 * r.peak_force);
  EXPECT_DOUBLE_EQ(r.tensile_strength, BrazilianTensileStrength(r.peak_force, 0.05, 0.025));
  EXPECT_DOUBLE_EQ(r.displacement_at_peak, c.displacement[r.peak_index]);
}

TEST(LabTests, ReadsTheDeckCurveFormatAndNamesABadLine) {
  char name[] = "/tmp/lab_curve_XXXXXX";
  const int fd = mkstemp(name);
  ASSERT_GE(fd, 0);
  close(fd);
  {
    std::ofstream o(name);
    o << "# step time displacement_m force_top_N force_bottom_N lateral_strain bonds broken\n"
      << "0 0 0 0 0 0 100 0\n50 1e-6 2e-7 10 12 1e-8 100 0\n";
  }
  const LoadCurve c = ReadLoadCurve(name);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_DOUBLE_EQ(c.force(1), 11.0);
  EXPECT_DOUBLE_EQ(c.displacement[1], 2e-7);
  {
    std::ofstream o(name, std::ios::app);
    o << "100 2e-6 oops\n";
  }
  try {
    ReadLoadCurve(name);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":4:"), std::string::npos) << e.what();
  }
  std::remove(name);
}

TEST(LabTests, FitLineRecoversALine) {
  const std::vector<double> x = {0, 1, 2, 3, 4}, y = {1, 3, 5, 7, 9};
  const LinearFit f = FitLine(x, y, 1, 4);
  EXPECT_DOUBLE_EQ(f.slope, 2.0);
  EXPECT_DOUBLE_EQ(f.intercept, 1.0);
  EXPECT_DOUBLE_EQ(f.r2, 1.0);
}

// Power-law response y = a x^b: the first (default-slope) step lands at
// (target/y)^(1/s0) x, the secant then finds b exactly and lands on target.
TEST(LabTests, SecantStepConvergesOnAPowerLaw) {
  const double a = 3e-3, b = 0.8, target = 50e6;
  auto y = [&](double x) { return a * std::pow(x, b); };
  const SecantRule rule{true, 1.0, 0.2, 3.0, std::log(10.0)};
  SecantPoint now{1e12, y(1e12)};
  std::optional<SecantPoint> prev;
  int it = 0;
  for (; it < 10 && RelativeError(now.y, target) > 1e-9; ++it) {
    const SecantStep st = SecantUpdate(rule, now, prev, target);
    if (it > 0) {
      EXPECT_TRUE(st.used_secant);
      EXPECT_NEAR(st.slope, b, 1e-9);
    }
    prev = now;
    now = {st.x_new, y(st.x_new)};
  }
  EXPECT_LE(it, 3);
  EXPECT_NEAR(now.x, std::pow(target / a, 1 / b), 1e-6 * now.x);
}

// A response linear in ln x (Poisson's ratio against kn/ks), with the step cap.
TEST(LabTests, SecantStepOnALogLinearResponseRespectsTheCap) {
  auto nu = [](double r) { return 0.1 + 0.07 * std::log(r); };
  const SecantRule rule{false, 0.1, 0.02, 0.5, 0.7};
  // Far target: the step is capped at e^0.7.
  SecantStep st = SecantUpdate(rule, {1.0, nu(1.0)}, std::nullopt, 0.4);
  EXPECT_NEAR(st.x_new, std::exp(0.7), 1e-12);
  EXPECT_FALSE(st.used_secant);
  // Near target: the secant through the two points finds the slope and lands on it.
  const SecantPoint prev{1.0, nu(1.0)}, now{st.x_new, nu(st.x_new)};
  st = SecantUpdate(rule, now, prev, 0.18);
  EXPECT_TRUE(st.used_secant);
  EXPECT_NEAR(st.slope, 0.07, 1e-9);
  EXPECT_NEAR(nu(st.x_new), 0.18, 1e-9);
}

// Noise that would reverse the secant slope is clamped: the step still goes
// the right way.
TEST(LabTests, SecantSlopeIsClampedAgainstNoise) {
  const SecantRule rule{true, 1.0, 0.3, 2.0, std::log(4.0)};
  // y fell although x rose: the raw slope is negative.
  const SecantStep st = SecantUpdate(rule, {2.0, 0.9}, SecantPoint{1.0, 1.0}, 1.8);
  EXPECT_TRUE(st.used_secant);
  EXPECT_DOUBLE_EQ(st.slope, 0.3);
  EXPECT_GT(st.x_new, 2.0);
  EXPECT_LE(st.x_new, 8.0 + 1e-12);
  EXPECT_THROW(SecantUpdate(rule, {0.0, 1.0}, std::nullopt, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace mill::post
