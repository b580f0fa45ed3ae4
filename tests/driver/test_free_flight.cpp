// The lump's free flight before it can touch the mill (geometry/free_flight.h),
// against closed forms: point-triangle distances, a lump falling onto a floor,
// a turning plate sweeping onto a lump at rest.
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/free_flight.h"

namespace mill::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Each Voronoi region of the unit right triangle in z = 0: its distance by hand.
TEST(FreeFlight, PointTriangleDistanceInEveryRegion) {
  const Triangle t{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_NEAR(point_triangle_distance({0.2, 0.2, 3.0}, t), 3.0, 1e-14);             // face
  EXPECT_NEAR(point_triangle_distance({-1, -1, 0}, t), std::sqrt(2.0), 1e-14);      // vertex a
  EXPECT_NEAR(point_triangle_distance({2, 0, 1}, t), std::sqrt(2.0), 1e-14);        // vertex b
  EXPECT_NEAR(point_triangle_distance({0, 2, 0}, t), 1.0, 1e-14);                   // vertex c
  EXPECT_NEAR(point_triangle_distance({0.5, -2, 0}, t), 2.0, 1e-14);                // edge ab
  EXPECT_NEAR(point_triangle_distance({-3, 0.5, 0}, t), 3.0, 1e-14);                // edge ac
  EXPECT_NEAR(point_triangle_distance({1, 1, 0}, t), 1.0 / std::sqrt(2.0), 1e-14);  // edge bc
  EXPECT_NEAR(point_triangle_distance({1, 1, 2}, t), std::sqrt(0.5 + 4.0),
              1e-14);                                                    // edge bc, off plane
  EXPECT_NEAR(point_triangle_distance({0.25, 0.25, 0}, t), 0.0, 1e-14);  // on the face
}

Surface floor_at(double y) {
  return {{{-1, y, -1}, {1, y, -1}, {1, y, 1}}, {{-1, y, -1}, {1, y, 1}, {-1, y, 1}}};
}

// A lump falling onto a floor: its gap y(t) - R closes to the clearance at
// the root of y0 + v0 t - g t^2 / 2 - R = c. The free flight ends at most
// one grid step (clearance / 2 over the closing speed) before that.
TEST(FreeFlight, FallingLumpStopsAClearanceAboveTheFloor) {
  FreeFlightQuery q;
  q.x0 = {0, 1.0, 0};
  q.v0 = {0, -10.0, 0};
  q.gravity = {0, -9.81, 0};
  q.radius = 0.02;
  q.clearance = 0.01;
  q.horizon = 1.0;
  const FreeFlight f = free_flight_time(floor_at(0.0), {}, q);
  // 4.905 t^2 + 10 t - (1 - 0.03) = 0
  const double a = 4.905, b = 10.0, c = -(1.0 - q.radius - q.clearance);
  const double t_star = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  const double step = 0.5 * q.clearance / (10.0 + 9.81 * q.horizon);
  EXPECT_LE(f.time, t_star);
  EXPECT_GE(f.time, t_star - step - 1e-12);
  EXPECT_FALSE(f.reaches_horizon);
  const double y = 1.0 - 10.0 * f.time - 4.905 * f.time * f.time;
  EXPECT_NEAR(f.gap_at_time, y - q.radius, 1e-12);
  EXPECT_GE(f.gap_at_time, q.clearance);
}

// A thin plate from r = 0.1 to 0.5 m in the plane through the axis, turning
// at omega towards a lump at rest at radius 0.3 m and polar angle 60 deg: the
// gap 0.3 sin(60 deg - omega t) - R reaches the clearance at
// omega t* = 60 deg - asin((R + c) / 0.3).
TEST(FreeFlight, TurningPlateStopsTheFlightAtTheClosedFormAngle) {
  const Surface plate = {{{0.1, 0, -0.1}, {0.5, 0, -0.1}, {0.5, 0, 0.1}},
                         {{0.1, 0, -0.1}, {0.5, 0, 0.1}, {0.1, 0, 0.1}}};
  FreeFlightQuery q;
  const double phi = kPi / 3, r = 0.3;
  q.x0 = {r * std::cos(phi), r * std::sin(phi), 0};
  q.radius = 0.02;
  q.clearance = 0.01;
  q.horizon = 0.1;
  q.omega = 100.0;
  const FreeFlight f = free_flight_time({}, plate, q);
  const double t_star = (phi - std::asin((q.radius + q.clearance) / r)) / q.omega;
  const double step = 0.5 * q.clearance / (q.omega * 0.5);
  EXPECT_LE(f.time, t_star);
  EXPECT_GE(f.time, t_star - step - 1e-12);
  EXPECT_NEAR(f.gap_at_time, r * std::sin(phi - q.omega * f.time) - q.radius, 1e-12);
  // Turning the other way the plate moves off: free up to the horizon
  // (it comes round again after 2 pi - 60 deg, 50 ms at 100 rad/s; the
  // horizon is shorter).
  q.omega = -100.0;
  q.horizon = 0.03;
  const FreeFlight back = free_flight_time({}, plate, q);
  EXPECT_TRUE(back.reaches_horizon);
  EXPECT_DOUBLE_EQ(back.time, q.horizon);
}

// Within the clearance at the start: nothing is skipped.
TEST(FreeFlight, LumpNearASurfaceAtTheStartSkipsNothing) {
  FreeFlightQuery q;
  q.x0 = {0, 0.025, 0};
  q.v0 = {0, 5.0, 0};  // moving away, but already close
  q.radius = 0.02;
  q.clearance = 0.01;
  q.horizon = 1e-3;
  const FreeFlight f = free_flight_time(floor_at(0.0), {}, q);
  EXPECT_EQ(f.time, 0.0);
  EXPECT_NEAR(f.gap_at_time, 0.005, 1e-15);
  EXPECT_FALSE(f.reaches_horizon);
  q.clearance = 0;
  EXPECT_THROW(free_flight_time(floor_at(0.0), {}, q), std::invalid_argument);
}

}  // namespace
}  // namespace mill::geometry
