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

// Both are inlined into the element update (a call passes the 3-vectors
// through the stack); the exported turn_sin_cos and carry below wrap them
// for the tests.
[[gnu::always_inline]] inline SinCos sin_cos(double a) {
  if (std::fabs(a) >= kSeriesTurn) return {std::sin(a), std::cos(a)};
  // Horner forms of the series (flat_joint.h: error bounds); the constants
  // are the reciprocals, so that nothing here divides.
  const double a2 = a * a;
  const double s = a * (1.0 - a2 * (1.0 / 6.0) * (1.0 - a2 * (1.0 / 20.0)));
  const double c = 1.0 - 0.5 * a2 * (1.0 - a2 * (1.0 / 12.0));
  return {s, c};
}

// t1 (unit, normal to n0) carried with the pair from the normal n0 to n1
// and turned by `spin` about n1. The carry is the smallest rotation taking
// n0 onto n1, exact for any turn of the pair below 180 degrees: Rodrigues'
// rotation about k = n0 x n1, v + k x v + k x (k x v) / (1 + n0 . n1),
// which is also the product of two reflections,
// v + 2 (n0 . v) n1 - (s . v) / (1 + n0 . n1) s with s = n0 + n1; for v = t1
// normal to n0 the middle term is zero (round-off), which leaves
// t1 - (s . t1) / (1 + n0 . n1) s: the same rotation in half the
// operations. Then the spin: t1 cos + (n1 x t1) sin (sin_cos). Rotations
// keep t1 unit and normal to n1 up to round-off; carry (the end of a step)
// removes that round-off; the midpoint's turn does without it.
[[gnu::always_inline]] inline Vec3 turn(Vec3 t1, Vec3 n0, Vec3 n1, double spin) {
  const Vec3 s = n0 + n1;
  t1 = t1 - (dot(s, t1) / (1.0 + dot(n0, n1))) * s;
  if (spin != 0.0) {
    const SinCos sc = sin_cos(spin);
    t1 = sc.cos * t1 + sc.sin * cross(n1, t1);
  }
  return t1;
}
[[gnu::always_inline]] inline Vec3 carry_inline(Vec3 t1, Vec3 n0, Vec3 n1, double spin) {
  t1 = turn(t1, n0, n1, spin);
  t1 = t1 - dot(t1, n1) * n1;
  return (1.0 / std::sqrt(dot(t1, t1))) * t1;
}

}  // namespace

SinCos turn_sin_cos(double a) { return sin_cos(a); }
Vec3 carry(Vec3 t1, Vec3 n0, Vec3 n1, double spin) { return carry_inline(t1, n0, n1, spin); }

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
      lay.inv_area.push_back(na / ring_area);
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

