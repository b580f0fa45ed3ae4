// The flat-joint interface (Potyondy 2012): element layout, force-displacement
// law and breakage. Equations: docs/styles/fix_bond_flatjoint.md.
#include "flat_joint.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace mill::flat_joint {

using namespace bond_geometry;

namespace {

constexpr double kPi = 3.14159265358979323846;

// t1 carried with the pair from the normal n0 to n1 and turned by `spin`
// about n1: the smallest rotation taking n0 onto n1 (Rodrigues, axis
// k = n0 x n1: v + k x v + k x (k x v) / (1 + n0 . n1)), exact for any turn
// of the pair below 180 degrees, then the spin; kept unit and normal to n1.
Vec3 carry(Vec3 t1, Vec3 n0, Vec3 n1, double spin) {
  const Vec3 k = cross(n0, n1);
  const Vec3 kv = cross(k, t1);
  t1 = t1 + kv + (1.0 / (1.0 + dot(n0, n1))) * cross(k, kv);
  if (spin != 0.0) t1 = std::cos(spin) * t1 + std::sin(spin) * cross(n1, t1);
  t1 = t1 - dot(t1, n1) * n1;
  return (1.0 / std::sqrt(dot(t1, t1))) * t1;
}

// An axis normal to n: n x (the coordinate axis least aligned with n).
Vec3 any_normal(Vec3 n) {
  const double ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
  const Vec3 e = ax <= ay && ax <= az ? Vec3{1, 0, 0} : (ay <= az ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
  const Vec3 t = cross(n, e);
  return (1.0 / std::sqrt(dot(t, t))) * t;
}

// One element's load: normal force (tension > 0) and in-plane shear force.
struct ElementLoad {
  double normal = 0, s1 = 0, s2 = 0;
  double energy(double kna, double ksa) const {
    return 0.5 * normal * normal / kna + 0.5 * (s1 * s1 + s2 * s2) / ksa;
  }
};

// Work lost to slip in one step of a shear spring ks A whose force went from
// `prev` to the elastic trial `trial` and was then cut back to `kept`: the
// work the grains did on it (the mean force times the displacement, as the
// energy ledger integrates it) minus the change of its stored energy,
// (trial - kept) . (prev + kept) / (2 ks A). (Cap x slip, the usual
// estimate, misses (trial - kept) . (prev - kept) / (2 ks A) each step: an
// error of first order in dt over a run.)
double slip_loss(const ElementLoad &trial, const ElementLoad &kept, double prev1, double prev2,
                 double ksa) {
  return ((trial.s1 - kept.s1) * (prev1 + kept.s1) + (trial.s2 - kept.s2) * (prev2 + kept.s2)) /
         (2.0 * ksa);
}

}  // namespace

Layout make_layout(int nr, int na) {
  if (nr < 1 || na < 3 || nr * na > kMaxElements)
    throw std::invalid_argument("flat joint: " + std::to_string(nr) + " rings x " +
                                std::to_string(na) +
                                " sectors: need rings >= 1, sectors >= 3 and at most " +
                                std::to_string(kMaxElements) + " elements");
  Layout lay;
  lay.nr = nr;
  lay.na = na;
  for (int k = 0; k < nr; ++k) {
    const double r_in = double(k) / nr, r_out = double(k + 1) / nr;
    const double ring_area = r_out * r_out - r_in * r_in;  // / (pi R^2)
    const double rho = std::sqrt(0.5 * (r_in * r_in + r_out * r_out));
    for (int s = 0; s < na; ++s) {
      const double alpha = 2.0 * kPi * (s + 0.5) / na;
      lay.area.push_back(ring_area / na);
      lay.px.push_back(rho * std::cos(alpha));
      lay.py.push_back(rho * std::sin(alpha));
    }
  }
  return lay;
}

void init_history(double *h, const Layout &lay, Vec3 n, bool bonded) {
  store3(h + kT1, any_normal(n));
  store3(h + kNormal, n);
  h[kBend] = h[kBend + 1] = 0.0;
  for (int e = 0; e < lay.elements(); ++e) {
    double *el = h + kHistory + 3 * e;
    el[kState] = bonded ? 0.0 : 1.0;
    el[kShear] = el[kShear + 1] = 0.0;
  }
}

Result update(double *h, const Layout &lay, const Params &p, const Step &s) {
  const double area = kPi * p.radius * p.radius;
  Vec3 t1 = load3(h + kT1);
  // Each element's shear force at the end of the last step (frame components).
  double prev1[kMaxElements] = {}, prev2[kMaxElements] = {};
  if (s.advance) {
    // The step's increments on the midpoint's frame (the bond style's
    // scheme): the relative bend rotation and each element's shear force are
    // held in the (t1, t2) frame, which turns with the pair.
    t1 = carry(t1, load3(h + kNormal), s.n_mid, 0.5 * s.spin);
    const Vec3 t2 = cross(s.n_mid, t1);
    const double du1 = dot(s.du_shear, t1), du2 = dot(s.du_shear, t2);
    const double twist = dot(s.dtheta, s.n_mid);
    h[kBend] += dot(s.dtheta, t1);
    h[kBend + 1] += dot(s.dtheta, t2);
    for (int e = 0; e < lay.elements(); ++e) {
      // Shear displacement of the element: the centre's plus the twist's,
      // twist x (n x r) with n x t1 = t2, n x t2 = -t1.
      const double x = p.radius * lay.px[e], y = p.radius * lay.py[e];
      const double ksa = p.ks * area * lay.area[e];
      double *el = h + kHistory + 3 * e;
      prev1[e] = el[kShear];
      prev2[e] = el[kShear + 1];
      el[kShear] -= ksa * (du1 - twist * y);
      el[kShear + 1] -= ksa * (du2 + twist * x);
    }
    t1 = carry(t1, s.n_mid, s.n_end, 0.5 * s.spin);
    store3(h + kT1, t1);
    store3(h + kNormal, s.n_end);
  }

  const Vec3 n = s.n_end;
  const Vec3 t2 = cross(n, t1);
  const double th1 = h[kBend], th2 = h[kBend + 1];
  Result out;
  out.force_b = out.moment_b = Vec3{0, 0, 0};
  int checked = 0;  // bonded elements at the start of the step
  for (int e = 0; e < lay.elements(); ++e) {
    const double x = p.radius * lay.px[e], y = p.radius * lay.py[e];
    const double ae = area * lay.area[e];
    const double kna = p.kn * ae, ksa = p.ks * ae;
    double *el = h + kHistory + 3 * e;
    // Opening of the element: the stretch plus the bend rotation's,
    // (theta_b x r) . n = theta_1 y - theta_2 x (tension > 0).
    const double u = s.stretch + th1 * y - th2 * x;
    ElementLoad load{kna * u, el[kShear], el[kShear + 1]};
    const Vec3 r = x * t1 + y * t2;
    bool broke = false;
    ElementLoad before;
    if (el[kState] == 0.0) {
      const double sigma = load.normal / ae;
      const double tau = std::sqrt(load.s1 * load.s1 + load.s2 * load.s2) / ae;
      const double strength = p.cohesion - sigma * p.tan_phi;  // Mohr-Coulomb, tension > 0
      out.sigma_max = checked++ == 0 ? sigma : std::max(out.sigma_max, sigma);
      out.tau_ratio = std::max(out.tau_ratio, strength > 0.0 ? tau / strength : HUGE_VAL);
      if (s.advance && sigma > p.tensile) {
        ++out.broke_tension;
        broke = true;
      } else if (s.advance && tau > strength) {
        ++out.broke_shear;
        broke = true;
      } else {
        ++out.bonded;
      }
      if (broke) {
        el[kState] = 1.0;
        before = load;
      }
    }
    if (el[kState] != 0.0) {
      // Broken: compression only, once the faces touch (u + g0 < 0), and
      // shear up to mu x the compression.
      const double uc = u + s.gap0;
      if (uc >= 0.0) {
        // Open: the cap mu |N| has gone to zero and the shear slips off
        // (friction; one that broke this step counts it as released).
        if (s.advance && !broke) out.slipped += slip_loss(load, ElementLoad{}, prev1[e], prev2[e], ksa);
        load = ElementLoad{};
      } else {
        load.normal = kna * uc;
        const double cap = p.mu * (-load.normal);
        const double mag = std::sqrt(load.s1 * load.s1 + load.s2 * load.s2);
        if (mag > cap) {
          const double sc = mag > 0.0 ? cap / mag : 0.0;
          const ElementLoad trial = load;
          load.s1 *= sc;
          load.s2 *= sc;
          if (s.advance && !broke) out.slipped += slip_loss(trial, load, prev1[e], prev2[e], ksa);
        }
      }
    }
    if (s.advance) {
      el[kShear] = load.s1;
      el[kShear + 1] = load.s2;
    }
    if (broke) {
      // Released: what the element held minus what it still holds, plus the
      // half step of work the lost force would still have done (its force
      // ends between two steps), as for a parallel bond.
      const Vec3 gone = (-(before.normal - load.normal)) * n + (before.s1 - load.s1) * t1 +
                        (before.s2 - load.s2) * t2;
      const Vec3 v_e = s.vrel + cross(s.wrel, r);
      out.released += before.energy(kna, ksa) - load.energy(kna, ksa) + 0.5 * s.dt * dot(gone, v_e);
    }
    if (load.normal != 0.0 || load.s1 != 0.0 || load.s2 != 0.0) out.loaded = true;
    out.energy += load.energy(kna, ksa);
    const Vec3 f = (-load.normal) * n + load.s1 * t1 + load.s2 * t2;
    out.force_b = out.force_b + f;
    out.moment_b = out.moment_b + cross(r, f);
  }
  return out;
}

Stiffness intact_stiffness(const Layout &lay, const Params &p) {
  const double area = kPi * p.radius * p.radius, r2 = p.radius * p.radius;
  double ixx = 0, iyy = 0;
  for (int e = 0; e < lay.elements(); ++e) {
    ixx += area * lay.area[e] * r2 * lay.py[e] * lay.py[e];
    iyy += area * lay.area[e] * r2 * lay.px[e] * lay.px[e];
  }
  return {p.kn * area, p.ks * area, p.kn * std::max(ixx, iyy), p.ks * (ixx + iyy)};
}

}  // namespace mill::flat_joint
