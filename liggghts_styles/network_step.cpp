// The network's largest eigenfrequency by Lanczos (network_step.h).
#include "network_step.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace mill::network_step {

using namespace bond_geometry;

namespace {

Vec3 at3(const std::vector<double> &v, size_t k) { return {v[k], v[k + 1], v[k + 2]}; }
void add3(std::vector<double> &v, size_t k, Vec3 a) {
  v[k] += a.x;
  v[k + 1] += a.y;
  v[k + 2] += a.z;
}

double norm(const std::vector<double> &v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s);
}

// M^-1/2 per coordinate: 1 / sqrt(m) for the translations, 1 / sqrt(I)
// for the rotations (computed once per estimate, not per product).
std::vector<double> inverse_sqrt_mass(const Atoms &atoms) {
  const size_t n_atoms = atoms.mass.size();
  std::vector<double> scale(6 * n_atoms);
  for (size_t i = 0; i < n_atoms; ++i) {
    const double sm = 1.0 / std::sqrt(atoms.mass[i]), si = 1.0 / std::sqrt(atoms.inertia[i]);
    for (int c = 0; c < 3; ++c) {
      scale[6 * i + c] = sm;
      scale[6 * i + 3 + c] = si;
    }
  }
  return scale;
}

// The energy of a bond is kn A dn^2 / 2 + ks A |dt|^2 / 2 + kn I |wt|^2 / 2 +
// ks J wn^2 / 2 with d the relative displacement of b's face at the contact
// point against a's, d = u_b - u_a + arm_a n x th_a + arm_b n x th_b, and w =
// th_b - th_a (n, t: its normal and in-plane parts); K x is its gradient: the
// force F = kn A dn n + ks A dt on b (-F on a), the moments arm F x n on
// each (d . (n x th) = th . (F x n)), and the bending and twisting moment
// M = kn I wt + ks J wn n on b (-M on a). `scale`: inverse_sqrt_mass; `q`
// holds M^-1/2 x between the calls.
void apply_scaled(const std::vector<Bond> &bonds, const std::vector<double> &scale,
                  const std::vector<double> &x, std::vector<double> &q, std::vector<double> &y) {
  q.resize(scale.size());
  for (size_t k = 0; k < q.size(); ++k) q[k] = scale[k] * x[k];
  y.assign(scale.size(), 0.0);
  for (const Bond &bd : bonds) {
    const size_t ia = 6 * static_cast<size_t>(bd.a), ib = 6 * static_cast<size_t>(bd.b);
    const Vec3 n = bd.n;
    const Vec3 ua = at3(q, ia), ta = at3(q, ia + 3), ub = at3(q, ib), tb = at3(q, ib + 3);
    const Vec3 d = ub - ua + bd.arm_a * cross(n, ta) + bd.arm_b * cross(n, tb);
    const double dn = dot(d, n);
    const Vec3 f = (bd.kna * dn) * n + bd.ksa * (d - dn * n);
    const Vec3 fxn = cross(f, n);
    const Vec3 w = tb - ta;
    const double wn = dot(w, n);
    const Vec3 m = bd.kni * (w - wn * n) + (bd.ksj * wn) * n;
    add3(y, ia, -f);
    add3(y, ib, f);
    add3(y, ia + 3, bd.arm_a * fxn - m);
    add3(y, ib + 3, bd.arm_b * fxn + m);
  }
  for (size_t k = 0; k < y.size(); ++k) y[k] *= scale[k];
}

}  // namespace

void apply(const std::vector<Bond> &bonds, const Atoms &atoms, const std::vector<double> &x,
           std::vector<double> &y) {
  std::vector<double> q;
  apply_scaled(bonds, inverse_sqrt_mass(atoms), x, q, y);
}

Estimate largest_omega2(const std::vector<Bond> &bonds, const Atoms &atoms, const Options &opt) {
  Estimate est;
  const size_t dim = 6 * atoms.mass.size();
  if (bonds.empty() || dim == 0) return est;
  // Start: a fixed pseudo-random vector (a 64-bit linear congruential
  // generator, Knuth's MMIX constants), the same on every run.
  std::vector<double> v(dim), v_prev(dim, 0.0), w;
  uint64_t state = opt.seed;
  for (double &c : v) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    c = static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0) - 0.5;
  }
  const double v0 = norm(v);
  for (double &c : v) c /= v0;
  const std::vector<double> scale = inverse_sqrt_mass(atoms);
  std::vector<double> q, alpha, beta;
  double b_prev = 0.0;
  const int kmax = std::max(1, std::min<int>(opt.max_iterations, static_cast<int>(dim)));
  for (int k = 1; k <= kmax; ++k) {
    apply_scaled(bonds, scale, v, q, w);
    double a = 0.0;
    for (size_t c = 0; c < dim; ++c) {
      w[c] -= b_prev * v_prev[c];
      a += w[c] * v[c];
    }
    for (size_t c = 0; c < dim; ++c) w[c] -= a * v[c];
    const double b = norm(w);
    alpha.push_back(a);
    beta.push_back(b);
    // The Ritz value and its residual, every fourth step and at the end
    // (b at round-off: the Krylov space is invariant and theta exact in it).
    const bool last = k == kmax || !(b > 1e-12 * (std::fabs(a) + b_prev));
    if (last || k % 4 == 0) {
      const Eigen::VectorXd diag = Eigen::Map<const Eigen::VectorXd>(alpha.data(), k);
      const Eigen::VectorXd sub = Eigen::Map<const Eigen::VectorXd>(beta.data(), k - 1);
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es;
      es.computeFromTridiagonal(diag, sub, Eigen::ComputeEigenvectors);
      est.ritz = es.eigenvalues()(k - 1);
      est.residual = b * std::fabs(es.eigenvectors()(k - 1, k - 1));
      est.iterations = k;
      if (last || est.residual <= opt.tolerance * est.ritz) break;
    }
    for (size_t c = 0; c < dim; ++c) {
      v_prev[c] = v[c];
      v[c] = w[c] / b;
    }
    b_prev = b;
  }
  est.omega2 = est.ritz + est.residual;
  return est;
}

}  // namespace mill::network_step
