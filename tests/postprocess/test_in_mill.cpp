// Start states of in-mill breakage and the records of a run.
#include "postprocess/in_mill.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

namespace mill::post {
namespace {

ImpactRecord strike(long long id, double t, const std::string& surface, double vn) {
  ImpactRecord r;
  r.particle_id = id;
  r.time_s = t;
  r.surface = surface;
  r.normal_speed_m_s = vn;
  r.speed_m_s = vn;
  r.angle_deg = 90;
  r.position = {0.52, 1.2, 0.0};
  r.contact = {0.5, 1.2, 0.0};
  r.relative_velocity = {-vn, 0, 0};
  return r;
}

RotorMotion rotor(double omega) {
  RotorMotion m;
  m.omega_rad_s = omega;
  m.origin = {0.0, 1.2, 0.0};
  return m;
}

TEST(SelectStrikeStarts, FirstFlywheelStrikeOfEachLump) {
  // Lump 1 strikes twice: its earlier strike counts; housing contacts and a
  // resting touch do not.
  const std::vector<ImpactRecord> recs = {
      strike(1, 0.30, "flywheel", 40), strike(1, 0.10, "flywheel", 20),
      strike(2, 0.05, "housing", 30), strike(2, 0.20, "flywheel", 0.1)};
  const auto s = SelectStrikeStarts(recs, 5, 0.0, rotor(0.0));
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].particle_id, 1);
  EXPECT_DOUBLE_EQ(s[0].strike_time_s, 0.10);
  EXPECT_DOUBLE_EQ(s[0].strike_normal_speed_m_s, 20);
}

TEST(SelectStrikeStarts, LabVelocityAddsTheBeaterAndBacksOffBallistically) {
  // Contact at r = 0.5 m on +x, omega 200 rad/s: the beater moves at +100 m/s
  // along y there; relative velocity (-20, 0, 0) -> lab (-20, 100, 0).
  const double w = 200, lead = 2e-3, g = 9.81;
  const auto s = SelectStrikeStarts({strike(7, 0.0125, "flywheel", 20)}, 1, lead, rotor(w));
  ASSERT_EQ(s.size(), 1u);
  EXPECT_NEAR(s[0].velocity[0], -20, 1e-12);
  EXPECT_NEAR(s[0].velocity[1], 100 + g * lead, 1e-12);
  EXPECT_NEAR(s[0].position[0], 0.52 + 20 * lead, 1e-12);
  EXPECT_NEAR(s[0].position[1], 1.2 - 100 * lead - 0.5 * g * lead * lead, 1e-12);
  EXPECT_NEAR(s[0].start_time_s, 0.0125 - lead, 1e-15);
  // Flung forward from the start state, it reaches the strike point.
  const double x = s[0].position[0] + s[0].velocity[0] * lead;
  const double y = s[0].position[1] + s[0].velocity[1] * lead - 0.5 * g * lead * lead;
  EXPECT_NEAR(x, 0.52, 1e-12);
  EXPECT_NEAR(y, 1.2, 1e-12);
  // The flywheel angle at the start, in [0, 2 pi).
  EXPECT_NEAR(s[0].rotor_angle_rad, std::fmod(w * (0.0125 - lead), 2 * kPi), 1e-12);
}

TEST(SelectStrikeStarts, SpreadsTheChoiceOverStrikeSpeeds) {
  std::vector<ImpactRecord> recs;
  for (int i = 0; i < 10; ++i) recs.push_back(strike(i + 1, 0.1 + i * 0.01, "flywheel", 10.0 + i));
  const auto s = SelectStrikeStarts(recs, 2, 1e-3, rotor(100));
  ASSERT_EQ(s.size(), 2u);
  // Quantiles 1/4 and 3/4 of ten: the 3rd and 8th slowest.
  EXPECT_EQ(s[0].particle_id, 3);
  EXPECT_EQ(s[1].particle_id, 8);
  EXPECT_EQ(SelectStrikeStarts(recs, 50, 1e-3, rotor(100)).size(), 10u);
}

