// Stage 'report': report/index.html (self-contained: pictures embedded) and
// report/summary.json from the declared outputs of every stage that ran.
#include "stages/report_stage.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "postprocess/breakage_results.h"
#include "progress.h"

namespace mill {
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned n = (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8) |
                       static_cast<unsigned char>(in[i + 2]);
    out += {t[n >> 18], t[(n >> 12) & 63], t[(n >> 6) & 63], t[n & 63]};
  }
  if (i + 1 == in.size()) {
    const unsigned n = static_cast<unsigned char>(in[i]) << 16;
    out += {t[n >> 18], t[(n >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const unsigned n = (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8);
    out += {t[n >> 18], t[(n >> 12) & 63], t[(n >> 6) & 63], '='};
  }
  return out;
}

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else if (c == '"') o += "&quot;";
    else o += c;
  }
  return o;
}

// A number for a table cell with the given precision ("{:.1f}"); a value
// that is not a number (NaN, infinite: a damaged or degenerate result) reads
// "n/a", never as a huge integer.
std::string cell(double v, const char* spec, double scale = 1.0) {
  if (!std::isfinite(v)) return "n/a";
  return fmt::format(fmt::runtime(spec), scale * v);
}

std::string fmt_value(const nlohmann::json& v) {
  if (v.is_number_float()) return cell(v.get<double>(), "{:.4g}");
  if (v.is_string()) return esc(v.get<std::string>());
  if (v.is_null()) return "n/a";
  return esc(v.dump());
}

