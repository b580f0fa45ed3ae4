// Start states and run records of in-mill breakage.
#include "postprocess/in_mill.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace mill::post {

std::vector<StrikeStart> SelectStrikeStarts(const std::vector<ImpactRecord>& records, int k,
                                            double lead_time_s, const RotorMotion& rotor,
                                            double min_normal_m_s) {
  if (k < 1) throw PostError(fmt::format("lumps to select must be >= 1, got {}", k));
  if (!(lead_time_s >= 0))
    throw PostError(fmt::format("lead time must be >= 0 s, got {:g}", lead_time_s));
  // Each particle's earliest flywheel strike.
  std::map<long long, const ImpactRecord*> first;
  for (const auto& r : records) {
    if (r.surface != "flywheel" || r.normal_speed_m_s < min_normal_m_s) continue;
    auto it = first.find(r.particle_id);
    if (it == first.end() || r.time_s < it->second->time_s) first[r.particle_id] = &r;
  }
  if (first.empty())
    throw PostError(fmt::format(
        "no lump struck the flywheel (no flywheel contact with a normal speed of at least "
        "{:g} m/s)",
        min_normal_m_s));
  std::vector<const ImpactRecord*> strikes;
  for (const auto& [id, r] : first) strikes.push_back(r);
  for (const auto* r : strikes)
    if (r->contact == std::array<double, 3>{0, 0, 0} &&
        r->relative_velocity == std::array<double, 3>{0, 0, 0})
      throw PostError(fmt::format(
          "the flywheel strike of particle {} at t = {:g} s has no contact point or relative "
          "velocity (impacts.csv without contact_*_m and vrel_*_m_s columns: rerun the "
          "transport stage)",
          r->particle_id, r->time_s));
  std::stable_sort(strikes.begin(), strikes.end(),
                   [](const ImpactRecord* a, const ImpactRecord* b) {
                     if (a->normal_speed_m_s != b->normal_speed_m_s)
                       return a->normal_speed_m_s < b->normal_speed_m_s;
                     return a->time_s < b->time_s;
                   });
  std::vector<const ImpactRecord*> chosen;
  const size_t n = strikes.size();
  if (static_cast<size_t>(k) >= n) {
    chosen = strikes;
  } else {
    for (int i = 0; i < k; ++i)
      chosen.push_back(
          strikes[std::min(n - 1, static_cast<size_t>((i + 0.5) * static_cast<double>(n) / k))]);
  }

  std::vector<StrikeStart> out;
  const double w = rotor.omega_rad_s, g = rotor.gravity_m_s2, t = lead_time_s;
  for (const auto* r : chosen) {
    StrikeStart s;
    s.particle_id = r->particle_id;
    s.strike_time_s = r->time_s;
    s.start_time_s = r->time_s - t;
    // Lab velocity: relative velocity plus the beater's Omega x r (axis +z).
    const double rx = r->contact[0] - rotor.origin[0], ry = r->contact[1] - rotor.origin[1];
    const std::array<double, 3> v = {r->relative_velocity[0] - w * ry,
                                     r->relative_velocity[1] + w * rx, r->relative_velocity[2]};
    // Ballistic back-off under gravity (along -y): v0 = v - g_vec t,
    // x0 = x - v t + g_vec t^2 / 2.
    s.velocity = {v[0], v[1] + g * t, v[2]};
    s.position = {r->position[0] - v[0] * t, r->position[1] - v[1] * t - 0.5 * g * t * t,
                  r->position[2] - v[2] * t};
    double a = std::fmod(w * s.start_time_s, 2 * kPi);
    if (a < 0) a += 2 * kPi;
    s.rotor_angle_rad = a;
    s.strike_speed_m_s = r->speed_m_s;
    s.strike_normal_speed_m_s = r->normal_speed_m_s;
    s.strike_angle_deg = r->angle_deg;
    out.push_back(s);
  }
  std::sort(out.begin(), out.end(), [](const StrikeStart& a, const StrikeStart& b) {
    return a.particle_id < b.particle_id;
  });
  return out;
}

