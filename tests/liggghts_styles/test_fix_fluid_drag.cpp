// Tests of fix fluid/drag: the drag-coefficient function, and real
// liggghts-mill runs compared with analytic solutions. Each test states its
// tolerance next to the assertion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "deck_runner.h"
#include "fix_fluid_drag.h"
#include "postprocess/flow_field_io.h"

using namespace mill_test;
using LAMMPS_NS::FixFluidDrag;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMu = 1.8e-5;   // air viscosity [Pa s]
constexpr double kRhoGas = 1.2;  // air density [kg/m3]
constexpr double kG = 9.81;      // gravity [m/s2]

// Rows "t v" of a fix print file.
std::vector<std::vector<double>> run_and_read(const std::string &dir, const std::string &deck,
                                              const std::string &table) {
  const auto r = run_deck(dir, deck);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  return read_table(dir + "/" + table);
}

}  // namespace

// Schiller & Naumann below Re = 1000, 0.424 above; the two branches meet at
// Re = 1000 (24/1000 (1 + 100/6) = 0.424): continuous value, a kink in slope.
TEST(DragCoefficient, SchillerNaumannAndNewtonBranches) {
  EXPECT_NEAR(FixFluidDrag::drag_coefficient(1.0), 24.0 * (1.0 + 1.0 / 6.0), 1e-12);
  EXPECT_NEAR(FixFluidDrag::drag_coefficient(8.0), 3.0 * (1.0 + 4.0 / 6.0), 1e-12);
  EXPECT_NEAR(FixFluidDrag::drag_coefficient(1000.0), 0.424, 1e-12);
  EXPECT_DOUBLE_EQ(FixFluidDrag::drag_coefficient(1000.0001), 0.424);
  EXPECT_DOUBLE_EQ(FixFluidDrag::drag_coefficient(1e6), 0.424);
  // Continuity at the switch: the jump is below 1e-7 (relative).
  const double below = FixFluidDrag::drag_coefficient(1000.0 - 1e-6);
  const double above = FixFluidDrag::drag_coefficient(1000.0 + 1e-6);
  std::printf("C_d at Re = 1000 -/+ 1e-6: %.10f / %.10f\n", below, above);
  EXPECT_NEAR(below / above, 1.0, 1e-7);
  // C_d Re stays finite in the Stokes limit and equals C_d * Re elsewhere.
  EXPECT_NEAR(FixFluidDrag::drag_coefficient_times_re(0.0), 24.0, 1e-12);
  for (double re : {1e-3, 0.5, 10.0, 999.0, 1001.0, 1e5})
    EXPECT_NEAR(FixFluidDrag::drag_coefficient_times_re(re) / re,
                FixFluidDrag::drag_coefficient(re), 1e-12 * FixFluidDrag::drag_coefficient(re));
}

// A 40 mm sandstone sphere falling in still air reaches the Newton-regime
// terminal velocity v_t = sqrt(4 g d (rho_s - rho) / (3 C_d rho)), C_d = 0.424.
// Tolerance: 1 %.
TEST(FluidDrag, TerminalVelocityNewtonRegime) {
  const double d = 0.04, rho_s = 2580.0;
  const double vt = std::sqrt(4.0 * kG * d * (rho_s - kRhoGas) / (3.0 * 0.424 * kRhoGas));
  const double tau = vt / (kG * (1.0 - kRhoGas / rho_s));  // v = vt tanh(t / tau)
  const std::string dir = make_run_dir("terminal");
  std::ostringstream s;
  s.precision(17);
  s << deck_head(0.5, 5e9, "p p p") << "create_atoms 1 single 0 0 0 units box\n"
    << "set group all diameter " << d << " density " << rho_s << "\n"
    << "fix integr all nve/sphere\n"
    << "fix grav all gravity " << kG << " vector 0 -1 0\n"
    << "fix drag all fluid/drag viscosity " << kMu << " uniform 0 0 0 " << kRhoGas << " buoyancy 0 "
    << -kG << " 0\n"
    << "timestep 2e-3\n"
    << "variable t equal time\nvariable vy equal vy[1]\nvariable re equal f_drag[4]\n"
    << "fix pr all print 250 \"${t} ${vy} ${re}\" file v.txt screen no title none\n"
    << "thermo 10000\nrun " << static_cast<int>(8.0 * tau / 2e-3) << "\n";
  const auto rows = run_and_read(dir, s.str(), "v.txt");
  ASSERT_FALSE(rows.empty());
  const double measured = -rows.back()[1];
  std::printf(
      "terminal velocity: measured %.5f m/s, analytic %.5f m/s (Re %.3g), rel. error %.2e (tol "
      "1e-2)\n",
      measured, vt, rows.back()[2], std::fabs(measured / vt - 1.0));
  EXPECT_GT(rows.back()[2], 1000.0);
  EXPECT_NEAR(measured / vt, 1.0, 0.01);
}

