// Virtual lab tests on hand-made data: stress and strain of a load curve with
// known E, nu and peak; the Brazilian formula; the triaxial curve and peak;
// the Mohr-Coulomb and Hoek-Brown envelopes of synthetic peaks; the
// semi-circular bend toughness; the calibration step on analytic response
// models.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

#include "postprocess/lab_tests.h"
#include "temp_dir.h"

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

// A specimen that fails and whose debris then carries more (the default
// case's parallel bond at a 60 deg bond friction angle, bench/README.md,
// "The UCS before the debris"): linear to 24 MPa at E = 20 GPa with nu 0.2,
// bonds breaking at the peak, a drop to 15 MPa (0.625 x), then a rise to
// 32 MPa. The UCS is the first peak, E and nu those of its loading branch;
// the same curve with no bond broken at the drop (a start-up dip), or a dip
// to 0.75 x only, keeps the whole curve's maximum.
TEST(LabTests, UcsIsThePeakBeforeTheSpecimenFails) {
  const double E = 20e9, nu = 0.2;
  StressStrain s;
  auto add = [&](double eps, double sigma, double lat, double broken) {
    s.strain.push_back(eps);
    s.stress.push_back(sigma);
    s.lateral_strain.push_back(lat);
    s.broken_bonds.push_back(broken);
  };
  for (int i = 0; i <= 120; ++i) {  // loading: 0 .. 24 MPa
    const double eps = 1.2e-3 * i / 120;
    add(eps, E * eps, nu * eps, 0);
  }
  add(1.25e-3, 15e6, 3e-3, 400);  // failure: bonds break, the load falls
  for (int i = 1; i <= 100; ++i)  // the debris compacted: up to 32 MPa
    add(1.25e-3 + 5e-5 * i, 15e6 + 0.17e6 * i, 3e-3 + 1e-3 * i, 400 + i);
  const UcsResult r = AnalyseUcs(s);
  EXPECT_EQ(r.failure_index, 121u);
  EXPECT_EQ(r.peak_index, 120u);
  EXPECT_NEAR(r.ucs, 24e6, 1e-3);
  EXPECT_NEAR(r.youngs_modulus / E, 1.0, 1e-9);
  EXPECT_NEAR(r.poisson_ratio, nu, 1e-9);
  // No bond broken at the drop: not a failure, the maximum of the curve.
  StressStrain dip = s;
  std::fill(dip.broken_bonds.begin(), dip.broken_bonds.end(), 0.0);
  const UcsResult d = AnalyseUcs(dip);
  EXPECT_EQ(d.failure_index, dip.stress.size());
  EXPECT_NEAR(d.ucs, 32e6, 1e-3);
  // A drop to 0.75 x: above kUcsFailureFraction, not a failure either.
  StressStrain shallow = s;
  for (size_t i = 121; i < shallow.stress.size(); ++i)
    shallow.stress[i] = std::max(shallow.stress[i], 0.75 * 24e6);
  EXPECT_NEAR(AnalyseUcs(shallow).ucs, 32e6, 1e-3);
  // Without broken-bond counts (a curve made by hand): the whole curve.
  StressStrain bare = s;
  bare.broken_bonds.clear();
  EXPECT_NEAR(AnalyseUcs(bare).ucs, 32e6, 1e-3);
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
  EXPECT_FALSE(r.no_split);  // the load falls to nothing after the peak, bonds breaking
}

