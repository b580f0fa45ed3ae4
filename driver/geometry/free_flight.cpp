// The free flight of a lump before it can touch the mill (free_flight.h).
#include "geometry/free_flight.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "postprocess/closest_point.h"

namespace mill::geometry {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 axpy(const Vec3& a, double s, const Vec3& d) {
  return {a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

double distance_to(const Vec3& p, const Surface& s) {
  double d = std::numeric_limits<double>::infinity();
  for (const Triangle& t : s) d = std::min(d, point_triangle_distance(p, t));
  return d;
}

}  // namespace

double point_triangle_distance(const Vec3& p, const Triangle& t) {
  Vec3 q;
  post::closest_on_triangle(p.data(), t.a.data(), t.b.data(), t.c.data(), q.data());
  return norm(sub(p, q));
}

FreeFlight free_flight_time(const Surface& housing, const Surface& flywheel,
                            const FreeFlightQuery& q) {
  if (!(q.clearance > 0) || !(q.horizon >= 0) || !(q.radius >= 0))
    throw std::invalid_argument(
        "free_flight_time: expected clearance > 0, horizon >= 0 and radius >= 0");
  // The fastest the gap can close: the lump's top speed over the horizon
  // plus the speed of the flywheel's outermost point.
  double r_fly = 0;
  for (const Triangle& t : flywheel)
    for (const Vec3* v : {&t.a, &t.b, &t.c})
      r_fly = std::max(r_fly, std::hypot((*v)[0] - q.axis_origin[0], (*v)[1] - q.axis_origin[1]));
  const double v_close = norm(q.v0) + norm(q.gravity) * q.horizon + std::fabs(q.omega) * r_fly;
  const double step = v_close > 0 ? 0.5 * q.clearance / v_close : q.horizon;

  const auto gap = [&](double t) {
    const Vec3 c = axpy(axpy(q.x0, t, q.v0), 0.5 * t * t, q.gravity);
    // The flywheel at t is the start's turned by omega t about the axis: the
    // centre turned back by omega t against the start's facets.
    const double a = -q.omega * t, ca = std::cos(a), sa = std::sin(a);
    const Vec3 r = sub(c, q.axis_origin);
    const Vec3 back = {q.axis_origin[0] + ca * r[0] - sa * r[1],
                       q.axis_origin[1] + sa * r[0] + ca * r[1], c[2]};
    return std::min(distance_to(c, housing), distance_to(back, flywheel)) - q.radius;
  };

  FreeFlight f;
  f.gap_at_time = gap(0.0);
  if (f.gap_at_time < q.clearance) return f;
  for (long k = 1;; ++k) {
    const double t = std::min(static_cast<double>(k) * step, q.horizon);
    const double g = gap(t);
    if (g < q.clearance) return f;
    f.time = t;
    f.gap_at_time = g;
    if (t >= q.horizon) {
      f.reaches_horizon = true;
      return f;
    }
  }
}

}  // namespace mill::geometry