// A 10 um sphere at rest in a uniform 1 mm/s air stream (Re < 7e-4, the
// Schiller-Naumann correction below 0.14 %) relaxes as u (1 - exp(-t/tau)),
// tau = rho_s d^2 / (18 mu) (Stokes). Fitted tau: tolerance 2 %.
TEST(FluidDrag, StokesRelaxationTime) {
  const double d = 1e-5, rho_s = 1000.0, u = 1e-3;
  const double tau = rho_s * d * d / (18.0 * kMu);
  const double dt = tau / 500.0;
  const std::string dir = make_run_dir("stokes");
  std::ostringstream s;
  s.precision(17);
  s << deck_head(0.001, 5e9, "p p p") << "create_atoms 1 single 0 0 0 units box\n"
    << "set group all diameter " << d << " density " << rho_s << "\n"
    << "fix integr all nve/sphere\n"
    << "fix drag all fluid/drag viscosity " << kMu << " uniform " << u << " 0 0 " << kRhoGas << "\n"
    << "timestep " << dt << "\n"
    << "variable t equal time\nvariable vx equal vx[1]\n"
    << "fix pr all print 10 \"${t} ${vx}\" file v.txt screen no title none\n"
    << "thermo 1000\nrun 2500\n";
  const auto rows = run_and_read(dir, s.str(), "v.txt");
  // Least-squares slope of ln(1 - v/u) over t in [0.2 tau, 3 tau].
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto &r : rows) {
    if (r[0] < 0.2 * tau || r[0] > 3.0 * tau) continue;
    const double y = std::log(1.0 - r[1] / u);
    sx += r[0];
    sy += y;
    sxx += r[0] * r[0];
    sxy += r[0] * y;
    ++n;
  }
  ASSERT_GT(n, 50);
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  const double measured = -1.0 / slope;
  std::printf(
      "Stokes relaxation time: measured %.6e s, analytic %.6e s, rel. error %.2e (tol 2e-2)\n",
      measured, tau, std::fabs(measured / tau - 1.0));
  EXPECT_NEAR(measured / tau, 1.0, 0.02);
}

