// The nearest point of a triangle to a point (Ericson 2005, Real-Time
// Collision Detection, sec. 5.1.5), shared by fix impact/recorder (contact
// points, liggghts_styles) and the in-mill runs' free flight
// (driver/geometry/free_flight.h). Header only, no LIGGGHTS.
#ifndef MILL_POST_CLOSEST_POINT_H
#define MILL_POST_CLOSEST_POINT_H

namespace mill::post {

inline double dot3_(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline void sub3_(const double *a, const double *b, double *c) {
  for (int k = 0; k < 3; ++k) c[k] = a[k] - b[k];
}

// Nearest point c of triangle (a, b, t) to p, by the Voronoi regions of the
// triangle's vertices, edges and face (Ericson 2005, Real-Time Collision
// Detection, sec. 5.1.5).
inline void closest_on_triangle(const double *p, const double *a, const double *b, const double *t,
                                double *c) {
  double ab[3], at[3], ap[3];
  sub3_(b, a, ab);
  sub3_(t, a, at);
  sub3_(p, a, ap);
  const double d1 = dot3_(ab, ap), d2 = dot3_(at, ap);
  if (d1 <= 0.0 && d2 <= 0.0) {  // vertex a
    for (int k = 0; k < 3; ++k) c[k] = a[k];
    return;
  }
  double bp[3];
  sub3_(p, b, bp);
  const double d3 = dot3_(ab, bp), d4 = dot3_(at, bp);
  if (d3 >= 0.0 && d4 <= d3) {  // vertex b
    for (int k = 0; k < 3; ++k) c[k] = b[k];
    return;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {  // edge ab
    const double v = d1 / (d1 - d3);
    for (int k = 0; k < 3; ++k) c[k] = a[k] + v * ab[k];
    return;
  }
  double tp[3];
  sub3_(p, t, tp);
  const double d5 = dot3_(ab, tp), d6 = dot3_(at, tp);
  if (d6 >= 0.0 && d5 <= d6) {  // vertex t
    for (int k = 0; k < 3; ++k) c[k] = t[k];
    return;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {  // edge at
    const double w = d2 / (d2 - d6);
    for (int k = 0; k < 3; ++k) c[k] = a[k] + w * at[k];
    return;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {  // edge bt
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    for (int k = 0; k < 3; ++k) c[k] = b[k] + w * (t[k] - b[k]);
    return;
  }
  const double denom = 1.0 / (va + vb + vc);  // inside the face
  const double v = vb * denom, w = vc * denom;
  for (int k = 0; k < 3; ++k) c[k] = a[k] + ab[k] * v + at[k] * w;
}

}  // namespace mill::post

#endif
