// The circuit of each rotor speed from its lumps and the bootstrap band over
// the lumps; see circuit_bootstrap.h and docs/population_balance.md, "The
// band the lumps give".
#include "postprocess/circuit_bootstrap.h"

#include <fmt/format.h>

#include <algorithm>
#include <random>

#include "postprocess/fragments.h"

namespace mill::post {
namespace {

std::string IntervalText(const Interval& v, const char* format, const char* unit) {
  return fmt::format(fmt::runtime(format), v.low) + "-" +
         fmt::format(fmt::runtime(format), v.high) + " " + unit;
}

// A lump of class j with its pieces binned once: one piece per class it
// reaches, at that class's representative size, holding the class's mass.
// MeasuredBreakageColumn bins it into the same masses (to rounding), so a
// draw costs a few entries per lump, not its every piece.
LumpRun Binned(const SizeClasses& classes, std::size_t j, const LumpRun& lump) {
  const std::vector<double> mass = BinPieces(classes, j, lump.pieces);
  LumpRun out;
  out.work = lump.work;
  for (std::size_t i = j; i < classes.size(); ++i)
    if (mass[i] > 0.0) {
      out.pieces.size_mm.push_back(RepresentativeSize(classes, i));
      out.pieces.mass_kg.push_back(mass[i]);
    }
  return out;
}

}  // namespace

SpeedOutcome EvaluateSpeed(const CircuitSetup& setup, const SpeedLumps& speed) {
  const SizeClasses& classes = setup.classes;
  std::map<std::size_t, std::vector<double>> columns;
  std::map<std::size_t, double> w;
  for (const auto& [j, lumps] : speed.by_class) {
    std::vector<LumpPieces> pieces;
    std::vector<LumpWork> work;
    for (const LumpRun& l : lumps) {
      pieces.push_back(l.pieces);
      work.push_back(l.work);
    }
    columns[j] = MeasuredBreakageColumn(classes, j, pieces);
    w[j] = BeaterWorkPerKg(work);
  }
  SpeedOutcome out;
  out.matrix = AssembleBreakageMatrix(classes, columns);
  out.work = BeaterWorkPerClass(classes, w);
  try {
    out.state = SolveCircuit(classes, out.matrix.b, setup.c, setup.feed_t_h);
  } catch (const PostError& e) {
    out.problem = e.what();
    return out;
  }
  out.steady = true;
  out.p80_mm =
      SizeAtPercentPassing(classes, out.state.product, 80).value_or(classes.upper_mm.back());
  out.energy =
      MillEnergyPerTonne(out.state.mill_input, out.work, speed.gas_W, out.state.feed_total);
  return out;
}

TargetDecision DecideFromOutcomes(const CircuitSetup& setup, const std::vector<SpeedLumps>& speeds,
                                  const std::vector<SpeedOutcome>& outcomes) {
  if (!setup.target_p80_mm) throw PostError("decision: no P80 target");
  std::vector<SpeedForP80> points;
  for (std::size_t k = 0; k < speeds.size(); ++k)
    points.push_back({speeds[k].rpm, outcomes.at(k).p80_mm});
  return LowestSpeedMeetingP80(points, *setup.target_p80_mm);
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) throw PostError("percentile of no value");
  std::sort(values.begin(), values.end());
  const double h = (static_cast<double>(values.size()) - 1.0) * p / 100.0;
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  const double a = values[lo], b = values[hi];
  if (a == b) return a;
  if (std::isinf(a) || std::isinf(b)) return HUGE_VAL;
  return a + (h - static_cast<double>(lo)) * (b - a);
}

