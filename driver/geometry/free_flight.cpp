// The free flight of a lump before it can touch the mill (free_flight.h).
#include "geometry/free_flight.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

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
  // Barycentric tests of the Voronoi regions in turn: vertex a, vertex b,
  // edge ab, vertex c, edge ac, edge bc, else the face (Ericson 2005,
  // sec. 5.1.5).
  const Vec3 ab = sub(t.b, t.a), ac = sub(t.c, t.a);
  const Vec3 ap = sub(p, t.a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return norm(ap);
  const Vec3 bp = sub(p, t.b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return norm(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm(sub(p, axpy(t.a, d1 / (d1 - d3), ab)));
  const Vec3 cp = sub(p, t.c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return norm(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm(sub(p, axpy(t.a, d2 / (d2 - d6), ac)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return norm(sub(p, axpy(t.b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(t.c, t.b))));
  const double sum = va + vb + vc;
  if (!(sum > 0)) {  // a degenerate (zero-area) facet: its nearest vertex
    return std::min({norm(ap), norm(bp), norm(cp)});
  }
  const Vec3 q = axpy(axpy(t.a, vb / sum, ab), vc / sum, ac);
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
