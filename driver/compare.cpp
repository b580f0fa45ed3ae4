// orchestrate compare; see compare.h.
#include "compare.h"

#include <fmt/format.h>

#include <map>
#include <set>
#include <sstream>

#include "config/case_config.h"
#include "engine/runner.h"
#include "jobs/job_store.h"
#include "report/headline.h"
#include "report/html.h"

namespace mill {
namespace fs = std::filesystem;

void check_compare_runs(const std::vector<fs::path>& runs) {
  if (runs.size() < 2)
    throw config::ConfigError(fmt::format(
        "compare: expected at least two run folders, got {}; e.g. orchestrate compare runs/default runs/granite",
        runs.size()));
  std::set<fs::path> seen;
  for (const auto& r : runs) {
    if (!fs::is_directory(r))
      throw config::ConfigError(fmt::format("compare: {}: no such run folder", r.string()));
    if (!seen.insert(fs::canonical(r)).second)
      throw config::ConfigError(fmt::format("compare: {}: given twice; compare different runs", r.string()));
    const auto s = report::read_json(r / "report" / "summary.json");
    if (!s.is_object() || !s.contains("headline"))
      throw config::ConfigError(fmt::format(
          "compare: {}: not a finished run (no readable report/summary.json); finish it with "
          "`orchestrate --case <its case> --stage all --output {}` (or `--stage report` if its stages are done)",
          r.string(), r.string()));
  }
}

std::string write_compare(const CompareOptions& opt) {
  check_compare_runs(opt.runs);
  // Column labels: the case name, with the folder when two runs share it.
  std::vector<std::string> labels;
  std::map<std::string, int> count;
  for (const auto& r : opt.runs) {
    const auto s = report::read_json(r / "report" / "summary.json");
    labels.push_back(s.value("case", r.filename().string()));
    ++count[labels.back()];
  }
  for (size_t i = 0; i < labels.size(); ++i)
    if (count[labels[i]] > 1) labels[i] += " (" + opt.runs[i].string() + ")";

  // Rows in the order first met, one column per run.
  std::vector<std::pair<std::string, std::string>> keys;  // (group, what)
  std::map<std::pair<std::string, std::string>, std::vector<std::string>> cells;
  std::vector<std::string> ores;
  for (size_t i = 0; i < opt.runs.size(); ++i) {
    const auto s = report::read_json(opt.runs[i] / "report" / "summary.json");
    ores.push_back(s.value("ore", std::string("?")));
    for (const auto& row : report::headline_rows(report::headline_json(opt.runs[i]))) {
      const auto k = std::make_pair(row.group, row.what);
      auto& c = cells[k];
      if (c.empty()) {
        keys.push_back(k);
        c.assign(opt.runs.size(), "-");
      }
      c[i] = row.value;
    }
  }
  // Keep the stage groups in pipeline order.
  std::vector<std::pair<std::string, std::string>> ordered;
  for (const auto& g : report::headline_groups())
    for (const auto& k : keys)
      if (k.first == g.title) ordered.push_back(k);

  fs::create_directories(opt.output / "figures");
  const fs::path png = opt.output / "figures" / "compare_passing.png";
  fs::remove(png);
  std::vector<std::string> args = {"--out", png.string()};
  for (size_t i = 0; i < opt.runs.size(); ++i) {
    args.push_back("--run");
    args.push_back(labels[i] + "=" + fs::absolute(opt.runs[i]).string());
  }
  engine::Runner runner;
  engine::run_python(runner, opt.project_dir / "postprocess" / "plot_compare.py", args,
                     opt.output / "plot_compare.log", "compare/plot");

  using report::esc;
  std::ostringstream o;
  o << report::page_head("Beater mill: comparison of " + std::to_string(opt.runs.size()) + " runs");
  o << "<h1>Beater mill: " << opt.runs.size() << " runs side by side</h1>\n<table class=headline><tr><th></th>";
  for (const auto& l : labels) o << "<th>" << esc(l) << "</th>";
  o << "</tr>\n<tr><td>ore</td>";
  for (const auto& ore : ores) o << "<td>" << esc(ore) << "</td>";
  o << "</tr>\n<tr><td>run folder and its report</td>";
  for (const auto& r : opt.runs) {
    const fs::path page = fs::relative(fs::absolute(r) / "report" / "index.html", fs::absolute(opt.output));
    o << "<td><a href=\"" << esc(page.string()) << "\">" << esc(r.string()) << "</a></td>";
  }
  o << "</tr>\n";
  std::string group;
  for (const auto& k : ordered) {
    if (k.first != group)
      o << "<tr class=group><th colspan=" << opt.runs.size() + 1 << ">" << esc(k.first) << "</th></tr>\n";
    group = k.first;
    o << "<tr><td>" << esc(k.second) << "</td>";
    for (const auto& v : cells[k]) o << "<td>" << esc(v) << "</td>";
    o << "</tr>\n";
  }
  o << "</table>\n<h2>Product size distributions</h2>\n";
  report::embed_png(o, png, "cumulative % passing against size (mm): the mill product per rotor speed, or each "
                            "impact condition of a sweep");
  o << "<p class=note>A run with conditions from the transport stage draws its mill product per rotor speed (solid); "
       "a velocity sweep draws each impact condition, averaged over repeats (thin, dashed). Sizes are d/D x the "
       "lump diameter; P80 is interpolated log-linearly between sieves.</p>\n";
  o << report::page_tail();
  const fs::path html = opt.output / "index.html";
  jobs::atomic_write(html, o.str());
  return fmt::format("compare: {} runs -> {}\n", opt.runs.size(), html.string());
}

}  // namespace mill