CircuitBand BootstrapCircuit(const CircuitSetup& setup, const std::vector<SpeedLumps>& speeds,
                             const BootstrapOptions& options) {
  if (options.draws < 1)
    throw PostError(fmt::format("bootstrap: {} draws; expected at least 1", options.draws));
  CircuitBand band;
  band.draws = options.draws;
  band.seed = options.seed;
  band.low_percent = options.low_percent;
  band.high_percent = options.high_percent;
  band.has_target = setup.target_p80_mm.has_value();
  for (const SpeedLumps& s : speeds)
    for (const auto& [j, lumps] : s.by_class) band.defined = band.defined || lumps.size() > 1;
  if (!band.defined) {
    band.reason = "1 lump per class: no band";
    return band;
  }
  bool with_gas = true;
  for (const SpeedLumps& s : speeds) with_gas = with_gas && s.gas_W.has_value();
  std::mt19937_64 rng(options.seed);
  const std::size_t n_speeds = speeds.size();
  std::vector<std::vector<double>> p80(n_speeds), kwh(n_speeds);
  std::vector<double> rpm, kwh_decided;
  std::vector<SpeedLumps> binned = speeds;
  for (auto& s : binned)
    for (auto& [j, lumps] : s.by_class)
      for (LumpRun& l : lumps) l = Binned(setup.classes, j, l);
  std::vector<SpeedLumps> drawn = binned;
  for (int draw = 0; draw < options.draws; ++draw) {
    std::vector<SpeedOutcome> outcomes;
    std::map<double, CircuitEnergy> energy;
    for (std::size_t k = 0; k < n_speeds; ++k) {
      for (auto& [j, lumps] : drawn[k].by_class) {
        const std::vector<LumpRun>& from = binned[k].by_class.at(j);
        for (LumpRun& l : lumps) l = from[static_cast<std::size_t>(rng() % from.size())];
      }
      outcomes.push_back(EvaluateSpeed(setup, drawn[k]));
      p80[k].push_back(outcomes.back().p80_mm);
      if (outcomes.back().steady) {
        kwh[k].push_back(outcomes.back().energy.total_kWh_t);
        energy[speeds[k].rpm] = outcomes.back().energy;
      }
    }
    if (!band.has_target) continue;
    const TargetDecision d = DecideFromOutcomes(setup, speeds, outcomes);
    if (d.kind == TargetDecision::Kind::not_met) {
      rpm.push_back(HUGE_VAL);
      continue;
    }
    rpm.push_back(d.rpm);
    ++band.met_draws;
    if (const auto e = EnergyAtDecision(d, energy, with_gas).kWh_t) kwh_decided.push_back(*e);
  }
  const auto interval = [&](const std::vector<double>& v) {
    return Interval{Percentile(v, options.low_percent), Percentile(v, options.high_percent)};
  };
  for (std::size_t k = 0; k < n_speeds; ++k) {
    SpeedBand s;
    s.rpm = speeds[k].rpm;
    s.p80_mm = interval(p80[k]);
    s.steady_draws = static_cast<int>(kwh[k].size());
    if (!kwh[k].empty()) s.kWh_t = interval(kwh[k]);
    band.speeds.push_back(s);
  }
  if (band.has_target) {
    band.rpm = interval(rpm);
    band.kWh_t_draws = static_cast<int>(kwh_decided.size());
    if (!kwh_decided.empty()) band.kWh_t = interval(kwh_decided);
  }
  return band;
}

std::string BandSentence(const CircuitBand& band) {
  if (!band.defined) return band.reason;
  std::string s = fmt::format("{:g}-{:g} % of {} lump resamples: ", band.low_percent,
                              band.high_percent, band.draws);
  if (!band.has_target) return s + "no target";
  if (std::isinf(band.rpm.low))
    return s + fmt::format("the target is met in only {} of {} draws", band.met_draws, band.draws);
  if (std::isinf(band.rpm.high))
    s += fmt::format("from {:.0f} rpm to not met at any simulated speed ({} of {} draws meet it)",
                     band.rpm.low, band.met_draws, band.draws);
  else
    s += IntervalText(band.rpm, "{:.0f}", "rpm");
  if (band.kWh_t) s += ", " + IntervalText(*band.kWh_t, "{:.3g}", "kWh/t");
  return s;
}

}  // namespace mill::post