// The Brazilian strength is the load at the split (kBrazilianSplitFraction):
// a disc of 1000 bonds loaded to 2 kN splits (the load falls to 1.2 kN, 300
// bonds break), then its halves are loaded up to 3 kN: T from 2 kN, to
// 1e-12. A disc whose load rises to the end while 45 % of its bonds break
// was crushed (no_split), and so was one with a dip to 0.75 x only. A drop
// without a broken bond is no split, and a disc that lost under
// kBrazilianCrushedLoss of its bonds is whole at the end: its largest load
// is kept (a lower bound), not flagged.
TEST(LabTests, BrazilianStrengthIsTheLoadAtTheSplit) {
  LoadCurve c;
  auto add = [&](double u, double F, double broken) {
    c.time.push_back(u);
    c.displacement.push_back(u);
    c.force_top.push_back(F);
    c.force_bottom.push_back(F);
    c.lateral_strain.push_back(0);
    c.intact_bonds.push_back(1000.0 - broken);
    c.broken_bonds.push_back(broken);
  };
  for (int i = 0; i <= 100; ++i) add(1e-7 * i, 20.0 * i, i / 2.0);                     // to 2 kN
  add(1.01e-5, 1200.0, 350);                                                           // the split
  for (int i = 1; i <= 100; ++i) add(1.01e-5 + 1e-7 * i, 1200.0 + 18.0 * i, 350 + i);  // to 3 kN
  const BrazilianResult r = AnalyseBrazilian(c, 0.05, 0.025);
  EXPECT_FALSE(r.no_split);
  EXPECT_EQ(r.split_index, 101u);
  EXPECT_EQ(r.peak_index, 100u);
  EXPECT_NEAR(r.peak_force, 2000.0, 1e-9);
  EXPECT_NEAR(r.tensile_strength / BrazilianTensileStrength(2000.0, 0.05, 0.025), 1.0, 1e-12);
  // The load rising to the end, bonds breaking all along: no split; the
  // largest load is reported, flagged.
  LoadCurve crushed = c;
  for (size_t i = 101; i < crushed.size(); ++i)
    crushed.force_top[i] = crushed.force_bottom[i] = 2000.0 + 10.0 * static_cast<double>(i - 100);
  const BrazilianResult k = AnalyseBrazilian(crushed, 0.05, 0.025);
  EXPECT_TRUE(k.no_split);
  EXPECT_EQ(k.split_index, crushed.size());
  EXPECT_EQ(k.peak_index, crushed.size() - 1);
  // A dip to 0.75 x (above the fraction): no split either.
  LoadCurve shallow = c;
  shallow.force_top[101] = shallow.force_bottom[101] = 1500.0;
  for (size_t i = 102; i < shallow.size(); ++i)
    shallow.force_top[i] = shallow.force_bottom[i] = std::max(shallow.force_top[i], 1500.0);
  EXPECT_TRUE(AnalyseBrazilian(shallow, 0.05, 0.025).no_split);
  // The drop without a broken bond (the jaws seating): no split, and no bond
  // lost: whole, the curve's largest load.
  LoadCurve seating = c;
  std::fill(seating.broken_bonds.begin(), seating.broken_bonds.end(), 0.0);
  std::fill(seating.intact_bonds.begin(), seating.intact_bonds.end(), 1000.0);
  const BrazilianResult w = AnalyseBrazilian(seating, 0.05, 0.025);
  EXPECT_FALSE(w.no_split);
  EXPECT_EQ(w.split_index, seating.size());
  EXPECT_NEAR(w.peak_force, 3000.0, 1e-9);
  // Rising to the end with 2 % of the bonds broken (a strong disc at its
  // cap): whole, its largest load kept.
  LoadCurve strong = crushed;
  for (size_t i = 0; i < strong.size(); ++i) {
    strong.broken_bonds[i] = std::min(strong.broken_bonds[i], 20.0);
    strong.intact_bonds[i] = 1000.0 - strong.broken_bonds[i];
  }
  const BrazilianResult g = AnalyseBrazilian(strong, 0.05, 0.025);
  EXPECT_FALSE(g.no_split);
  EXPECT_NEAR(g.bonds_lost, 0.02, 1e-12);
  EXPECT_EQ(g.peak_index, strong.size() - 1);
  EXPECT_NEAR(k.bonds_lost, 0.45, 1e-12);
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
  mill::test::remove_unless_failed(name, HasFailure());
}

// A triaxial curve file as the deck writes it: the confining force column is
// read, a line that lacks it is named.
TEST(LabTestsTriaxial, ReadsTheCurveFileWithTheConfiningForce) {
  char name[] = "/tmp/triax_curve_XXXXXX";
  const int fd = mkstemp(name);
  ASSERT_GE(fd, 0);
  close(fd);
  {
    std::ofstream o(name);
    o << "# step time displacement_m force_top_N force_bottom_N lateral_strain bonds broken "
         "confining_force_N\n"
      << "10800 8.0e-4 2.7e-08 1210.5 1207.7 1.3e-08 1081 0 7604.2\n"
      << "11040 8.2e-4 2.9e-07 1247.8 1247.2 1.7e-06 1081 2 7604.3\n";
  }
  const TriaxialCurve c = ReadTriaxialCurve(name);
  ASSERT_EQ(c.load.size(), 2u);
  ASSERT_EQ(c.confining_force.size(), 2u);
  EXPECT_DOUBLE_EQ(c.confining_force[1], 7604.3);
  EXPECT_DOUBLE_EQ(c.load.force(1), 1247.5);
  EXPECT_DOUBLE_EQ(c.load.broken_bonds[1], 2.0);
  EXPECT_DOUBLE_EQ(c.load.lateral_strain[1], 1.7e-06);
  // A UCS curve (8 columns) is not a triaxial curve.
  {
    std::ofstream o(name, std::ios::app);
    o << "11280 8.4e-4 5.5e-07 1290.0 1290.6 3.4e-06 1081 2\n";
  }
  try {
    ReadTriaxialCurve(name);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":4: expected 9 numbers"), std::string::npos) << e.what();
  }
  mill::test::remove_unless_failed(name, HasFailure());
}

