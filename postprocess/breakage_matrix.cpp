// The breakage matrix from lumps' pieces; see breakage_matrix.h and
// docs/population_balance.md, "Breakage matrix from the in-mill runs".
#include "postprocess/breakage_matrix.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "postprocess/distributions.h"
#include "postprocess/fragments.h"

namespace mill::post {
namespace {

void CheckClass(const SizeClasses& classes, std::size_t j, const char* what) {
  if (j >= classes.size())
    throw PostError(fmt::format("{}: class {} of {} size classes; expected an index below {}", what,
                                j, classes.size(), classes.size()));
}

// The passing of a measured column at relative size s (sieve / x_m): its
// sieves' passing, linear in log(s) between them, 1 at and above its top
// sieve, the finest sieve's value below the finest sieve.
class RelativePassing {
 public:
  RelativePassing(const SizeClasses& classes, std::size_t m, const std::vector<double>& column) {
    const double x = RepresentativeSize(classes, m);
    // Sieves m .. n-1, ascending in s from the finest: passing sieve i is
    // the mass of classes i .. n-1.
    double passing = 0.0;
    for (std::size_t i = classes.size(); i-- > m;) {
      passing += column[i];
      log_s_.push_back(std::log(classes.upper_mm[i] / x));
      p_.push_back(i == m ? 1.0 : passing);
    }
  }

  double operator()(double s) const {
    const double ls = std::log(s);
    if (ls >= log_s_.back()) return 1.0;
    if (ls <= log_s_.front()) return p_.front();
    const auto hi = std::upper_bound(log_s_.begin(), log_s_.end(), ls) - log_s_.begin();
    const auto lo = hi - 1;
    const double w = (ls - log_s_[lo]) / (log_s_[hi] - log_s_[lo]);
    return p_[lo] + w * (p_[hi] - p_[lo]);
  }

 private:
  std::vector<double> log_s_, p_;  // ascending in s
};

}  // namespace

std::size_t ClassOfSize(const SizeClasses& classes, double size_mm) {
  const auto& u = classes.upper_mm;
  if (size_mm >= u.front()) return classes.size();
  std::size_t i = 0;
  while (i + 1 < u.size() && size_mm < u[i + 1]) ++i;
  return i;
}

std::vector<double> BinPieces(const SizeClasses& classes, std::size_t j, const LumpPieces& pieces) {
  CheckClass(classes, j, "binning pieces");
  const std::size_t n = classes.size();
  // SizeFractionMass's edges, ascending: 0, the sieves n-1 .. j+1, and class
  // j's upper edge; a piece at or above the top edge goes into the top
  // fraction, class j.
  std::vector<double> edges = {0.0};
  for (std::size_t i = n; i-- > j;) edges.push_back(classes.upper_mm[i]);
  const std::vector<double> f = SizeFractionMass(pieces.size_mm, pieces.mass_kg, edges);
  double total = 0.0;
  for (double m : pieces.mass_kg) total += m;
  std::vector<double> out(n, 0.0);
  for (std::size_t k = 0; k < f.size(); ++k) out[n - 1 - k] = f[k] * total;
  return out;
}

std::vector<double> MeasuredBreakageColumn(const SizeClasses& classes, std::size_t j,
                                           const std::vector<LumpPieces>& lumps) {
  CheckClass(classes, j, "measured breakage column");
  if (lumps.empty())
    throw PostError(
        fmt::format("measured breakage column of the {} class: no lump", classes.name(j)));
  std::vector<double> column(classes.size(), 0.0);
  double total = 0.0;
  for (const auto& lump : lumps) {
    const auto binned = BinPieces(classes, j, lump);
    for (std::size_t i = 0; i < column.size(); ++i) {
      column[i] += binned[i];
      total += binned[i];
    }
  }
  if (!(total > 0.0))
    throw PostError(
        fmt::format("measured breakage column of the {} class: the {} lump(s) hold no mass",
                    classes.name(j), lumps.size()));
  for (double& v : column) v /= total;
  return column;
}

std::vector<double> ScaledBreakageColumn(const SizeClasses& classes, std::size_t m,
                                         const std::vector<double>& column_m, std::size_t j) {
  CheckClass(classes, m, "scaled breakage column (measured class)");
  CheckClass(classes, j, "scaled breakage column");
  const std::size_t n = classes.size();
  if (column_m.size() != n)
    throw PostError(
        fmt::format("scaled breakage column: the measured column has {} entries for {} "
                    "size classes",
                    column_m.size(), n));
  const RelativePassing passing(classes, m, column_m);
  const double x = RepresentativeSize(classes, j);
  // q[i]: the passing of sieve i (i > j) for class j; q[j] = 1, q[n] = 0.
  std::vector<double> q(n + 1, 0.0);
  q[j] = 1.0;
  for (std::size_t i = j + 1; i < n; ++i)
    q[i] = std::min(q[i - 1], passing(classes.upper_mm[i] / x));
  std::vector<double> column(n, 0.0);
  for (std::size_t i = j; i < n; ++i) column[i] = q[i] - q[i + 1];
  return column;
}

std::size_t NearestMeasuredClass(const SizeClasses& classes, std::size_t j,
                                 const std::vector<std::size_t>& measured) {
  CheckClass(classes, j, "nearest measured class");
  if (measured.empty())
    throw PostError(fmt::format("nearest measured class to the {} class: no class is measured",
                                classes.name(j)));
  std::vector<std::size_t> sorted = measured;
  std::sort(sorted.begin(), sorted.end());
  // Coarsest first: only a strictly nearer class replaces the one found, so
  // the coarser of two equally near wins.
  const double lx = std::log(RepresentativeSize(classes, j));
  std::size_t from = sorted.front();
  double best = HUGE_VAL;
  for (std::size_t m : sorted) {
    CheckClass(classes, m, "nearest measured class");
    const double dist = std::abs(std::log(RepresentativeSize(classes, m)) - lx);
    if (dist < best - 1e-12) {
      best = dist;
      from = m;
    }
  }
  return from;
}

AssembledMatrix AssembleBreakageMatrix(const SizeClasses& classes,
                                       const std::map<std::size_t, std::vector<double>>& measured) {
  const std::size_t n = classes.size();
  if (measured.empty())
    throw PostError("breakage matrix: no measured column; expected at least one class with lumps");
  for (const auto& [m, column] : measured) {
    CheckClass(classes, m, "breakage matrix");
    if (column.size() != n)
      throw PostError(
          fmt::format("breakage matrix: the measured column of the {} class has {} "
                      "entries; expected {}",
                      classes.name(m), column.size(), n));
  }
  AssembledMatrix a;
  a.b.assign(n, std::vector<double>(n, 0.0));
  a.origin.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    std::vector<double> column;
    if (j + 1 == n) {
      column.assign(n, 0.0);
      column[j] = 1.0;
      a.origin[j] = {"finest", j};
    } else if (auto it = measured.find(j); it != measured.end()) {
      column = it->second;
      a.origin[j] = {"measured", j};
    } else {
      std::vector<std::size_t> have;
      for (const auto& [m, c] : measured) have.push_back(m);
      const std::size_t from = NearestMeasuredClass(classes, j, have);
      column = ScaledBreakageColumn(classes, from, measured.at(from), j);
      a.origin[j] = {"scaled", from};
    }
    for (std::size_t i = 0; i < n; ++i) a.b[i][j] = column[i];
  }
  ValidateBreakageMatrix(classes, a.b);
  return a;
}

}  // namespace mill::post
