// Hand-made iterations and packing runs for the calibrate stage's unit tests
// (no engine): what the lab tests of one set of bond parameters measured.
#pragma once

#include "stages/calibrate/fitting.h"

namespace mill::test {

// An iteration with parameters p whose first packing measured E, nu, UCS and T.
inline calibrate::Iteration iteration(const BondParams& p, double E, double nu, double ucs,
                                      double t) {
  calibrate::Iteration it;
  it.p = p;
  it.ucs.r.youngs_modulus = E;
  it.ucs.r.poisson_ratio = nu;
  it.ucs.r.ucs = ucs;
  it.br.r.tensile_strength = t;
  return it;
}

// The UCS and Brazilian tests on the packing of first seed `seed`.
inline calibrate::PackingRun packing_run(long seed, double E, double nu, double ucs, double t) {
  const calibrate::Iteration it = iteration({}, E, nu, ucs, t);
  calibrate::PackingRun r{seed, it.ucs, it.br, std::nullopt};
  r.ucs.tag = "packing_ucs";
  r.br.tag = "packing_brazilian";
  return r;
}

}  // namespace mill::test
