// The closed circuit per rotor speed (docs/population_balance.md, "The
// circuit per rotor speed").
#include "stages/breakage/circuit.h"

#include <fmt/format.h>

#include <cmath>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "postprocess/fragments.h"
#include "progress.h"
#include "stages/breakage/summaries.h"

namespace mill::breakage {

namespace {

// A vector given coarsest first, finest first (as the case's sieves).
std::vector<double> ascending(const std::vector<double>& coarsest_first) {
  return {coarsest_first.rbegin(), coarsest_first.rend()};
}

// With feed.target_p80_mm: the lowest rotor speed whose closed-circuit P80
// meets it (post::LowestSpeedMeetingP80) as circuit.json's "decision".
nlohmann::json decision_json(const config::Feed& feed, const nlohmann::json& speeds) {
  std::vector<post::SpeedForP80> points;
  for (const auto& e : speeds) {
    double p80 = HUGE_VAL;  // no steady state: never meets the target
    if (e.at("steady").get<bool>())
      p80 = e.at("p80_mm").is_number() ? e.at("p80_mm").get<double>() : feed.sizes_mm.front();
    points.push_back({e.at("rpm").get<double>(), p80});
  }
  const post::TargetDecision d = post::LowestSpeedMeetingP80(points, *feed.target_p80_mm);
  using K = post::TargetDecision::Kind;
  const char* kind = d.kind == K::crossed         ? "crossed"
                     : d.kind == K::met_at_lowest ? "met_at_lowest"
                                                  : "not_met";
  nlohmann::json j = {
      {"target_p80_mm", *feed.target_p80_mm},
      {"kind", kind},
      {"rpm", d.kind == K::not_met ? nlohmann::json(nullptr) : nlohmann::json(d.rpm)},
      {"met_at_every_faster_speed", d.met_above},
      {"sentence", post::DecisionSentence(d)},
      {"definition",
       "the lowest rotor speed whose closed-circuit product P80 is at or below "
       "the target, interpolated linearly in rpm between the two simulated "
       "speeds where P80 crosses it; a P80 finer than the finest sieve counts as "
       "that sieve, a speed with no steady state as not met"}};
  if (d.kind == K::crossed) {
    j["between_rpm"] = {d.below_rpm, d.above_rpm};
    j["interpolated"] = d.interpolated;
  }
  return j;
}

// P80 against rpm with the target and the decision
// (postprocess/plot_circuit.py, reading circuit.json only).
void plot_circuit(StageContext& ctx) {
  const std::filesystem::path dir = ctx.stage_dir;
  engine::run_python(
      ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_circuit.py",
      {"--circuit", (dir / "circuit.json").string(), "--out", (dir / "plots").string()},
      dir / "plot_circuit.log", "breakage/circuit plot");
}

std::string mm_or_finer(const nlohmann::json& v, double finest) {
  return v.is_number() ? fmt::format("{:.3g} mm", v.get<double>())
                       : fmt::format("< {:g} mm", finest);
}

}  // namespace

void write_circuit(StageContext& ctx, const std::map<double, post::AssembledMatrix>& matrices,
                   const std::map<double, MillEnergy>& energy) {
  const config::Feed& feed = ctx.cfg.feed.value();
  const post::SizeClasses classes = post::SizeClassesFromSieves(feed.sizes_mm);
  const std::size_t n = classes.size();
  const std::vector<double> c = post::SharpCutClassification(classes, feed.cut_size_mm);
  std::vector<double> f(n);
  for (std::size_t i = 0; i < n; ++i) f[i] = feed.rate_tph * feed.mass_fractions[n - 1 - i];
  nlohmann::json speeds = nlohmann::json::array();
  std::string csv =
      "rpm,class,lower_mm,upper_mm,feed_t_h,mill_input_t_h,returned_t_h,product_t_h,"
      "product_passing_percent,classification_returned\n";
  for (const auto& [rpm, m] : matrices) {
    nlohmann::json e = {{"rpm", rpm}};
    if (auto it = energy.find(rpm); it != energy.end()) {
      e["energy"] = energy_json(it->second, feed.rate_tph);
      ctx.progress.info(fmt::format(
          "[breakage] energy at {:g} rpm: {:.3g} kWh/t ({}ore {:.3g} kW at {:g} t/h)", rpm,
          e["energy"]["specific_energy_kWh_t"].get<double>(),
          it->second.has_gas
              ? fmt::format("gas shaft {:.3g} kW + ", it->second.gas_shaft_power_W / 1000)
              : std::string("no flow report: "),
          e["energy"]["ore_power_W"].get<double>() / 1000, feed.rate_tph));
    }
    post::CircuitState s;
    try {
      s = post::SolveCircuit(classes, m.b, c, f);
    } catch (const post::PostError& err) {
      e["steady"] = false;
      e["problem"] = err.what();
      speeds.push_back(e);
      ctx.progress.warn(fmt::format("[breakage] closed circuit at {:g} rpm: no steady state: {}",
                                    rpm, err.what()));
      continue;
    }
    if (!(s.mass_balance_residual <= kCircuitResidualLimit))
      throw std::runtime_error(fmt::format(
          "closed circuit at {:g} rpm: mass-balance residual {:.3g} of the feed, above {:g}: the "
          "balance does not close (breakage/breakage_matrix.json holds its matrix)",
          rpm, s.mass_balance_residual, kCircuitResidualLimit));
    std::vector<double> fraction = ascending(s.product);
    for (double& x : fraction) x /= s.product_total;
    const nlohmann::json pass = passing_json(feed.sizes_mm, fraction);
    e["steady"] = true;
    e["product_t_h"] = ascending(s.product);
    e["product_total_t_h"] = s.product_total;
    e["mill_input_t_h"] = ascending(s.mill_input);
    e["returned_t_h"] = ascending(s.returned);
    e["passing_percent"] = pass.at("passing_percent");
    e["p50_mm"] = pass.at("p50_mm");
    e["p80_mm"] = pass.at("p80_mm");
    e["circulating_load"] = s.circulating_load;
    e["mass_balance_residual"] = s.mass_balance_residual;
    speeds.push_back(e);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = n - 1 - k;  // the class of sieve k
      csv += fmt::format("{:g},{},{:g},{:g},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{:.6g}\n", rpm, i,
                         classes.lower_mm(i), classes.upper_mm[i], f[i], s.mill_input[i],
                         s.returned[i], s.product[i], pass.at("passing_percent")[k].get<double>(),
                         c[i]);
    }
    ctx.progress.info(fmt::format(
        "[breakage] closed circuit at {:g} rpm: product P80 {}, P50 {}, circulating load {:.3g} "
        "t per t of feed, mass-balance residual {:.2g}",
        rpm, mm_or_finer(e["p80_mm"], feed.sizes_mm.front()),
        mm_or_finer(e["p50_mm"], feed.sizes_mm.front()), s.circulating_load,
        s.mass_balance_residual));
  }
  nlohmann::json j = {
      {"feed",
       {{"sizes_mm", feed.sizes_mm},
        {"mass_fractions", feed.mass_fractions},
        {"rate_t_h", feed.rate_tph},
        {"cut_size_mm", feed.cut_size_mm},
        {"target_p80_mm",
         feed.target_p80_mm ? nlohmann::json(*feed.target_p80_mm) : nlohmann::json(nullptr)}}},
      {"sieves_mm", feed.sizes_mm},
      {"classification_returned", ascending(c)},
      {"rotor_speeds", speeds},
      {"units",
       {{"*_t_h", "t/h"},
        {"*_mm", "mm"},
        {"passing_percent", "% of the product's mass passing each sieve of sieves_mm"},
        {"circulating_load", "t returned to the rotor per t of fresh feed"},
        {"mass_balance_residual", "|product - feed| / feed, 1"},
        {"energy.*_kWh_t", "kWh per t of fresh feed"},
        {"energy.*_W", "W"}}},
      {"definitions",
       {{"order", "every per-class list follows sieves_mm, finest first"},
        {"steady_state",
         "m = f + C B m, product P = (I - C) B m (Whiten 1974; Austin, Klimpel & Luckie 1984); B "
         "from breakage/breakage_matrix.json, C the sharp cut at feed.cut_size_mm"},
        {"steady", "false when a class above the cut never breaks: no steady state (problem)"}}}};
  if (feed.target_p80_mm && !speeds.empty()) {
    j["decision"] = decision_json(feed, speeds);
    ctx.progress.info(fmt::format("[breakage] product P80 <= {:g} mm in the closed circuit: {}",
                                  *feed.target_p80_mm,
                                  j["decision"]["sentence"].get<std::string>()));
  }
  jobs::atomic_write(ctx.stage_dir / "circuit.json", j.dump(2) + "\n");
  jobs::atomic_write(ctx.stage_dir / "circuit.csv", csv);
  plot_circuit(ctx);
}

}  // namespace mill::breakage