// The element loop runs for every interface every step, so it is written to
// avoid what costs there (perf: a square root and five divisions per
// element): the strength tests compare squares (|S|^2 against (tau_c A_e)^2),
// the largest stresses are found after the loop and only when they are
// wanted (Step::stresses, or a break), the stored energy is summed
// as N^2 / a_e and |S|^2 / a_e (a_e = A_e / A, its reciprocal from the
// layout) and scaled once, and the force and moment are summed in the frame
// (t1, t2, n) and turned into the global frame once. The square root is
// taken only where a broken element slips. All of it is the same arithmetic
// as docs/styles/fix_bond_flatjoint.md up to round-off.
Result update(double *h, const Layout &lay, const Params &p, const Step &s) {
  // Copies: h, p, s and the layout are all doubles, so without them every
  // store into h would make the compiler load the others again.
  const double radius = p.radius, area = kPi * radius * radius;
  const double kn = p.kn, kna_all = kn * area, ksa_all = p.ks * area;
  const double cohesion = p.cohesion, tan_phi = p.tan_phi, tensile = p.tensile, mu = p.mu;
  const double stretch = s.stretch, gap0 = s.gap0;
  // Tension softening: from u_t = sigma_c / kn to u_s = lambda u_t (lambda = 1: brittle).
  const bool softens = p.softening > 1.0;
  const double u_t = tensile / kn, u_s = p.softening * u_t;
  const bool advance = s.advance;
  const double *px = lay.px.data(), *py = lay.py.data(), *pa = lay.area.data();
  const double *inv_a = lay.inv_area.data();

  Vec3 t1 = load3(h + kT1);
  // The step's increments on the midpoint's frame (the bond style's scheme):
  // the relative bend rotation and each element's shear force are held in the
  // (t1, t2) frame, which turns with the pair. Each element's shear
  // increment is the centre's plus the twist's, twist x (n x r) with
  // n x t1 = t2, n x t2 = -t1: (du1 - twist y, du2 + twist x).
  double du1 = 0.0, du2 = 0.0, twist = 0.0;
  if (advance) {
    const Vec3 n_mid = s.n_mid, n_end = s.n_end;
    t1 = turn(t1, load3(h + kNormal), n_mid, 0.5 * s.spin);
    const Vec3 t2 = cross(n_mid, t1);
    du1 = dot(s.du_shear, t1);
    du2 = dot(s.du_shear, t2);
    twist = dot(s.dtheta, n_mid);
    h[kBend] += dot(s.dtheta, t1);
    h[kBend + 1] += dot(s.dtheta, t2);
    t1 = carry_inline(t1, n_mid, n_end, 0.5 * s.spin);
    store3(h + kT1, t1);
    store3(h + kNormal, n_end);
  }

  const Vec3 n = s.n_end;
  const Vec3 t2 = cross(n, t1);
  const double th1 = h[kBend], th2 = h[kBend + 1];
  Result out;
  // Force on b, its moment about the contact point and the stored energy,
  // summed over the elements in (t1, t2, n) (flat_joint.h, ElementSums).
  ElementSums<double> sums;
  // The bonded elements' stresses at the start of the step, for sigma_max
  // and tau_ratio after the loop (when they are wanted).
  int checked = 0;  // bonded elements at the start of the step
  int checked_e[kMaxElements];
  double sigma_e[kMaxElements], shear_sq_e[kMaxElements], strength_e[kMaxElements];
  const int ne = lay.elements();
  for (int e = 0; e < ne; ++e) {
    const double x = radius * px[e], y = radius * py[e];
    const double kna = kna_all * pa[e], ksa = ksa_all * pa[e];
    double *el = h + kHistory + 3 * e;
    // Each element's shear force at the end of the last step (frame components).
    const double prev1 = el[kShear], prev2 = el[kShear + 1];
    double s1 = prev1, s2 = prev2;
    if (advance) {
      s1 -= ksa * (du1 - twist * y);
      s2 -= ksa * (du2 + twist * x);
    }
    // Opening of the element: the stretch plus the bend rotation's,
    // (theta_b x r) . n = theta_1 y - theta_2 x (tension > 0).
    const double u = stretch + th1 * y - th2 * x;
    double normal = kna * u;
    bool broke = false;
    ElementLoad before;
    const double damage = el[kState];  // 0 intact, 1 broken, between: softened
    const bool bonded = damage < 1.0;
    double keep = 1.0, inv_keep = 1.0;  // 1 - D of a softened element opened in tension, else 1
    if (softens && bonded && u > 0.0) {
      double d = damage;
      if (advance && u > u_t && u < u_s) {
        // On the envelope sigma_c (u_s - u) / (u_s - u_t): the secant's damage.
        const double d_env = 1.0 - tensile * (u_s - u) / ((u_s - u_t) * kn * u);
        if (d_env > d) {
          // At this opening the element held (1 - d) kn A_e u^2 / 2 and now
          // holds (1 - d_env) of it: the difference is dissipated.
          out.released += 0.5 * kna * u * u * (d_env - d);
          el[kState] = d_env;
          d = d_env;
        }
      }
      keep = 1.0 - d;
      inv_keep = 1.0 / keep;  // only here: no division per element otherwise
      normal *= keep;
    }
    if (bonded) {
      const double sigma = keep * kn * u;                  // N_e / A_e
      const double strength = cohesion - sigma * tan_phi;  // Mohr-Coulomb, tension > 0
      // tau > tau_c  <=>  |S|^2 > (tau_c A_e)^2 for tau_c > 0; always for
      // tau_c < 0; for tau_c = 0 once any shear is left.
      const double s_sq = s1 * s1 + s2 * s2;
      const double lim = strength * area * pa[e], lim_sq = lim * lim;
      checked_e[checked] = e;
      sigma_e[checked] = sigma;
      shear_sq_e[checked] = s_sq;
      strength_e[checked++] = strength;
      const bool shear_fails = strength > 0.0 ? s_sq > lim_sq : strength < 0.0 || s_sq > 0.0;
      if (advance && (softens ? u >= u_s : sigma > tensile)) {
        ++out.broke_tension;
        broke = true;
      } else if (advance && shear_fails) {
        ++out.broke_shear;
        broke = true;
      } else {
        ++out.bonded;
      }
      if (broke) {
        el[kState] = 1.0;
        before = ElementLoad{normal, s1, s2};
      }
    }
    if (!bonded || broke) {
      // Broken: compression only, once the faces touch (u + g0 < 0), and
      // shear up to mu x the compression.
      const double uc = u + gap0;
      if (uc >= 0.0) {
        // Open: the cap mu |N| has gone to zero and the shear slips off
        // (friction; one that broke this step counts it as released).
        if (advance && !broke)
          out.slipped += slip_loss(ElementLoad{normal, s1, s2}, ElementLoad{}, prev1, prev2, ksa);
        normal = s1 = s2 = 0.0;
      } else {
        normal = kna * uc;
        const double cap = mu * (-normal);  // >= 0
        const double mag_sq = s1 * s1 + s2 * s2;
        if (mag_sq > cap * cap) {  // slips: back onto the cone (mag > 0 here)
          const double sc = cap / std::sqrt(mag_sq);
          const ElementLoad trial{normal, s1, s2};
          s1 *= sc;
          s2 *= sc;
          if (advance && !broke)
            out.slipped += slip_loss(trial, ElementLoad{normal, s1, s2}, prev1, prev2, ksa);
        }
      }
      if (broke) {
        // Released: what the element held minus what it still holds, plus
        // the half step of work the lost force would still have done (its
        // force ends between two steps), as for a parallel bond.
        const ElementLoad load{normal, s1, s2};
        const Vec3 r = x * t1 + y * t2;
        const Vec3 gone = (-(before.normal - load.normal)) * n + (before.s1 - load.s1) * t1 +
                          (before.s2 - load.s2) * t2;
        const Vec3 v_e = s.vrel + cross(s.wrel, r);
        out.released +=
            before.energy(kna * keep, ksa) - load.energy(kna, ksa) + 0.5 * s.dt * dot(gone, v_e);
      }
    }
    if (advance) {
      el[kShear] = s1;
      el[kShear + 1] = s2;
    }
    sums.add(normal, s1, s2, x, y, inv_a[e], inv_keep);
  }
  out.energy = sums.energy(kna_all, ksa_all);
  // Some element carries force when some N_e or S_e is not zero (a force
  // below 1e-154 N, whose square underflows, counts as none).
  out.loaded = sums.sum_n > 0.0 || sums.sum_s > 0.0;
  if (s.stresses || out.broke_tension + out.broke_shear > 0) {
    for (int c = 0; c < checked; ++c) {
      const double tau = std::sqrt(shear_sq_e[c]) / (area * pa[checked_e[c]]);
      out.sigma_max = c == 0 ? sigma_e[c] : std::max(out.sigma_max, sigma_e[c]);
      out.tau_ratio = std::max(out.tau_ratio, strength_e[c] > 0.0 ? tau / strength_e[c] : HUGE_VAL);
    }
  }
  out.force_b = sums.force(t1, t2, n);
  out.moment_b = sums.moment(t1, t2, n);
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
