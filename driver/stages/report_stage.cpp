// Stage 'report': report/index.html (self-contained: pictures embedded) and
// report/summary.json from the declared outputs of every stage that ran.
#include "stages/report_stage.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <sstream>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "postprocess/breakage_results.h"
#include "progress.h"
#include "report/headline.h"
#include "report/html.h"

namespace mill {
namespace fs = std::filesystem;

namespace {

using report::cell;
using report::embed_png;
using report::esc;
using report::fold;
using report::json_table;
using report::Problems;

// Every file the report reads, under the stage folders it knows.
std::vector<fs::path> report_inputs(const fs::path& run) {
  std::vector<fs::path> files;
  for (const char* stage : {"flow", "sample", "transport", "calibrate", "breakage"}) {
    const fs::path d = run / stage;
    if (!fs::is_directory(d)) continue;
    for (auto it = fs::recursive_directory_iterator(d); it != fs::recursive_directory_iterator();
         ++it) {
      const fs::path p = it->path();
      if (it->is_directory() &&
          (p.filename() == "jobs" || p.filename() == "lumps" || p.filename() == "case" ||
           p.filename() == "run" || p.filename().string().rfind("processor", 0) == 0)) {
        it.disable_recursion_pending();
        continue;
      }
      const std::string ext = p.extension().string();
      if (p.filename() == "stage.json") continue;  // the stage's bookkeeping, not a result
      if (it->is_regular_file() &&
          (ext == ".png" || ext == ".gif" || ext == ".json" || ext == ".csv" || ext == ".md"))
        files.push_back(p);
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The stage's figures first in the order an engineer reads them, then the rest.
int figure_rank(const fs::path& f) {
  static const std::vector<std::string> first = {
      "jk_t10_vs_ecs.png",        "passing_vs_size.png",
      "product_vs_rpm.png",       "circuit_p80_vs_rpm.png",
      "largest_vs_velocity.png",
      "pieces_vs_velocity.png",   "comminution_efficiency_vs_velocity.png",
      "energy_ledger_fastest.png"};
  const auto it = std::find(first.begin(), first.end(), f.filename().string());
  return it == first.end() ? static_cast<int>(first.size()) : static_cast<int>(it - first.begin());
}

// The headline rows of the stage's groups as a labelled list (dt/dd).
void stage_numbers(std::ostringstream& o, const std::vector<report::HeadlineRow>& rows,
                   const std::string& stage) {
  std::string items;
  for (const auto& g : report::headline_groups()) {
    if (g.stage != stage) continue;
    for (const auto& r : rows)
      if (r.group == g.title)
        items += "<dt>" + esc(r.what) + "</dt><dd>" + esc(r.value) + "</dd>\n";
  }
  if (!items.empty()) o << "<dl class=numbers>\n" << items << "</dl>\n";
}

// The ore card's properties in words and units.
void ore_table(std::ostringstream& o, const config::Document& ore) {
  o << "<table class=headline>\n";
  auto row = [&](const std::string& what, const std::string& value) {
    o << "<tr><td>" << esc(what) << "</td><td>" << esc(value) << "</td></tr>\n";
  };
  row("ore", ore.str("name"));
  row("density", fmt::format("{:g} kg/m3", ore.real("density")));
  row("Young's modulus", fmt::format("{:.3g} GPa", ore.real("youngs_modulus") / 1e9));
  row("Poisson's ratio", fmt::format("{:g}", ore.real("poisson_ratio")));
  row("uniaxial compressive strength (UCS)", fmt::format("{:.3g} MPa", ore.real("ucs") / 1e6));
  row("tensile strength", fmt::format("{:.3g} MPa", ore.real("tensile_strength") / 1e6));
  if (ore.has("jk.A") && ore.has("jk.b"))
    row("JK breakage parameters (measured)",
        fmt::format("A {:g}%, b {:g} t/kWh, A x b {:.3g}", ore.real("jk.A"), ore.real("jk.b"),
                    ore.real("jk.A") * ore.real("jk.b")));
  o << "</table>\n";
}

// P50 and P80 per impact condition, from breakage/size_distributions.json.
void size_table(std::ostringstream& o, const nlohmann::json& sd) {
  const auto conds = report::pick(sd, "conditions");
  if (!conds.is_array() || conds.empty()) return;
  const auto finest = report::pick(sd, "finest_sieve_mm");
  auto mm = [&](const nlohmann::json& v) {
    if (v.is_number()) return cell(v.get<double>(), "{:.3g}");
    return finest.is_number() ? fmt::format("&lt; {:.3g}", finest.get<double>()) : std::string("-");
  };
  o << "<table><tr><th>impact speed [m/s]</th><th>angle [deg]</th><th>repeats</th><th>P50 "
       "[mm]</th><th>P80 [mm]</th>"
       "<th>P80 over repeats [mm]</th></tr>\n";
  for (const auto& c : conds) {
    const auto r = report::pick(c, "p80_mm_over_repeats");
    o << fmt::format(
        "<tr><td>{:g}</td><td>{:g}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
        c.value("velocity_m_s", 0.0), c.value("angle_deg", 0.0), c.value("repeats", 0),
        mm(report::pick(c, "p50_mm")), mm(report::pick(c, "p80_mm")),
        r.is_object() ? fmt::format("{:.3g}-{:.3g}", r.value("min", 0.0), r.value("max", 0.0))
                      : "-");
  }
  o << "</table><p class=note>Sizes are d/D x the lump diameter ("
    << fmt::format("{:g}", report::pick(sd, "lump_diameter_mm").is_number()
                               ? sd["lump_diameter_mm"].get<double>()
                               : 0.0)
    << " mm); P50 and P80 are interpolated log-linearly between sieves.</p>\n";
}

// Figures drawn for the report from the flow stage's files: the mill
// geometry and the solver's convergence (matplotlib, Debian's python3), into
// report/figures/ (emptied first). Returns that folder.
fs::path draw_figures(StageContext& ctx) {
  const fs::path run = ctx.run_dir, out_dir = ctx.stage_dir;
  const fs::path figures = out_dir / "figures";
  fs::remove_all(figures);
  if (fs::is_directory(run / "flow")) {
    fs::create_directories(figures);
    engine::run_python(ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_report_figures.py",
                       {"--run", run.string(), "--out", figures.string(), "--target",
                        fmt::format("{:g}", ctx.cfg.doc.real("flow.residual_target"))},
                       out_dir / "figures.log", "report/figures");
  }
  return figures;
}

// The page's head, title, the case's description and where it came from.
void page_intro(std::ostringstream& o, const config::CaseConfig& cfg) {
  o << report::page_head("Beater mill: " + cfg.name);
  o << "<h1>Beater mill: case " << esc(cfg.name) << "</h1>\n";
  if (cfg.doc.has("description")) o << "<p>" << esc(cfg.doc.str("description")) << "</p>\n";
  o << "<p class=note>Case file <code>" << esc(cfg.file.string()) << "</code>, ore card <code>"
    << esc(cfg.ore_file.string())
    << "</code>. Every figure is embedded; its data file is linked.</p>\n";
}

// A flow that missed its residual target reaches here only with
// flow.allow_unconverged: say so first (and in summary.json).
void unconverged_banner(std::ostringstream& o, nlohmann::json& summary) {
  std::vector<std::string> unconverged;
  const nlohmann::json& head = summary["headline"];
  if (head.contains("flow") && head["flow"].is_object())
    for (auto it = head["flow"].begin(); it != head["flow"].end(); ++it) {
      if (it->is_object() && it->contains("converged") && it->at("converged").is_boolean() &&
          !it->at("converged").get<bool>())
        unconverged.push_back(it.key());
    }
  // The transport stage records the flow state of the field it ran on.
  if (head.contains("transport") && head["transport"].is_object())
    for (auto it = head["transport"].begin(); it != head["transport"].end(); ++it)
      if (it->is_object() && it->contains("flow_converged") && it->at("flow_converged") == false &&
          std::find(unconverged.begin(), unconverged.end(), it.key()) == unconverged.end())
        unconverged.push_back(it.key());
  if (unconverged.empty()) return;
  std::string list;
  for (const auto& r : unconverged) list += (list.empty() ? "" : ", ") + r;
  o << "<div class=bad><b>The gas flow did not converge</b> (" << esc(list)
    << "): it missed <code>flow.residual_target</code> within <code>flow.max_iterations</code>, "
       "and "
       "the case sets <code>flow.allow_unconverged: true</code>, so the sampled field, the lump "
       "tracks, the impact conditions and the mill product below rest on an unconverged "
       "flow.</div>\n";
  summary["unconverged_flow"] = unconverged;
}

// Values the case or its ore card keeps outside their plausible range
// (allow_outside_range): say so first (and in summary.json).
void outlier_banner(std::ostringstream& o, const config::CaseConfig& cfg, nlohmann::json& summary) {
  const nlohmann::json all = config::outliers(cfg);
  if (all.empty()) return;
  o << "<div class=bad><b>Values outside their plausible range</b>, kept on purpose "
       "(<code>allow_outside_range</code>):<ul>\n";
  for (const auto& x : all) {
    const std::string unit = x["unit"].get<std::string>().empty() ? "" : " " + x["unit"].get<std::string>();
    o << "<li><code>" << esc(x["key"].get<std::string>()) << "</code> = " << config::num(x["value"].get<double>()) << esc(unit)
      << " (plausible " << config::num(x["plausible"][0].get<double>()) << " to "
      << config::num(x["plausible"][1].get<double>()) << esc(unit) << ") in " << esc(x["file"].get<std::string>())
      << "</li>\n";
  }
  o << "</ul></div>\n";
  summary["outside_plausible_range"] = all;
}

// The headline: a short table in words and units, grouped by stage.
void headline_table(std::ostringstream& o, const std::vector<report::HeadlineRow>& rows) {
  o << "<h2>Headline</h2>\n";
  if (rows.empty()) {
    o << "<p class=note>No stage has produced results yet.</p>\n";
    return;
  }
  o << "<table class=headline>\n";
  std::string group;
  for (const auto& r : rows) {
    if (!r.brief) continue;  // shown in its stage's section
    if (r.group != group) o << "<tr class=group><th colspan=2>" << esc(r.group) << "</th></tr>\n";
    group = r.group;
    o << "<tr><td>" << esc(r.what) << "</td><td>" << esc(r.value) << "</td></tr>\n";
  }
  o << "</table>\n";
}

// The case's section: the mill's picture, the ore card, every key folded.
void case_section(std::ostringstream& o, const config::CaseConfig& cfg, const fs::path& figures) {
  o << "<h2>Case and ore card</h2>\n";
  if (fs::exists(figures / "mill_geometry.png"))
    embed_png(o, figures / "mill_geometry.png", "mill geometry (STL)");
  ore_table(o, cfg.ore);
  o << fold("The ore card as written");
  json_table(o, cfg.ore.to_json());
  o << "</details>\n" << fold("All case keys (defaults included)");
  json_table(o, cfg.doc.to_json());
  o << "</details>\n";
}

// What a stage section is drawn from, and where it writes.
struct SectionInputs {
  fs::path run, out_dir, figures;
  const std::vector<report::HeadlineRow>& rows;
  nlohmann::json& summary;
  Problems& problems;
};

// A stage's JSON files as folded tables (into `raw`, each also into
// summary.json) and links to its data files (JSON, CSV, Markdown) in `o`.
void stage_data(std::ostringstream& o, std::ostringstream& raw, const std::vector<fs::path>& mine,
                const SectionInputs& in) {
  std::string links;
  for (const auto& f : mine) {
    const std::string rel = fs::relative(f, in.out_dir).string();
    const std::string name = fs::relative(f, in.run).string();
    if (f.extension() == ".json") {
      const nlohmann::json j = report::read_json(f, &in.problems);
      if (j.is_null()) {
        o << "<p class=bad><code>" << esc(name)
          << "</code> not shown: this file is damaged (see the top of the "
          << "page).</p>\n";
        continue;
      }
      raw << "<h3>" << esc(name) << "</h3>\n";
      if (j.is_object())
        json_table(raw, j);
      else if (j.is_array())
        for (const auto& e : j)
          if (e.is_object()) json_table(raw, e);
      in.summary[name] = j;
      links += (links.empty() ? "" : ", ") + std::string("<a href=\"") + esc(rel) + "\">" +
               esc(name) + "</a>";
    } else if (f.extension() == ".csv" || f.extension() == ".md") {
      links += (links.empty() ? "" : ", ") + std::string("<a href=\"") + esc(rel) + "\">" +
               esc(name) + "</a>";
    }
  }
  if (!links.empty()) o << "<p class=note>Data: " << links << "</p>\n";
}

// Every impact of breakage/summary.csv as a table (into `raw`).
void impact_table(std::ostringstream& raw, const SectionInputs& in) {
  std::vector<post::ImpactSummary> impacts;
  if (fs::exists(in.run / "breakage" / "summary.csv")) {
    try {
      impacts = post::ReadSummaryCsv((in.run / "breakage" / "summary.csv").string());
    } catch (const std::exception& e) {
      in.problems.push_back({in.run / "breakage" / "summary.csv", e.what()});
    }
  }
  if (impacts.empty()) return;
  raw << "<h3>Every impact</h3><table><tr><th>V [m/s]</th><th>angle "
         "[deg]</th><th>repeat</th><th>pieces</th>"
         "<th>single</th><th>multi</th><th>largest [%]</th><th>single mass [%]</th><th>broken "
         "bonds [%]</th>"
         "<th>Ecs [kWh/t]</th><th>t10 [%]</th><th>comminution efficiency [%]</th></tr>\n";
  for (const auto& r : impacts)
    raw << fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</"
        "td>"
        "<td>{}</td><td>{}</td><td>{}{}</td><td>{}</td></tr>\n",
        cell(r.velocity_m_s, "{:g}"), cell(r.angle_deg, "{:g}"), r.repeat, r.n_pieces, r.n_single,
        r.n_multi, cell(r.largest_mass_fraction, "{:.1f}", 100),
        cell(r.single_mass_fraction, "{:.1f}", 100), cell(r.broken_bond_fraction, "{:.1f}", 100),
        cell(r.specific_energy_kWh_t, "{:.3g}"), cell(r.t10_percent, "{:.1f}"),
        r.t10_resolved ? "" : "*", cell(r.comminution_efficiency, "{:.3g}", 100));
  raw << "</table><p class=note>* t10 not resolved: single elements are coarser than a tenth of "
         "the lump.</p>\n";
  in.summary["breakage_impacts"] = impacts.size();
}

// True for the files of breakage/animation/ (drawn by animation_block).
bool in_animation(const fs::path& f, const fs::path& run) {
  const fs::path rel = fs::relative(f, run);
  auto it = rel.begin();
  return it != rel.end() && *it == "breakage" && ++it != rel.end() && *it == "animation";
}

// The in-mill animation (breakage/animation/, docs/report.md): the GIF with
// a caption naming the lump, rotor speed and time span, then its first,
// middle and last frame as stills.
void animation_block(std::ostringstream& o, const SectionInputs& in) {
  const fs::path dir = in.run / "breakage" / "animation";
  if (!fs::is_directory(dir)) return;
  const nlohmann::json j = report::read_json(dir / "animation.json", &in.problems);
  if (!j.is_object()) {
    if (!fs::exists(dir / "animation.json"))
      in.problems.push_back({dir / "animation.json", "missing beside the animation's frames"});
    return;
  }
  for (const char* f :
       {"animation.gif", "animation_first.png", "animation_middle.png", "animation_last.png"})
    if (!fs::exists(dir / f)) {
      in.problems.push_back({dir / f, "missing: the in-mill animation is left out"});
      return;
    }
  const std::string caption = fmt::format(
      "{}. {} frames from t = {:.2f} to {:.2f} ms, one every {:.2f} ms; the elements (discs of "
      "their radius) coloured by their intact bonds, the housing and the flywheel cut in the "
      "plane of the rotor.",
      j.value("caption", std::string("In-mill run")), j.value("frames", 0),
      j.value("time_first_ms", 0.0), j.value("time_last_ms", 0.0),
      j.value("frame_interval_ms", 0.0));
  o << "<h3>One lump in the mill</h3>\n";
  report::embed_image(o, dir / "animation.gif", "image/gif", caption);
  o << "<figure class=strip>";
  for (const char* s : {"first", "middle", "last"}) {
    const auto& still = report::pick(report::pick(j, "stills"), s);
    const std::string what = fmt::format("{} frame, t = {:.2f} ms", s,
                                         still.is_object() ? still.value("time_ms", 0.0) : 0.0);
    o << "<div><img alt=\"" << esc(what) << "\" src=\"data:image/png;base64,"
      << report::base64(report::slurp(dir / fmt::format("animation_{}.png", s)))
      << "\"><figcaption>" << esc(what) << "</figcaption></div>";
  }
  o << "</figure>\n<p class=note>Drawn from the run's frame dump by "
       "<code>postprocess/plot_animation.py</code>; <code>breakage.in_mill.animate: false</code> "
       "turns it off.</p>\n";
  in.summary["in_mill_animation"] = j;
}

// One stage's section: figures first, then the stage's labelled numbers,
// then the raw data folded; a note when the stage has not run.
void stage_section(std::ostringstream& o, const std::string& stage, const std::string& title,
                   const std::vector<fs::path>& inputs, const SectionInputs& in) {
  std::vector<fs::path> mine;
  for (const auto& f : inputs)
    if (fs::relative(f, in.run).begin()->string() == stage) mine.push_back(f);
  o << "<h2>" << esc(title) << "</h2>\n";
  // Impacts that ran but were never merged are named, not left out.
  if (stage == "breakage" && !fs::exists(in.run / "breakage" / "summary.csv") &&
      fs::is_directory(in.run / "breakage" / "jobs"))
    in.problems.push_back(
        {in.run / "breakage" / "summary.csv",
         "missing: the breakage stage has jobs but no merged table of them (finish it with "
         "--stage breakage)"});
  if (stage == "flow" && fs::is_directory(in.figures))
    for (const auto& f : fs::directory_iterator(in.figures))
      if (f.path().filename().string().rfind("flow_convergence_", 0) == 0)
        embed_png(o, f.path(), "solver convergence, " + f.path().stem().string().substr(17));
  if (mine.empty()) {
    o << "<p class=note>No results: stage '" << stage << "' has not run (<code>orchestrate --stage "
      << stage << "</code>).</p>\n";
    return;
  }
  std::vector<fs::path> pngs;
  for (const auto& f : mine)
    if (f.extension() == ".png" && !in_animation(f, in.run)) pngs.push_back(f);
  std::stable_sort(pngs.begin(), pngs.end(), [](const fs::path& a, const fs::path& b) {
    return figure_rank(a) < figure_rank(b);
  });
  for (const auto& f : pngs) embed_png(o, f, fs::relative(f, in.run).string());
  if (stage == "breakage") animation_block(o, in);
  stage_numbers(o, in.rows, stage);
  if (stage == "breakage")
    size_table(o, report::read_json(in.run / "breakage" / "size_distributions.json", &in.problems));
  std::ostringstream raw;
  stage_data(o, raw, mine, in);
  if (stage == "breakage") impact_table(raw, in);
  if (!raw.str().empty())
    o << fold("Raw results: every key of the stage's JSON files") << raw.str() << "</details>\n";
}

// Damaged input files: named at the top of the page (before the headline),
// in summary.json and on the console.
void damaged_box(StageContext& ctx, std::ostringstream& o, const Problems& problems,
                 nlohmann::json& summary) {
  if (problems.empty()) return;
  std::ostringstream box;
  box << "<div class=bad><b>Damaged input files, left out of this report:</b><ul>\n";
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [f, why] : problems) {
    const std::string rel = fs::relative(f, ctx.run_dir).string();
    box << "<li><code>" << esc(rel) << "</code>: " << esc(why) << "</li>\n";
    list.push_back({{"file", rel}, {"problem", why}});
    ctx.progress.warn(
        fmt::format("[report] {}: {}; left out of the report (rerun the stage that writes it, with "
                    "--force if its jobs are done)",
                    f.string(), why));
  }
  box << "</ul>Rerun the stage that writes each file (with <code>--force</code> if its jobs are "
         "done), then the "
         "report.</div>\n";
  summary["damaged_inputs"] = list;
  std::string page = o.str();
  page.insert(page.find("<h2>Headline</h2>"), box.str());
  o.str(page);
  o.seekp(0, std::ios::end);
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
  p.jobs.push_back({"report",
                    {{"inputs", in}, {"report_version", 5}},
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
  nlohmann::json summary = {{"case", ctx.cfg.name},
                            {"ore", ctx.cfg.ore.str("name")},
                            {"headline", report::headline_json(run, &problems)}};
  const auto rows = report::headline_rows(summary["headline"]);
  const fs::path figures = draw_figures(ctx);
  std::ostringstream o;
  page_intro(o, ctx.cfg);
  unconverged_banner(o, summary);
  outlier_banner(o, ctx.cfg, summary);
  headline_table(o, rows);
  case_section(o, ctx.cfg, figures);
  const std::vector<std::pair<std::string, std::string>> sections = {
      {"flow", "Stage 1a: gas flow (OpenFOAM)"},
      {"sample", "Stage 1a: sampled velocity field"},
      {"transport", "Stage 1b: ore lumps through the mill"},
      {"calibrate", "Calibration of the bond model"},
      {"breakage", "Stage 2: breakage of one lump"}};
  const SectionInputs in{run, out_dir, figures, rows, summary, problems};
  for (const auto& [stage, title] : sections) stage_section(o, stage, title, inputs, in);
  damaged_box(ctx, o, problems, summary);
  o << report::page_tail();
  jobs::atomic_write(out_dir / "index.html", o.str());
  jobs::atomic_write(out_dir / "summary.json", summary.dump(2) + "\n");
  ctx.progress.info("[report] " + (out_dir / "index.html").string());
}

}  // namespace mill
