// Energy bookkeeping shared by the project's styles and fix energy/ledger.
//
// PowerIntegral integrates a power P(t) [W] sampled at the full steps of
// velocity Verlet with the trapezoidal rule, one step's trapezoid at the end
// of each step (with that step's length, which may change between runs). With every force family's
// power summed this way, the kinetic energy follows exactly, up to the integrator's shadow term
// (docs/styles/fix_energy_ledger.md, "Exact bookkeeping").
#ifndef MILL_ENERGY_TERMS_H
#define MILL_ENERGY_TERMS_H

namespace mill {

// Sum over atoms of f.F/m + t.T/I for a family's forces f, torques t against
// the total force F and torque T (I = 2/5 m r^2): the family's end term of
// the trapezoidal work, times dt^2/4, that makes it its exact velocity-Verlet
// work (docs/styles/fix_energy_ledger.md).
inline double end_term(const double *f, const double *t, const double *ftot, const double *ttot,
                       double mass, double radius) {
  const double inertia = 0.4 * mass * radius * radius;
  return (f[0] * ftot[0] + f[1] * ftot[1] + f[2] * ftot[2]) / mass +
         (t[0] * ttot[0] + t[1] * ttot[1] + t[2] * ttot[2]) / inertia;
}

// Power of per-atom forces and torques f6 (6 per atom: force, torque) on the
// first n atoms at velocities v and angular velocities omega [W].
inline double power6(const double *f6, int n, double *const *v, double *const *omega) {
  double p = 0.0;
  for (int i = 0; i < n; ++i) {
    const double *q = f6 + 6 * i;
    p += q[0] * v[i][0] + q[1] * v[i][1] + q[2] * v[i][2] + q[3] * omega[i][0] +
         q[4] * omega[i][1] + q[5] * omega[i][2];
  }
  return p;
}

struct PowerIntegral {
  double cum = 0.0;   // the trapezoidal integral up to the last sample [J]
  double last = 0.0;  // the last power sampled [W]

  // The first sample (the setup of the first run).
  void start(double p, double /*step*/) {
    cum = 0.0;
    last = p;
  }
  // The sample at the end of a step of length `step`: that step's trapezoid,
  // (last + p) step / 2, exact also when the step changed between samples
  // (fix step/adaptive).
  void add(double p, double step) {
    cum += 0.5 * (last + p) * step;
    last = p;
  }
  // The trapezoidal integral up to the last sample [J].
  double value() const { return cum; }
  // The integral up to a sample p not yet added (read before the owner's
  // end_of_step ran this step) [J].
  double value_with(double p, double step) const { return cum + 0.5 * (last + p) * step; }
};

}  // namespace mill

#endif
