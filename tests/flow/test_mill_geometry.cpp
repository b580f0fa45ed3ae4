// The mill surfaces: closed where they should be, normals into the gas,
// volumes as built, and fit errors that name the key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <map>

#include "geometry/mill_geometry.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill::geometry;

namespace {

// Edge use count: each directed edge of a closed, consistently oriented
// surface appears once, and its reverse once.
bool closed_and_oriented(const Surface& s) {
  std::map<std::pair<Vec3, Vec3>, int> edges;
  for (const auto& t : s)
    for (auto [a, b] : {std::pair{t.a, t.b}, std::pair{t.b, t.c}, std::pair{t.c, t.a}})
      edges[{a, b}]++;
  for (const auto& [e, n] : edges)
    if (n != 1 || edges.count({e.second, e.first}) != 1) return false;
  return true;
}

Vec3 normal(const Triangle& t) {
  const Vec3 u{t.b[0] - t.a[0], t.b[1] - t.a[1], t.b[2] - t.a[2]},
      v{t.c[0] - t.a[0], t.c[1] - t.a[1], t.c[2] - t.a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

}  // namespace

TEST(MillGeometry, FlywheelIsClosedWithOutwardNormalsAndRightVolume) {
  MillGeometry g;
  const auto s = flywheel_surface(g);
  EXPECT_TRUE(closed_and_oriented(s));
  const double v = signed_volume(s);
  EXPECT_GT(v, 0) << "outward normals give a positive volume";
  EXPECT_NEAR(v, flywheel_volume(g), 2e-3 * flywheel_volume(g));  // hub polygon vs circle
}

TEST(MillGeometry, HousingNormalsPointIntoTheHousing) {
  MillGeometry g;
  const auto s = housing_surface(g);
  const double box = g.width * g.height * g.depth;
  const double holes = g.inlet_size * g.inlet_size + g.outlet_size * g.outlet_size;
  const double walls = 2 * (g.width * g.height + g.width * g.depth + g.height * g.depth);
  EXPECT_NEAR(area(s), walls - holes, 1e-9);
  for (const auto& t : s) {
    const Vec3 n = normal(t);
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const Vec3 c{(t.a[0] + t.b[0] + t.c[0]) / 3 + 1e-3 * n[0] / len,
                 (t.a[1] + t.b[1] + t.c[1]) / 3 + 1e-3 * n[1] / len,
                 (t.a[2] + t.b[2] + t.c[2]) / 3 + 1e-3 * n[2] / len};
    EXPECT_TRUE(std::abs(c[0]) < 0.5 * g.width && c[1] > 0 && c[1] < g.height &&
                std::abs(c[2]) < 0.5 * g.depth);
  }
  (void)box;
}

TEST(MillGeometry, OpeningsPointIntoTheHousing) {
  MillGeometry g;
  const auto in = inlet_surface(g), out = outlet_surface(g);
  for (const auto& t : in) EXPECT_LT(normal(t)[1], 0);
  for (const auto& t : out) EXPECT_GT(normal(t)[1], 0);
  EXPECT_NEAR(area(in), g.inlet_size * g.inlet_size, 1e-12);
  EXPECT_NEAR(area(out), g.outlet_size * g.outlet_size, 1e-12);
}

TEST(MillGeometry, StlRoundTripOneSolidPerFile) {
  MillGeometry g;
  const mill::test::TempPath d("mill_geom_" + std::to_string(getpid()));
  const auto set = write_stl_set(g, d);
  for (const auto& [f, name] : {std::pair{set.housing, "housing"},
                                {set.flywheel, "flywheel"},
                                {set.inlet, "inlet"},
                                {set.outlet, "outlet"}}) {
    ASSERT_TRUE(fs::exists(f));
    std::ifstream in(f);
    std::string first;
    std::getline(in, first);
    EXPECT_EQ(first, std::string("solid ") + name);
  }
  const auto back = read_stl(set.flywheel);
  EXPECT_EQ(back.size(), flywheel_surface(g).size());
  EXPECT_NEAR(signed_volume(back), signed_volume(flywheel_surface(g)), 1e-6);
}

TEST(MillGeometry, FitErrorsNameTheKey) {
  MillGeometry g;
  g.plate_thickness = 0.2;  // six 0.2 m plates on a 0.3 m hub
  try {
    g.validate();
    FAIL() << "expected a fit error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mill.flywheel.plate_thickness"), std::string::npos)
        << e.what();
  }
  MillGeometry h;
  h.inlet_x = 0.75;
  try {
    h.validate();
    FAIL() << "expected a fit error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mill.inlet.center_x"), std::string::npos) << e.what();
  }
}

// rotor_angle turns the whole flywheel rigidly about the rotor axis: each
// vertex is the angle-0 vertex rotated by the angle (1e-12 m), the surface
// stays closed and its volume is the same (1e-12 relative).
TEST(MillGeometry, RotorAngleTurnsTheFlywheelRigidly) {
  MillGeometry g;
  const auto s0 = flywheel_surface(g);
  g.rotor_angle = 0.37;
  const auto s1 = flywheel_surface(g);
  ASSERT_EQ(s0.size(), s1.size());
  EXPECT_TRUE(closed_and_oriented(s1));
  EXPECT_NEAR(signed_volume(s1), signed_volume(s0), 1e-12 * signed_volume(s0));
  const double c = std::cos(0.37), sn = std::sin(0.37);
  auto turn = [&](const Vec3& p) {
    const double dx = p[0] - g.axis_x, dy = p[1] - g.axis_height;
    return Vec3{g.axis_x + c * dx - sn * dy, g.axis_height + sn * dx + c * dy, p[2]};
  };
  for (size_t k = 0; k < s0.size(); ++k)
    for (auto [p, q] : {std::pair{s0[k].a, s1[k].a}, std::pair{s0[k].b, s1[k].b},
                        std::pair{s0[k].c, s1[k].c}}) {
      const Vec3 r = turn(p);
      for (int d = 0; d < 3; ++d) ASSERT_NEAR(r[d], q[d], 1e-12) << "triangle " << k;
    }
}