// Peak of sigma_1 - sigma_3 of a hand-made curve: a confinement of 5 MPa on a
// lateral area A_lat, an axial stress that rises from 5 MPa to a peak of
// 30 MPa and falls.
TEST(LabTestsTriaxial, PeakOfTheDeviatoricStress) {
  const double A = 2.4e-4, A_lat = 1.5e-3, L = 0.03, p = 5e6;
  TriaxialCurve c;
  for (int i = 0; i <= 100; ++i) {
    const double eps = 2e-5 * i;
    const double dev = 25e6 * std::sin(M_PI * i / 120.0);  // peak at i = 60
    c.load.time.push_back(1e-5 * i);
    c.load.displacement.push_back(eps * L);
    c.load.force_top.push_back((p + dev) * A * 1.01);
    c.load.force_bottom.push_back((p + dev) * A * 0.99);
    c.load.lateral_strain.push_back(0.0);
    c.load.broken_bonds.push_back(3.0 + i);
    c.confining_force.push_back(p * A_lat);
  }
  const TriaxialResult r = AnalyseTriaxial(c, L, A, A_lat);
  EXPECT_EQ(r.peak_index, 60u);
  EXPECT_NEAR(r.sigma3, p, 1e-6);
  EXPECT_NEAR(r.deviator, 25e6, 1e-3);
  EXPECT_NEAR(r.sigma1, 30e6, 1e-3);
  EXPECT_NEAR(r.strain_at_peak, 60 * 2e-5, 1e-15);
  EXPECT_DOUBLE_EQ(r.broken_before_loading, 3.0);
  EXPECT_THROW(AnalyseTriaxial(c, L, A, 0.0), std::invalid_argument);
}

// Peaks on a known Mohr-Coulomb envelope (phi 35 deg, c 10 MPa): the fit
// gives phi and c back to round-off, from three points and from two.
TEST(LabTestsTriaxial, MohrCoulombFitRecoversFrictionAngleAndCohesion) {
  const double phi = 35.0 * M_PI / 180.0, c = 10e6;
  const double q = (1 + std::sin(phi)) / (1 - std::sin(phi));
  const double ucs = 2 * c * std::cos(phi) / (1 - std::sin(phi));
  std::vector<StrengthPoint> pts;
  for (double s3 : {0.0, 5e6, 20e6}) pts.push_back({s3, ucs + q * s3});
  for (size_t n : {size_t(3), size_t(2)}) {
    const MohrCoulomb mc = FitMohrCoulomb(std::vector<StrengthPoint>(pts.begin(), pts.begin() + n));
    EXPECT_NEAR(mc.friction_angle_deg, 35.0, 1e-9) << n << " points";
    EXPECT_NEAR(mc.cohesion / c, 1.0, 1e-12) << n << " points";
    EXPECT_NEAR(mc.ucs / ucs, 1.0, 1e-12);
    EXPECT_NEAR(mc.q, q, 1e-12);
    EXPECT_NEAR(mc.Sigma1(20e6), pts[2].sigma1, 1e-6);
  }
  // q = tan^2(45 deg + phi/2), the textbook form of the same slope.
  EXPECT_NEAR(q, std::pow(std::tan(M_PI / 4 + phi / 2), 2), 1e-12);
}

TEST(LabTestsTriaxial, MohrCoulombFitNeedsTwoConfinementsAndFriction) {
  EXPECT_THROW(FitMohrCoulomb({{5e6, 40e6}}), std::invalid_argument);
  EXPECT_THROW(FitMohrCoulomb({{5e6, 40e6}, {5e6, 41e6}}), std::invalid_argument);
  // Strength falls with confinement: no friction angle.
  EXPECT_THROW(FitMohrCoulomb({{0.0, 40e6}, {5e6, 42e6}}), std::runtime_error);
}