// Drag from a field file: a particle in the gas is dragged, one in a masked
// region is not, and one warning counts the masked particle-steps.
TEST(FluidDrag, FieldFileAndMaskedPoints) {
  const std::string dir = make_run_dir("field");
  mill::post::FlowField f;
  f.dims = {5, 5, 5};
  f.origin = {-0.5, -0.5, -0.5};
  f.spacing = {0.25, 0.25, 0.25};
  f.allocate(false);
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) {
        const size_t p = f.point(i, j, k);
        f.mask[p] = i < 3 ? 1 : 0;  // gas for x <= 0
        f.U[3 * p] = f.mask[p] ? 2.0 : 0.0;
        f.rho[p] = f.mask[p] ? kRhoGas : 0.0;
      }
  f.source = "test";
  mill::post::write_flow_field(dir + "/field.h5", f);
  std::ostringstream s;
  s.precision(17);
  s << deck_head(0.6) << "atom_modify sort 0 0.0\nneighbor 0.05 bin\n"
    << "create_atoms 1 single -0.3 0 0 units box\n"
    << "create_atoms 1 single 0.4 0 0 units box\n"
    << "set group all diameter 0.001 density 1000\n"
    << "fix integr all nve/sphere\n"
    << "fix drag all fluid/drag viscosity " << kMu << " field field.h5\n"
    << "timestep 1e-4\n"
    << "variable v1 equal vx[1]\nvariable v2 equal vx[2]\nvariable nm equal f_drag[2]\n"
    << "thermo 500\nrun 1000\n"
    << "print \"result ${v1} ${v2} ${nm}\"\n";
  const auto r = run_deck(dir, s.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto pos = r.screen.find("result ");
  ASSERT_NE(pos, std::string::npos) << r.screen;
  double v1 = 0, v2 = 0, nm = 0;
  std::istringstream(r.screen.substr(pos + 7)) >> v1 >> v2 >> nm;
  EXPECT_GT(v1, 0.1);    // dragged towards 2 m/s
  EXPECT_EQ(v2, 0.0);    // masked: no drag
  EXPECT_GE(nm, 100.0);  // one masked particle every step
  EXPECT_NE(r.screen.find("felt no drag"), std::string::npos) << r.screen;
}

// A user error names the keyword.
TEST(FluidDrag, MissingViscosityIsNamed) {
  const std::string dir = make_run_dir("dragerr");
  const auto r =
      run_deck(dir, deck_head(0.1) + "fix drag all fluid/drag uniform 0 0 0 1.2\nrun 0\n");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.screen.find("'viscosity'"), std::string::npos) << r.screen;
}

const char *kOneParticle =
    "atom_modify sort 0 0.0\nneighbor 0.05 bin\ncreate_atoms 1 single 0 0 0 units box\n"
    "set group all diameter 0.001 density 1000\n"
    "fix integr all nve/sphere\n";

// The field's rotor speed must be the deck's: `omega` (rad/s) is checked
// against the rpm stored in the field file (relative tolerance 1e-4).
TEST(FluidDrag, FieldRotorSpeedMustMatchDeckOmega) {
  const std::string dir = make_run_dir("dragomega");
  mill::post::FlowField f;
  f.dims = {3, 3, 3};
  f.origin = {-0.5, -0.5, -0.5};
  f.spacing = {0.5, 0.5, 0.5};
  f.allocate(false);
  for (size_t p = 0; p < f.size(); ++p) {
    f.mask[p] = 1;
    f.rho[p] = kRhoGas;
  }
  f.rpm = 2000.0;
  f.source = "test";
  mill::post::write_flow_field(dir + "/field.h5", f);
  auto deck = [&](const std::string &omega) {
    return deck_head(0.6) + kOneParticle +
           "fix drag all fluid/drag viscosity 1.8e-5 field field.h5 omega " +
           omega + "\nrun 0\n";
  };
  const auto ok = run_deck(dir, deck("209.44"));  // 2000 rpm = 209.4395 rad/s
  EXPECT_EQ(ok.exit_code, 0) << ok.screen;
  const auto bad = run_deck(dir, deck("157.08"));  // 1500 rpm
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.screen.find("sampled at 2000 rpm"), std::string::npos) << bad.screen;
  EXPECT_NE(bad.screen.find("deck's omega is 157.08 rad/s"), std::string::npos) << bad.screen;
  const auto uni = run_deck(dir, deck_head(0.6) + kOneParticle +
                                     "fix drag all fluid/drag viscosity 1.8e-5 uniform 0 0 0 1.2 "
                                     "omega 10\nrun 0\n");
  EXPECT_NE(uni.exit_code, 0);
  EXPECT_NE(uni.screen.find("'omega'"), std::string::npos) << uni.screen;
}