// Every file the report reads, under the stage folders it knows.
std::vector<fs::path> report_inputs(const fs::path& run) {
  std::vector<fs::path> files;
  for (const char* stage : {"flow", "sample", "transport", "calibrate", "breakage"}) {
    const fs::path d = run / stage;
    if (!fs::is_directory(d)) continue;
    for (auto it = fs::recursive_directory_iterator(d); it != fs::recursive_directory_iterator(); ++it) {
      const fs::path p = it->path();
      if (it->is_directory() && (p.filename() == "jobs" || p.filename() == "lumps" || p.filename() == "case" ||
                                 p.filename() == "run" || p.filename().string().rfind("processor", 0) == 0)) {
        it.disable_recursion_pending();
        continue;
      }
      const std::string ext = p.extension().string();
      if (it->is_regular_file() && (ext == ".png" || ext == ".json" || ext == ".csv" || ext == ".md"))
        files.push_back(p);
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// A JSON object as a two-column table (nested objects flattened with dots).
void json_table(std::ostringstream& o, const nlohmann::json& j, const std::string& prefix = "") {
  if (prefix.empty()) o << "<table>\n";
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object()) json_table(o, *it, key);
    else o << "<tr><td>" << esc(key) << "</td><td>" << fmt_value(*it) << "</td></tr>\n";
  }
  if (prefix.empty()) o << "</table>\n";
}

// Input files the report could not read, with the reason: shown at the top
// of the report and printed as warnings, never silently left out.
using Problems = std::vector<std::pair<fs::path, std::string>>;

// A JSON file, or null when it does not exist; one that does not parse is
// null too and goes into `problems`.
nlohmann::json read_json(const fs::path& f, Problems& problems) {
  if (!fs::exists(f)) return nullptr;
  try {
    return nlohmann::json::parse(slurp(f));
  } catch (const std::exception& e) {
    if (std::none_of(problems.begin(), problems.end(), [&](const auto& p) { return p.first == f; }))
      problems.push_back({f, fmt::format("not valid JSON ({})", e.what())});
    return nullptr;
  }
}

// v[key] or null.
nlohmann::json pick(const nlohmann::json& v, const char* key) {
  return v.is_object() && v.contains(key) ? v.at(key) : nlohmann::json(nullptr);
}

void embed_png(std::ostringstream& o, const fs::path& f, const std::string& caption) {
  o << "<figure><img alt=\"" << esc(caption) << "\" src=\"data:image/png;base64," << base64(slurp(f))
    << "\"><figcaption>" << esc(caption) << "</figcaption></figure>\n";
}

// The numbers an engineer looks at first, per stage (and per rotor speed).
nlohmann::json headline(const fs::path& run, Problems& problems) {
  nlohmann::json h = nlohmann::json::object();
  for (const auto& d : {run / "flow", run / "transport"}) {
    if (!fs::is_directory(d)) continue;
    for (const auto& e : fs::directory_iterator(d)) {
      const std::string rpm = e.path().filename().string();
      if (!e.is_directory() || rpm.rfind("rpm", 0) != 0) continue;
      if (d.filename() == "flow") {
        const auto f = read_json(e.path() / "flow_report.json", problems);
        if (f.is_null()) continue;
        h["flow"][rpm] = {{"domain", pick(f, "domain")},
                          {"cells", pick(f, "cells")},
                          {"iterations", pick(f, "iterations")},
                          {"converged", pick(f, "converged")},
                          {"mass_imbalance_relative", pick(pick(f, "mass_flow_kg_s"), "imbalance_relative")},
                          {"inlet_mass_flow_kg_s", pick(pick(f, "mass_flow_kg_s"), "inlet_in")},
                          {"rim_gas_speed_to_tip_speed", pick(pick(f, "rim"), "ratio_speed_to_tip_speed")},
                          {"shaft_torque_Nm", pick(pick(f, "shaft"), "torque_Nm")},
                          {"shaft_power_kW", pick(pick(f, "shaft"), "power_kW")},
                          {"backflow_outlet_in_kg_s", pick(pick(f, "backflow_kg_s"), "outlet_in")},
                          {"backflow_inlet_out_kg_s", pick(pick(f, "backflow_kg_s"), "inlet_out")}};
      } else {
        const auto t = read_json(e.path() / "summary.json", problems);
        if (t.is_null()) continue;
        h["transport"][rpm] = {{"lumps", pick(t, "n_particles")},
                               {"flywheel_impacts", pick(t, "n_flywheel_impacts")},
                               {"wall_impacts", pick(t, "n_wall_impacts")},
                               {"flywheel_impact_speed_mean_m_s", pick(t, "flywheel_impact_speed_mean_m_s")},
                               {"flywheel_normal_speed_mean_m_s", pick(t, "flywheel_normal_speed_mean_m_s")},
                               {"flywheel_angle_mean_deg", pick(t, "flywheel_angle_mean_deg")}};
      }
    }
  }
  const auto cal = read_json(run / "calibrate" / "report.json", problems);
  if (!cal.is_null())
    h["calibration"] = {{"source", pick(cal, "source")}, {"converged", pick(cal, "converged")},
                        {"achieved", pick(cal, "achieved")}};
  const auto crit = read_json(run / "breakage" / "critical_velocity.json", problems);
  if (crit.is_array()) {
    for (const auto& c : crit) {
      const auto angle = pick(c, "angle_deg");
      h["breakage"]["critical_velocity_m_s"][angle.is_number() ? fmt::format("{:g} deg", angle.get<double>())
                                                               : std::string("all conditions")] =
          pick(c, "critical_velocity_m_s");
    }
    h["breakage"]["critical_largest_fraction"] = crit.empty() ? nlohmann::json(nullptr) : pick(crit[0], "threshold");
  }
  const auto prod = read_json(run / "breakage" / "product.json", problems);
  if (prod.is_array())
    for (const auto& p : prod)
      if (pick(p, "rpm").is_number()) h["product"][fmt::format("rpm{:g}", pick(p, "rpm").get<double>())] = {
          {"fully_shredded_mass_fraction", pick(p, "fully_shredded_mass_fraction")},
          {"largest_piece_mass_fraction", pick(p, "largest_piece_mass_fraction")},
          {"t10_percent", pick(p, "t10_percent")},
          {"conditions", pick(p, "conditions")}};
  return h;
}

}  // namespace

Plan ReportStage::plan(const StageContext& ctx) const {
  Plan p;
  // The report is rebuilt whenever any file it reads changed (size, time).
  nlohmann::json in = nlohmann::json::array();
  for (const auto& f : report_inputs(ctx.run_dir)) {
    struct stat st {};
    stat(f.c_str(), &st);
    in.push_back({fs::relative(f, ctx.run_dir).string(), static_cast<long long>(st.st_size),
                  static_cast<long long>(st.st_mtime)});
  }
  p.jobs.push_back({"report", {{"inputs", in}, {"report_version", 2}},
                    "report/index.html and report/summary.json from every stage's outputs"});
  return p;
}

// report/index.html (complete: it ends with </html>) and report/summary.json.
std::string ReportStage::damaged_outputs(const StageContext& ctx, const JobSpec&) const {
  return jobs::first_problem({jobs::check_text_ends(ctx.stage_dir / "index.html", "</html>"),
                              jobs::check_json(ctx.stage_dir / "summary.json")});
}