// Peaks on a known Hoek-Brown envelope of intact rock (sigma_ci 100 MPa,
// m_i 12): the regression gives both back, from four points and from two.
TEST(LabTestsTriaxial, HoekBrownFitRecoversMi) {
  const HoekBrown truth{100e6, 12.0};
  std::vector<StrengthPoint> pts;
  for (double s3 : {0.0, 5e6, 10e6, 20e6}) pts.push_back({s3, truth.Sigma1(s3)});
  EXPECT_NEAR(pts[0].sigma1, 100e6, 1e-6);  // sigma_1 = sigma_ci at sigma_3 = 0
  for (size_t n : {size_t(4), size_t(2)}) {
    const HoekBrown hb = FitHoekBrown(std::vector<StrengthPoint>(pts.begin(), pts.begin() + n));
    EXPECT_NEAR(hb.m_i, 12.0, 1e-9) << n << " points";
    EXPECT_NEAR(hb.sigma_ci / 100e6, 1.0, 1e-12) << n << " points";
  }
  // Without the unconfined point: two confined peaks fix both constants.
  const HoekBrown hb = FitHoekBrown({pts[2], pts[3]});
  EXPECT_NEAR(hb.m_i, 12.0, 1e-9);
  EXPECT_NEAR(hb.sigma_ci / 100e6, 1.0, 1e-12);
  EXPECT_THROW(FitHoekBrown({pts[1]}), std::invalid_argument);
}

// Y' of Kuruppu et al. (2014), eq. 2, at the corners and centre of the
// suggested geometry, against the polynomial evaluated by hand to 4 decimals
// (tolerance 5e-5).
TEST(LabTestsScb, GeometryFactorOfTheSuggestedGeometry) {
  EXPECT_NEAR(ScbGeometryFactor(0.5, 0.8), 6.6460, 5e-5);
  EXPECT_NEAR(ScbGeometryFactor(0.4, 0.5), 2.9050, 5e-5);
  EXPECT_NEAR(ScbGeometryFactor(0.6, 0.5), 4.8196, 5e-5);
  EXPECT_NEAR(ScbGeometryFactor(0.4, 0.8), 5.4362, 5e-5);
  EXPECT_NEAR(ScbGeometryFactor(0.6, 0.8), 8.4275, 5e-5);
  EXPECT_NEAR(ScbGeometryFactor(0.5, 0.6), 4.6684, 5e-5);
  // A longer notch or a wider span opens the crack more.
  EXPECT_GT(ScbGeometryFactor(0.55, 0.7), ScbGeometryFactor(0.45, 0.7));
  EXPECT_GT(ScbGeometryFactor(0.5, 0.75), ScbGeometryFactor(0.5, 0.65));
  EXPECT_THROW(ScbGeometryFactor(1.0, 0.8), std::invalid_argument);
  EXPECT_THROW(ScbGeometryFactor(0.5, 0.0), std::invalid_argument);
}

// K_IC = Y' P sqrt(pi a) / (2 R B): 1 kN on R 50 mm, B 40 mm, a 25 mm, s 40 mm
// (a/R 0.5, s/R 0.8) is 0.4656 MPa m^0.5; the peak of a curve gives the same.
TEST(LabTestsScb, ToughnessFromThePeakLoad) {
  const double R = 0.05, B = 0.04, a = 0.025, s = 0.04;
  const double k = ScbToughness(1000.0, R, B, a, s);
  EXPECT_NEAR(k, 6.6460 * 1000.0 * std::sqrt(M_PI * a) / (2 * R * B), 1e-3 * k);
  EXPECT_NEAR(k / 1e6, 0.4656, 1e-4);
  const LoadCurve c = MakeCurve(10e9, 0.0, 1e-3, 0.05, 1e-4);  // peak 775 N
  const ScbResult r = AnalyseScb(c, R, B, a, s);
  EXPECT_NEAR(r.peak_force, 775.0, 1.0);
  EXPECT_DOUBLE_EQ(r.toughness, ScbToughness(r.peak_force, R, B, a, s));
  EXPECT_DOUBLE_EQ(r.geometry_factor, ScbGeometryFactor(0.5, 0.8));
  EXPECT_THROW(ScbToughness(1000.0, R, 0.0, a, s), std::invalid_argument);
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
