// Reading OpenFOAM's output of a flow case (docs/flow.md, "flow_report.json").
#include "stages/flow/foam_results.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

namespace mill::flow {
namespace fs = std::filesystem;

namespace {

// Last line of a .dat file that is not a header ('#'); "" if none.
std::string last_data_text(const fs::path& file) {
  std::ifstream in(file);
  std::string l, last;
  while (std::getline(in, l))
    if (!l.empty() && l[0] != '#') last = l;
  return last;
}

// The leading numbers of a data line, brackets ignored: "1 (2 3 4)" -> 1 2 3 4.
std::vector<double> numbers_of(std::string line) {
  for (char& c : line)
    if (c == '(' || c == ')') c = ' ';
  std::istringstream ss(line);
  std::vector<double> v;
  double x;
  while (ss >> x) v.push_back(x);
  return v;
}

// True when f is the output file wanted: `ext` is an extension (".dat") or a
// file name ("moment.dat").
bool is_output_file(const fs::path& f, const std::string& ext) {
  return ext.rfind('.', 0) == 0 ? f.extension() == ext : f.filename() == ext;
}

// The single .dat (or given-name) file of a function object's output, newest time folder.
fs::path function_object_file(const fs::path& case_dir, const std::string& fo,
                              const std::string& ext) {
  const fs::path root = case_dir / "postProcessing" / fo;
  fs::path best;
  double best_t = -1;
  if (!fs::exists(root)) return best;
  for (const auto& t : fs::directory_iterator(root)) {
    if (!t.is_directory()) continue;
    double tv = 0;
    try {
      tv = std::stod(t.path().filename().string());
    } catch (...) {
      continue;
    }
    for (const auto& f : fs::directory_iterator(t.path()))
      if (is_output_file(f.path(), ext) && tv >= best_t) {
        best = f.path();
        best_t = tv;
      }
  }
  return best;
}

}  // namespace

// Incremental-free parse of the whole log (logs are small: ~12 lines/iteration).
SolverLog parse_solver_log(const fs::path& log) {
  SolverLog s;
  std::ifstream in(log);
  std::string l;
  static const std::regex time_re("^Time = ([0-9.eE+-]+)\\s*$");
  static const std::regex res_re("Solving for (\\w+), Initial residual = ([^,]+),");
  std::smatch m;
  std::set<std::string> seen;  // fields already solved in this iteration
  while (std::getline(in, l)) {
    if (l.rfind("Time = ", 0) == 0 && std::regex_match(l, m, time_re)) {
      s.iterations = static_cast<int>(std::lround(std::stod(m[1])));
      seen.clear();
    } else if (l.find("Solving for") != std::string::npos && std::regex_search(l, m, res_re)) {
      const std::string field = m[1];
      // Only the first solve of a field per iteration counts (as in
      // residualControl); later ones are non-orthogonal correctors.
      if (!seen.insert(field).second) continue;
      const std::string v = m[2];
      double r = 0;
      if (v.find("nan") != std::string::npos || v.find("inf") != std::string::npos) {
        s.nan = true;
        r = INFINITY;
      } else {
        r = std::stod(v);
      }
      s.initial_residual[field] = r;
      if (field == "p" || field == "Ux" || field == "Uy" || field == "Uz")
        s.max_initial_residual_pU = std::max(s.max_initial_residual_pU, r);
    } else if (l.rfind("ExecutionTime = ", 0) == 0) {
      s.cpu_seconds = std::atof(l.c_str() + 16);
    } else if (l.find("solution converged in") != std::string::npos) {
      s.converged = true;
    } else if (l.find("sigFpe") != std::string::npos ||
               l.find("Floating point exception") != std::string::npos) {
      s.fpe = true;
    }
  }
  return s;
}

// p's residual, as the progress line and the divergence check show it.
double p_residual(const SolverLog& s) {
  return s.initial_residual.count("p") ? s.initial_residual.at("p") : NAN;
}

// U's residual: its worst component.
double u_residual(const SolverLog& s) {
  double u = 0;
  for (const char* c : {"Ux", "Uy", "Uz"})
    if (s.initial_residual.count(c)) u = std::max(u, s.initial_residual.at(c));
  return u;
}

// A log or report, read whole.
std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A count of checkMesh's mesh stats.
long checkmesh_count(const std::string& text, const std::string& key) {
  std::smatch m;
  std::regex re("\\n\\s*" + key + ":\\s+([0-9]+)");
  if (std::regex_search(text, m, re)) return std::stol(m[1]);
  return -1;
}

// A patch's face count in checkMesh's patch table.
long checkmesh_patch_faces(const std::string& text, const std::string& patch) {
  std::smatch m;
  std::regex re("\\n\\s*" + patch + "\\s+([0-9]+)\\s+[0-9]+");
  if (std::regex_search(text, m, re)) return std::stol(m[1]);
  return -1;
}

// One column's history over a (possibly restarted) solve.
std::vector<std::pair<double, double>> function_object_series(const fs::path& case_dir,
                                                              const std::string& fo,
                                                              const std::string& ext, size_t col) {
  std::map<double, double> by_time;
  const fs::path root = case_dir / "postProcessing" / fo;
  if (!fs::exists(root)) return {};
  for (const auto& t : fs::directory_iterator(root)) {
    if (!t.is_directory()) continue;
    for (const auto& f : fs::directory_iterator(t.path())) {
      if (!is_output_file(f.path(), ext)) continue;
      std::ifstream in(f.path());
      std::string l;
      while (std::getline(in, l)) {
        if (l.empty() || l[0] == '#') continue;
        const std::vector<double> v = numbers_of(l);
        if (v.size() > col) by_time[v[0]] = v[col];
      }
    }
  }
  return {by_time.begin(), by_time.end()};
}

// A function object's figures at the last iteration.
std::vector<std::string> last_values(const fs::path& case_dir, const std::string& fo) {
  std::istringstream ss(last_data_text(function_object_file(case_dir, fo, ".dat")));
  std::vector<std::string> out;
  std::string w;
  while (ss >> w) out.push_back(w);
  return out;
}

// y+ on the walls, per patch.
nlohmann::json read_yplus(const fs::path& case_dir) {
  nlohmann::json out = nlohmann::json::object();
  const fs::path f = function_object_file(case_dir, "yPlus", ".dat");
  if (f.empty()) return out;
  std::ifstream in(f);
  std::string l;
  while (std::getline(in, l)) {
    if (l.empty() || l[0] == '#') continue;
    std::istringstream ss(l);
    std::string t, patch;
    double mn, mx, av;
    if (ss >> t >> patch >> mn >> mx >> av)
      out[patch] = {{"min", mn}, {"max", mx}, {"average", av}};
  }
  return out;
}

// An opening's area, as OpenFOAM summed it.
double read_patch_area(const fs::path& case_dir, const std::string& fo) {
  const auto f = function_object_file(case_dir, fo, ".dat");
  std::ifstream in(f);
  std::string l;
  while (std::getline(in, l))
    if (l.rfind("# Area", 0) == 0 && l.find(':') != std::string::npos)
      return std::stod(l.substr(l.find(':') + 1));
  return NAN;
}

// An opening's flux at the last iteration.
double read_flux(const fs::path& case_dir, const std::string& fo) {
  const auto v = last_values(case_dir, fo);
  return v.size() >= 2 ? std::stod(v[1]) : NAN;
}

// The last line of the forces function object's moment.dat: "time total_x
// total_y total_z pressure_x ... viscous_z".
std::vector<double> read_moment(const fs::path& case_dir) {
  const auto f = function_object_file(case_dir, "flywheelForces", "moment.dat");
  if (f.empty()) return {};
  const std::vector<double> v = numbers_of(last_data_text(f));
  if (v.size() < 4) return {};
  return {v[1], v[2], v[3]};
}

// The gas speed near the rim against the tip speed.
nlohmann::json read_rim(const fs::path& case_dir, const geometry::MillGeometry& g, double omega) {
  const auto f = function_object_file(case_dir, "rimSpeed", ".xy");
  nlohmann::json out;
  if (f.empty()) return out;
  std::ifstream in(f);
  double x, y, z, ux, uy, uz, sum_mag = 0, sum_tan = 0, r_sum = 0, z_sum = 0;
  int n = 0;
  while (in >> x >> y >> z >> ux >> uy >> uz) {
    const double dx = x - g.axis_x, dy = y - g.axis_height, r = std::hypot(dx, dy);
    if (r <= 0) continue;
    sum_mag += std::sqrt(ux * ux + uy * uy + uz * uz);
    sum_tan += (-dy * ux + dx * uy) / r;  // positive along the rotation (anticlockwise about +z)
    r_sum += r;
    z_sum += z;
    ++n;
  }
  if (n == 0) return out;
  const double rim_speed = omega * g.tip_radius();
  out["radius_m"] = r_sum / n;
  out["z_m"] = z_sum / n;
  out["points"] = n;
  out["tip_speed_m_s"] = rim_speed;
  out["gas_speed_mean_m_s"] = sum_mag / n;
  out["gas_tangential_mean_m_s"] = sum_tan / n;
  out["ratio_speed_to_tip_speed"] = rim_speed > 0 ? sum_mag / n / rim_speed : 0.0;
  return out;
}

}  // namespace mill::flow
