// The free flight of a lump before it can touch the mill: how long an
// in-mill run may skip (breakage.in_mill.skip_free_flight, docs/breakage.md
// "In-mill breakage").
//
// An in-mill run starts `lead_time` before the lump's strike in stage 1.
// Until an element touches a surface, every element of the lump has the same
// velocity and the same acceleration (gravity), so the lump moves as one rigid
// body and its bonds carry no load: that part of the run is the ballistic
// flight the start state was backed off along, and costs the bonded lump's
// full step (half of the reference in-mill run). free_flight_time() gives the
// time for which that flight is certain, from the lump's bounding sphere and
// the mill's surfaces (the flywheel turning).
#pragma once

#include "geometry/mill_geometry.h"

namespace mill::geometry {

// Distance from point p to the triangle (its closest point by the Voronoi
// regions of its vertices, edges and face: Ericson 2005, Real-Time Collision
// Detection, sec. 5.1.5; postprocess/closest_point.h, the impact recorder's).
double point_triangle_distance(const Vec3& p, const Triangle& t);

struct FreeFlightQuery {
  Vec3 x0{}, v0{};       // the lump's centre (m) and velocity (m/s) at the start
  Vec3 gravity{};        // m/s^2
  double radius = 0;     // the lump's bounding radius: centre to its outermost element surface, m
  double clearance = 0;  // the flight ends this far from a surface (m), > 0
  double horizon = 0;    // look no further ahead than this, s
  Vec3 axis_origin{};    // the flywheel turns about +z through this point ...
  double omega = 0;      // ... at this rate, rad/s (right-hand)
};

struct FreeFlight {
  double time = 0;               // s: the lump flies free over [0, time]
  double gap_at_time = 0;        // m: its bounding sphere's gap to the nearest surface then
  bool reaches_horizon = false;  // no surface within the clearance up to the horizon
};

// The longest time t <= horizon, on a grid fine enough that the gap between
// the lump's bounding sphere (centre x0 + v0 t + g t^2 / 2) and the nearest
// surface cannot close by more than clearance / 2 between two grid times,
// such that the gap is at least the clearance at every grid time up to t:
// over [0, t] the gap stays above clearance / 2, so no element touches the
// housing or the flywheel (given at its angle at the start, turning at
// omega). 0 when the gap is below the clearance at the start.
FreeFlight free_flight_time(const Surface& housing, const Surface& flywheel,
                            const FreeFlightQuery& q);

}  // namespace mill::geometry