std::vector<BreakEvent> ReadBreakLog(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PostError(path + ": cannot open the break log");
  std::vector<BreakEvent> out;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    double step = 0, x = 0, y = 0, z = 0, ti = 0, tj = 0;
    std::string mode;
    BreakEvent e;
    if (!(ls >> step >> e.time_s >> x >> y >> z >> mode >> ti >> tj))
      throw PostError(fmt::format(
          "{}:{}: expected 'step time x y z mode tag_i tag_j ...', got '{}'", path, lineno, line));
    e.i = std::llround(ti);
    e.j = std::llround(tj);
    out.push_back(e);
  }
  return out;
}

BreakSplit SplitBreaks(const std::vector<BreakEvent>& breaks,
                       const std::vector<ImpactRecord>& contacts) {
  BreakSplit s;
  for (const auto& c : contacts) {
    if (c.surface != "flywheel" && c.surface != "housing") continue;
    double& t = c.surface == "flywheel" ? s.first_flywheel_contact_s : s.first_housing_contact_s;
    if (t < 0 || c.time_s < t) t = c.time_s;
  }
  for (const auto& b : breaks) {
    const bool struck = s.first_flywheel_contact_s >= 0 && b.time_s >= s.first_flywheel_contact_s;
    const bool before_housing =
        s.first_housing_contact_s < 0 || b.time_s < s.first_housing_contact_s;
    ++(struck && before_housing ? s.at_strike : s.later);
  }
  return s;
}

ContactTally TallyContacts(const std::vector<ImpactRecord>& contacts, const std::string& surface) {
  ContactTally t;
  std::set<long long> ids;
  double sum = 0;
  for (const auto& c : contacts) {
    if (c.surface != surface) continue;
    ++t.n;
    ids.insert(c.particle_id);
    sum += c.normal_speed_m_s;
    t.normal_speed_max_m_s = std::max(t.normal_speed_max_m_s, c.normal_speed_m_s);
  }
  t.n_elements = static_cast<long long>(ids.size());
  t.normal_speed_mean_m_s = t.n > 0 ? sum / static_cast<double>(t.n) : 0.0;
  return t;
}

MassPlaces LocateMass(const std::vector<Element>& elements, const MillRegions& g) {
  MassPlaces m;
  double total = 0;
  for (const auto& e : elements) {
    total += e.mass;
    const double r = std::hypot(e.x[0] - g.axis_x, e.x[1] - g.axis_y);
    if (e.x[1] < g.floor_y)
      m.outlet += e.mass;
    else if (e.x[1] > g.roof_y)
      m.inlet += e.mass;
    else if (r <= g.tip_radius && std::abs(e.x[2]) <= g.half_width_z)
      m.rotor += e.mass;
    else
      m.housing += e.mass;
  }
  if (total > 0)
    for (double* v : {&m.rotor, &m.housing, &m.outlet, &m.inlet}) *v /= total;
  return m;
}

InMillStop ReadInMillStop(const std::string& log_path) {
  std::ifstream in(log_path);
  if (!in) throw PostError(log_path + ": cannot open the LIGGGHTS log");
  InMillStop stop;
  bool found = false;
  std::string line;
  const std::string head = "in_mill: stopped at t = ";
  while (std::getline(in, line)) {
    if (line.rfind(head, 0) != 0) continue;
    std::istringstream ls(line.substr(head.size()));
    double t = 0;
    std::string unit, reason;
    if (!(ls >> t >> unit >> reason) || unit != "s" || reason.size() < 3 || reason.front() != '(' ||
        reason.back() != ')')
      throw PostError(fmt::format("{}: expected '{}T s (REASON)', got '{}'", log_path, head, line));
    stop.time_s = t;
    stop.reason = reason.substr(1, reason.size() - 2);
    found = true;
  }
  if (!found)
    throw PostError(fmt::format("{}: no '{}T s (REASON)' line: the in-mill deck did not finish",
                                log_path, head));
  return stop;
}

}  // namespace mill::post