TEST(SelectStrikeStarts, ErrorsSayWhatIsMissing) {
  EXPECT_THROW(SelectStrikeStarts({strike(1, 0.1, "housing", 20)}, 1, 1e-3, rotor(100)), PostError);
  ImpactRecord old = strike(1, 0.1, "flywheel", 20);
  old.contact = {0, 0, 0};
  old.relative_velocity = {0, 0, 0};
  try {
    SelectStrikeStarts({old}, 1, 1e-3, rotor(100));
    FAIL() << "no error";
  } catch (const PostError& e) {
    EXPECT_NE(std::string(e.what()).find("rerun the transport stage"), std::string::npos)
        << e.what();
  }
}

TEST(SplitBreaks, StrikeUntilTheFirstHousingContact) {
  const std::vector<ImpactRecord> contacts = {strike(5, 0.002, "flywheel", 30),
                                              strike(9, 0.006, "housing", 50),
                                              strike(5, 0.008, "flywheel", 10)};
  const std::vector<BreakEvent> breaks = {
      {0.0021, 1, 2}, {0.004, 2, 3}, {0.0065, 3, 4}, {0.01, 4, 5}};
  const auto s = SplitBreaks(breaks, contacts);
  EXPECT_EQ(s.at_strike, 2);
  EXPECT_EQ(s.later, 2);
  EXPECT_DOUBLE_EQ(s.first_flywheel_contact_s, 0.002);
  EXPECT_DOUBLE_EQ(s.first_housing_contact_s, 0.006);
}

TEST(SplitBreaks, NoBeaterContactNothingAtTheStrike) {
  const auto s = SplitBreaks({{0.01, 1, 2}, {0.02, 2, 3}}, {strike(1, 0.005, "housing", 40)});
  EXPECT_EQ(s.at_strike, 0);
  EXPECT_EQ(s.later, 2);
  EXPECT_LT(s.first_flywheel_contact_s, 0);
}

TEST(ReadBreakLog, ReadsEventsAndNamesBadLines) {
  const std::string f = testing::TempDir() + "/breaks.txt";
  std::ofstream(f) << "# fix bond/breakable break events\n# columns: ...\n"
                   << "10 1e-06 0 0 0 tension 3 7 5e6 0\n12 1.2e-06 0 0 0 shear 4 9 1e6 2e7\n";
  const auto b = ReadBreakLog(f);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].i, 4);
  EXPECT_EQ(b[1].j, 9);
  EXPECT_DOUBLE_EQ(b[0].time_s, 1e-6);
  std::ofstream(f) << "10 oops\n";
  try {
    ReadBreakLog(f);
    FAIL() << "no error";
  } catch (const PostError& e) {
    EXPECT_NE(std::string(e.what()).find("breaks.txt:1"), std::string::npos) << e.what();
  }
  std::remove(f.c_str());
}

TEST(TallyContacts, CountsOnsetsAndElements) {
  const auto t = TallyContacts({strike(1, 0.1, "housing", 10), strike(1, 0.2, "housing", 30),
                                strike(2, 0.1, "housing", 20), strike(3, 0.1, "flywheel", 90)},
                               "housing");
  EXPECT_EQ(t.n, 3);
  EXPECT_EQ(t.n_elements, 2);
  EXPECT_DOUBLE_EQ(t.normal_speed_mean_m_s, 20);
  EXPECT_DOUBLE_EQ(t.normal_speed_max_m_s, 30);
}

TEST(LocateMass, SharesOfTheMassByPlace) {
  MillRegions g;
  g.axis_y = 1.2;
  g.tip_radius = 0.5;
  g.half_width_z = 0.15;
  g.floor_y = 0;
  g.roof_y = 4;
  auto el = [](double x, double y, double z, double m) {
    Element e;
    e.x = {x, y, z};
    e.mass = m;
    return e;
  };
  const auto m = LocateMass({el(0.2, 1.2, 0, 1), el(0.7, 1.2, 0, 1), el(0.2, 1.2, 0.2, 1),
                             el(0, -0.1, 0, 0.5), el(0, 4.1, 0, 0.5)},
                            g);
  EXPECT_DOUBLE_EQ(m.rotor, 0.25);
  EXPECT_DOUBLE_EQ(m.housing, 0.5);
  EXPECT_DOUBLE_EQ(m.outlet, 0.125);
  EXPECT_DOUBLE_EQ(m.inlet, 0.125);
}

}  // namespace
}  // namespace mill::post