void ReportStage::run_job(StageContext& ctx, const JobSpec&, const fs::path&) {
  const fs::path run = ctx.run_dir, out_dir = ctx.stage_dir;
  const auto inputs = report_inputs(run);
  Problems problems;
  nlohmann::json summary = {{"case", ctx.cfg.name}, {"ore", ctx.cfg.ore.str("name")},
                            {"headline", headline(run, problems)}};

  // Figures drawn for the report from the flow stage's files: the mill
  // geometry and the solver's convergence (matplotlib, Debian's python3).
  const fs::path figures = out_dir / "figures";
  fs::remove_all(figures);
  if (fs::is_directory(run / "flow")) {
    fs::create_directories(figures);
    engine::Command c;
    c.argv = {"/usr/bin/python3", (ctx.cfg.project_dir / "postprocess" / "plot_report_figures.py").string(), "--run",
              run.string(), "--out", figures.string(), "--target",
              fmt::format("{:g}", ctx.cfg.doc.real("flow.residual_target"))};
    c.cwd = out_dir;
    c.log = out_dir / "figures.log";
    c.job = "report/figures";
    ctx.runner.run(c);
  }
  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Beater mill: " << esc(ctx.cfg.name)
    << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
       "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}"
       "td:first-child{text-align:left}img{max-width:100%;border:1px solid #eee;margin:0.5em 0}"
       "h2{border-bottom:2px solid #468;padding-bottom:2px}.note{color:#666}"
       ".bad{color:#a00;border:1px solid #a00;padding:0.5em}</style></head><body>\n";
  o << "<h1>Beater mill: case " << esc(ctx.cfg.name) << "</h1>\n";
  if (ctx.cfg.doc.has("description")) o << "<p>" << esc(ctx.cfg.doc.str("description")) << "</p>\n";
  o << "<p class=note>Case file <code>" << esc(ctx.cfg.file.string()) << "</code>, ore card <code>"
    << esc(ctx.cfg.ore_file.string()) << "</code>. Every figure is embedded; its data file is linked.</p>\n";

  // A flow that missed its residual target reaches here only with
  // flow.allow_unconverged: say so first.
  std::vector<std::string> unconverged;
  const nlohmann::json& head = summary["headline"];
  if (head.contains("flow") && head["flow"].is_object())
    for (auto it = head["flow"].begin(); it != head["flow"].end(); ++it) {
      if (it->is_object() && it->contains("converged") && it->at("converged").is_boolean() &&
          !it->at("converged").get<bool>())
        unconverged.push_back(it.key());
    }
  if (!unconverged.empty()) {
    std::string list;
    for (const auto& r : unconverged) list += (list.empty() ? "" : ", ") + r;
    o << "<div class=bad><b>The gas flow did not converge</b> (" << esc(list)
      << "): it missed <code>flow.residual_target</code> within <code>flow.max_iterations</code>, and "
         "the case sets <code>flow.allow_unconverged: true</code>, so the sampled field, the lump "
         "tracks, the impact conditions and the mill product below rest on an unconverged flow.</div>\n";
    summary["unconverged_flow"] = unconverged;
  }

  o << "<h2>Headline numbers</h2>\n";
  if (summary["headline"].empty()) o << "<p class=note>No stage has produced results yet.</p>\n";
  else json_table(o, summary["headline"]);

  o << "<h2>Case and ore card</h2>\n";
  if (fs::exists(figures / "mill_geometry.png")) embed_png(o, figures / "mill_geometry.png", "mill geometry (STL)");
  json_table(o, ctx.cfg.ore.to_json());
  o << "<details><summary>All case keys (defaults included)</summary>\n";
  json_table(o, ctx.cfg.doc.to_json());
  o << "</details>\n";

  const std::vector<std::pair<std::string, std::string>> sections = {
      {"flow", "Stage 1a: gas flow (OpenFOAM)"},
      {"sample", "Stage 1a: sampled velocity field"},
      {"transport", "Stage 1b: ore lumps through the mill"},
      {"calibrate", "Calibration of the bond model"},
      {"breakage", "Stage 2: breakage of one lump"}};
  for (const auto& [stage, title] : sections) {
    std::vector<fs::path> mine;
    for (const auto& f : inputs)
      if (fs::relative(f, run).begin()->string() == stage) mine.push_back(f);
    o << "<h2>" << esc(title) << "</h2>\n";
    if (stage == "flow" && fs::is_directory(figures))
      for (const auto& f : fs::directory_iterator(figures))
        if (f.path().filename().string().rfind("flow_convergence_", 0) == 0)
          embed_png(o, f.path(), "solver convergence, " + f.path().stem().string().substr(17));
    if (mine.empty()) {
      o << "<p class=note>No results: stage '" << stage << "' has not run (<code>orchestrate --stage " << stage
        << "</code>).</p>\n";
      continue;
    }
    for (const auto& f : mine) {
      const std::string rel = fs::relative(f, out_dir).string();
      const std::string name = fs::relative(f, run).string();
      if (f.extension() == ".json") {
        const nlohmann::json j = read_json(f, problems);
        if (j.is_null()) {
          o << "<h3>" << esc(name) << "</h3>\n<p class=bad>Not shown: this file is damaged (see the top of the "
            << "page).</p>\n";
          continue;
        }
        o << "<h3>" << esc(name) << "</h3>\n";
        if (j.is_object()) json_table(o, j);
        else if (j.is_array())
          for (const auto& e : j)
            if (e.is_object()) json_table(o, e);
        summary[name] = j;
      } else if (f.extension() == ".png") {
        embed_png(o, f, name);
      } else if (f.extension() == ".csv" || f.extension() == ".md") {
        o << "<p>Data: <a href=\"" << esc(rel) << "\">" << esc(name) << "</a></p>\n";
      }
    }
    std::vector<post::ImpactSummary> rows;
    if (stage == "breakage" && fs::exists(run / "breakage" / "summary.csv")) {
      try {
        rows = post::ReadSummaryCsv((run / "breakage" / "summary.csv").string());
      } catch (const std::exception& e) {
        problems.push_back({run / "breakage" / "summary.csv", e.what()});
      }
    }
    if (!rows.empty()) {
      o << "<table><tr><th>V [m/s]</th><th>angle [deg]</th><th>repeat</th><th>pieces</th><th>single</th>"
           "<th>multi</th><th>largest [%]</th><th>single mass [%]</th><th>broken bonds [%]</th><th>E [kWh/t]</th>"
           "<th>t10 [%]</th></tr>\n";
      for (const auto& r : rows)
        o << fmt::format(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
            "<td>{}</td><td>{}</td><td>{}{}</td></tr>\n",
            cell(r.velocity_m_s, "{:g}"), cell(r.angle_deg, "{:g}"), r.repeat, r.n_pieces, r.n_single, r.n_multi,
            cell(r.largest_mass_fraction, "{:.1f}", 100), cell(r.single_mass_fraction, "{:.1f}", 100),
            cell(r.broken_bond_fraction, "{:.1f}", 100), cell(r.specific_energy_kWh_t, "{:.3g}"),
            cell(r.t10_percent, "{:.1f}"), r.t10_resolved ? "" : "*");
      o << "</table><p class=note>* t10 not resolved: single elements are coarser than a tenth of the lump.</p>\n";
      summary["breakage_impacts"] = rows.size();
    }
  }
  if (!problems.empty()) {
    // Named at the top of the page, in summary.json and on the console.
    std::ostringstream box;
    box << "<div class=bad><b>Damaged input files, left out of this report:</b><ul>\n";
    nlohmann::json list = nlohmann::json::array();
    for (const auto& [f, why] : problems) {
      const std::string rel = fs::relative(f, run).string();
      box << "<li><code>" << esc(rel) << "</code>: " << esc(why) << "</li>\n";
      list.push_back({{"file", rel}, {"problem", why}});
      ctx.progress.warn(fmt::format("[report] {}: {}; left out of the report (rerun the stage that writes it, with "
                                    "--force if its jobs are done)",
                                    f.string(), why));
    }
    box << "</ul>Rerun the stage that writes each file (with <code>--force</code> if its jobs are done), then the "
           "report.</div>\n";
    summary["damaged_inputs"] = list;
    std::string page = o.str();
    const std::string anchor = "<h2>Headline numbers</h2>";
    page.insert(page.find(anchor), box.str());
    o.str(page);
    o.seekp(0, std::ios::end);
  }
  o << "<hr><p class=note>Generated by orchestrate " << MILL_VERSION << ".</p></body></html>\n";
  jobs::atomic_write(out_dir / "index.html", o.str());
  jobs::atomic_write(out_dir / "summary.json", summary.dump(2) + "\n");
  ctx.progress.info("[report] " + (out_dir / "index.html").string());
}

}  // namespace mill
