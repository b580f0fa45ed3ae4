// Impact statistics of the transport stage: CSV and dump readers, struck
// parts, strikes and their chains to the housing, statistics.
#include "postprocess/impact_stats.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <tuple>

#include "postprocess/fragments.h"

namespace mill::post {
namespace fs = std::filesystem;

namespace {

// Splits a CSV line at commas (no quoting: the recorder writes none).
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// Parses a whole cell as a number or throws naming file, line and column.
double cell_number(const std::string& text, const std::string& where, const std::string& column) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0')
    throw PostError(fmt::format("{}: column {}: not a number: '{}'", where, column, text));
  return v;
}

// A CSV file with a header line: columns by name, rows with their line number.
struct CsvTable {
  std::string path;
  std::map<std::string, size_t> col;
  struct Row {
    int line = 0;
    std::vector<std::string> cells;
  };
  std::vector<Row> rows;

  bool has(const std::string& c) const { return col.count(c) > 0; }
  // The cell of column c as a number (0 if the file has no such column).
  double num(const Row& r, const std::string& c) const {
    const auto it = col.find(c);
    return it == col.end()
               ? 0.0
               : cell_number(r.cells[it->second], fmt::format("{}:{}", path, r.line), c);
  }
  const std::string& text(const Row& r, const std::string& c) const { return r.cells[col.at(c)]; }
};

// Reads a whole CSV (what: "the impact file"); every row must have the
// header's cell count and the header the columns in need.
CsvTable read_csv_table(const std::string& path, const std::vector<const char*>& need,
                        const std::string& what) {
  std::ifstream in(path);
  if (!in) throw PostError(path + ": cannot open " + what);
  CsvTable t;
  t.path = path;
  std::string line;
  if (!std::getline(in, line)) throw PostError(path + ": empty (no header line)");
  const auto head = split_csv(line);
  for (size_t i = 0; i < head.size(); ++i) t.col[head[i]] = i;
  for (const char* c : need)
    if (!t.has(c)) throw PostError(fmt::format("{}:1: missing column '{}'", path, c));
  int lineno = 1;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty()) continue;
    auto cells = split_csv(line);
    if (cells.size() != head.size())
      throw PostError(
          fmt::format("{}:{}: {} cells, header has {}", path, lineno, cells.size(), head.size()));
    t.rows.push_back({lineno, std::move(cells)});
  }
  return t;
}

constexpr const char* kAxes[3] = {"x", "y", "z"};

}  // namespace

std::vector<ImpactRecord> ReadImpactsCsv(const std::string& path) {
  const CsvTable t = read_csv_table(path,
                                    {"time_s", "particle_id", "surface", "x_m", "speed_m_s",
                                     "normal_speed_m_s", "tangential_speed_m_s", "angle_deg"},
                                    "the impact file");
  std::vector<ImpactRecord> out;
  for (const auto& row : t.rows) {
    ImpactRecord r;
    r.time_s = t.num(row, "time_s");
    r.particle_id = std::llround(t.num(row, "particle_id"));
    r.surface = t.text(row, "surface");
    for (int k = 0; k < 3; ++k) {
      const std::string a = kAxes[k];
      r.position[k] = t.num(row, a + "_m");
      r.contact[k] = t.num(row, "contact_" + a + "_m");
      r.normal[k] = t.num(row, "normal_" + a);
      r.relative_velocity[k] = t.num(row, "vrel_" + a + "_m_s");
    }
    r.speed_m_s = t.num(row, "speed_m_s");
    r.normal_speed_m_s = t.num(row, "normal_speed_m_s");
    r.tangential_speed_m_s = t.num(row, "tangential_speed_m_s");
    r.angle_deg = t.num(row, "angle_deg");
    r.surface_speed_m_s = t.num(row, "surface_speed_m_s");
    r.particle_speed_m_s = t.num(row, "particle_speed_m_s");
    r.axis_distance_m = t.num(row, "axis_distance_m");
    if (t.has("part")) r.part = t.text(row, "part");
    r.sliding = t.num(row, "sliding") != 0.0;
    r.strike = static_cast<int>(t.num(row, "strike"));
    out.push_back(r);
  }
  return out;
}

void WriteImpactsCsv(const std::string& path, const std::vector<ImpactRecord>& records) {
  const std::string tmp = path + ".tmp." + std::to_string(getpid());
  {
    std::ofstream o(tmp);
    if (!o) throw PostError(tmp + ": cannot write");
    o << "time_s,particle_id,surface,x_m,y_m,z_m,contact_x_m,contact_y_m,contact_z_m,"
         "normal_x,normal_y,normal_z,vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,speed_m_s,"
         "normal_speed_m_s,tangential_speed_m_s,angle_deg,surface_speed_m_s,"
         "particle_speed_m_s,axis_distance_m,part,sliding,strike\n";
    for (const auto& r : records) {
      o << fmt::format("{:.9g},{},{}", r.time_s, r.particle_id, r.surface);
      for (const auto* v : {&r.position, &r.contact, &r.normal, &r.relative_velocity})
        for (double x : *v) o << fmt::format(",{:.9g}", x);
      for (double x : {r.speed_m_s, r.normal_speed_m_s, r.tangential_speed_m_s, r.angle_deg,
                       r.surface_speed_m_s, r.particle_speed_m_s, r.axis_distance_m})
        o << fmt::format(",{:.9g}", x);
      o << fmt::format(",{},{},{}\n", r.part, r.sliding ? 1 : 0, r.strike);
    }
    if (!o) throw PostError(tmp + ": write failed");
  }
  fs::rename(tmp, path);
}

std::vector<ContactEnd> ReadContactEndsCsv(const std::string& path) {
  const CsvTable t = read_csv_table(path,
                                    {"time_s", "particle_id", "surface", "start_time_s",
                                     "duration_s", "vx_m_s", "vy_m_s", "vz_m_s", "speed_m_s"},
                                    "the contact-end file");
  std::vector<ContactEnd> out;
  for (const auto& row : t.rows) {
    ContactEnd e;
    e.time_s = t.num(row, "time_s");
    e.particle_id = std::llround(t.num(row, "particle_id"));
    e.surface = t.text(row, "surface");
    e.start_time_s = t.num(row, "start_time_s");
    e.duration_s = t.num(row, "duration_s");
    for (int k = 0; k < 3; ++k) {
      const std::string a = kAxes[k];
      e.position[k] = t.num(row, a + "_m");
      e.velocity[k] = t.num(row, "v" + a + "_m_s");
      e.relative_velocity[k] = t.num(row, "vrel_" + a + "_m_s");
    }
    e.speed_m_s = t.num(row, "speed_m_s");
    e.relative_speed_m_s = t.num(row, "relative_speed_m_s");
    e.normal_speed_m_s = t.num(row, "normal_speed_m_s");
    e.tangential_speed_m_s = t.num(row, "tangential_speed_m_s");
    e.surface_speed_m_s = t.num(row, "surface_speed_m_s");
    out.push_back(e);
  }
  return out;
}

const std::vector<std::string>& PartNames() {
  static const std::vector<std::string> names = {"plate_face", "plate_tip",  "hub",
                                                 "side_cap",   "side_wall",  "floor",
                                                 "roof",       "front_back", "other"};
  return names;
}

std::string ClassifyPart(const ImpactRecord& r, const MillShape& m) {
  const auto& n = r.normal;
  if (r.surface == "flywheel") {
    const double px = r.contact[0] - m.axis_x, py = r.contact[1] - m.axis_y;
    const double rho = std::hypot(px, py);
    const double er[2] = {rho > 0 ? px / rho : 1.0, rho > 0 ? py / rho : 0.0};
    const double nr = std::abs(n[0] * er[0] + n[1] * er[1]);
    const double nt = std::abs(-n[0] * er[1] + n[1] * er[0]);
    if (std::abs(n[2]) >= std::max(nr, nt)) return "side_cap";
    if (nt > nr) return "plate_face";
    return rho > 0.5 * (m.hub_radius + m.tip_radius) ? "plate_tip" : "hub";
  }
  if (r.surface == "housing") {
    const double ax = std::abs(n[0]), ay = std::abs(n[1]), az = std::abs(n[2]);
    if (ay >= ax && ay >= az) return n[1] > 0 ? "floor" : "roof";
    return ax >= az ? "side_wall" : "front_back";
  }
  return "other";
}

namespace {

// Indices of the records ordered by particle, then time (then input order).
std::vector<size_t> by_particle_and_time(const std::vector<ImpactRecord>& records) {
  std::vector<size_t> order(records.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const auto& ra = records[a];
    const auto& rb = records[b];
    return ra.particle_id != rb.particle_id ? ra.particle_id < rb.particle_id
                                            : ra.time_s < rb.time_s;
  });
  return order;
}

}  // namespace

void LabelImpacts(std::vector<ImpactRecord>& records, const MillShape& m,
                  double sliding_threshold_m_s) {
  for (auto& r : records) {
    r.part = ClassifyPart(r, m);
    r.sliding = r.normal_speed_m_s < sliding_threshold_m_s;
    r.strike = 0;
  }
  long long last = std::numeric_limits<long long>::min();
  for (size_t i : by_particle_and_time(records)) {
    auto& r = records[i];
    if (r.surface != "flywheel" || r.sliding) continue;
    r.strike = r.particle_id == last ? 2 : 1;
    last = r.particle_id;
  }
}

std::vector<Strike> StrikeChains(const std::vector<ImpactRecord>& records,
                                 const std::vector<ContactEnd>& ends) {
  // Contact ends by (particle, surface, onset time): the recorder writes the
  // onset time with the digits of the onset row, so they match exactly.
  std::map<std::tuple<long long, std::string, double>, long> end_of;
  for (size_t k = 0; k < ends.size(); ++k)
    end_of[{ends[k].particle_id, ends[k].surface, ends[k].start_time_s}] = static_cast<long>(k);
  std::vector<Strike> out;
  std::map<size_t, size_t> slot;  // record index -> index in out
  const auto order = by_particle_and_time(records);
  for (size_t i = 0; i < records.size(); ++i)
    if (records[i].strike > 0) {
      slot[i] = out.size();
      Strike s;
      s.record = i;
      const auto it = end_of.find({records[i].particle_id, "flywheel", records[i].time_s});
      if (it != end_of.end()) s.end = it->second;
      out.push_back(s);
    }
  // Walk each lump's records in time: a strike waits for the lump's next
  // housing impact after it left the beater, until the lump's next strike.
  long open = -1;  // index in out of the strike waiting for a housing impact
  long long lump = std::numeric_limits<long long>::min();
  for (size_t i : order) {
    const auto& r = records[i];
    if (r.particle_id != lump) {
      open = -1;
      lump = r.particle_id;
    }
    if (r.strike > 0) {
      open = static_cast<long>(slot.at(i));
      continue;
    }
    if (open < 0 || r.surface != "housing" || r.sliding) continue;
    Strike& s = out[open];
    const double left = s.end >= 0 ? ends[s.end].time_s : records[s.record].time_s;
    if (r.time_s < left) continue;  // touched the housing while still on the beater
    s.housing = static_cast<long>(i);
    s.flight_time_s = r.time_s - left;
    open = -1;
  }
  return out;
}

Trajectories ReadTrajectoryDump(const std::string& path, double dt) {
  std::ifstream in(path);
  if (!in) throw PostError(path + ": cannot open the trajectory dump");
  Trajectories t;
  std::string line;
  int lineno = 0;
  long long step = -1, last_step = -2;
  std::vector<int> cols;  // index of id x y z vx vy vz in an atom line
  bool skip = false;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.rfind("ITEM: TIMESTEP", 0) == 0) {
      if (!std::getline(in, line)) break;
      ++lineno;
      step = std::stoll(line);
      skip = step == last_step;  // a run boundary repeats the last snapshot
      last_step = step;
      continue;
    }
    if (line.rfind("ITEM: NUMBER", 0) == 0 || line.rfind("ITEM: BOX", 0) == 0) continue;
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      std::istringstream ls(line.substr(11));
      std::vector<std::string> names;
      std::string n;
      while (ls >> n) names.push_back(n);
      cols.assign(7, -1);
      const char* want[7] = {"id", "x", "y", "z", "vx", "vy", "vz"};
      for (int k = 0; k < 7; ++k)
        for (size_t j = 0; j < names.size(); ++j)
          if (names[j] == want[k]) cols[k] = static_cast<int>(j);
      for (int k = 0; k < 7; ++k)
        if (cols[k] < 0)
          throw PostError(fmt::format("{}:{}: no column '{}'", path, lineno, want[k]));
      continue;
    }
    if (cols.empty() || skip) continue;  // box bounds, counts, repeated snapshots
    std::istringstream ls(line);
    std::vector<double> v;
    double x;
    while (ls >> x) v.push_back(x);
    if (v.size() < 7) continue;
    t.time_s.push_back(static_cast<double>(step) * dt);
    t.particle_id.push_back(std::llround(v[cols[0]]));
    t.position.push_back({v[cols[1]], v[cols[2]], v[cols[3]]});
    t.velocity.push_back({v[cols[4]], v[cols[5]], v[cols[6]]});
  }
  return t;
}

MeanStd mean_std(const std::vector<double>& v) {
  MeanStd m;
  m.n = static_cast<long long>(v.size());
  if (v.empty()) return m;
  double s = 0;
  for (double x : v) s += x;
  m.mean = s / v.size();
  if (v.size() > 1) {
    double q = 0;
    for (double x : v) q += (x - m.mean) * (x - m.mean);
    m.std = std::sqrt(q / (v.size() - 1));
  }
  return m;
}

TransportStats ComputeTransportStats(const std::vector<ImpactRecord>& records,
                                     const std::vector<double>& insert_time_s,
                                     const std::vector<ContactEnd>& ends) {
  TransportStats s;
  s.n_particles = static_cast<long long>(insert_time_s.size());
  const size_t n = insert_time_s.size();
  s.impacts_per_particle.assign(n, 0);
  s.flywheel_impacts_per_particle.assign(n, 0);
  s.first_impact_time_s.assign(n, std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k < n; ++k) s.ids.push_back(static_cast<long long>(k + 1));
  std::map<std::string, std::vector<std::vector<double>>> cols;  // surface -> 6 lists
  for (const auto& r : records) {
    if (r.particle_id < 1 || r.particle_id > s.n_particles)
      throw PostError(
          fmt::format("impact of particle {} at t = {} s: only {} particles were inserted",
                      r.particle_id, r.time_s, s.n_particles));
    if (r.sliding) {  // not an impact: counted apart
      ++s.sliding[r.surface];
      ++s.sliding_contacts;
      continue;
    }
    if (!r.part.empty()) ++s.impacts_per_part[r.part];
    const size_t k = static_cast<size_t>(r.particle_id - 1);
    ++s.impacts_per_particle[k];
    if (r.surface == "flywheel") ++s.flywheel_impacts_per_particle[k];
    const double since = r.time_s - insert_time_s[k];
    if (std::isnan(s.first_impact_time_s[k]) || since < s.first_impact_time_s[k])
      s.first_impact_time_s[k] = since;
    auto& c = cols[r.surface];
    c.resize(6);
    c[0].push_back(r.speed_m_s);
    c[1].push_back(r.normal_speed_m_s);
    c[2].push_back(r.tangential_speed_m_s);
    c[3].push_back(r.angle_deg);
    c[4].push_back(r.particle_speed_m_s);
    c[5].push_back(r.axis_distance_m);
  }
  for (const char* name : {"flywheel", "housing"}) {
    cols[name].resize(6);
    s.sliding[name] += 0;
  }
  for (const auto& [name, c] : cols) {
    SurfaceStats ss;
    ss.n = static_cast<long long>(c[0].size());
    ss.speed = mean_std(c[0]);
    ss.normal_speed = mean_std(c[1]);
    ss.tangential_speed = mean_std(c[2]);
    ss.angle = mean_std(c[3]);
    ss.particle_speed = mean_std(c[4]);
    ss.axis_distance = mean_std(c[5]);
    s.surfaces[name] = ss;
  }
  if (n > 0) {
    double a = 0, f = 0, t = 0;
    for (size_t k = 0; k < n; ++k) {
      a += s.impacts_per_particle[k];
      f += s.flywheel_impacts_per_particle[k];
      if (!std::isnan(s.first_impact_time_s[k])) {
        t += s.first_impact_time_s[k];
        ++s.particles_with_impact;
      }
    }
    s.impacts_per_particle_mean = a / n;
    s.flywheel_impacts_per_particle_mean = f / n;
    s.first_impact_time_mean_s = s.particles_with_impact ? t / s.particles_with_impact : 0.0;
  }

  // Beater strikes, what the lump does as it leaves, and its next housing impact.
  s.chains = StrikeChains(records, ends);
  std::vector<double> first, later, lab, normal, duration, hs, ha, ht;
  for (const auto& c : s.chains) {
    const auto& r = records[c.record];
    (r.strike == 1 ? first : later).push_back(r.speed_m_s);
    if (c.end >= 0) {
      const auto& e = ends[static_cast<size_t>(c.end)];
      lab.push_back(e.speed_m_s);
      if (std::isfinite(e.normal_speed_m_s)) normal.push_back(e.normal_speed_m_s);
      duration.push_back(e.duration_s);
    }
    if (c.housing >= 0) {
      const auto& h = records[static_cast<size_t>(c.housing)];
      hs.push_back(h.speed_m_s);
      ha.push_back(h.angle_deg);
      ht.push_back(c.flight_time_s);
    }
  }
  StrikeStats& k = s.strikes;
  k.n_first = static_cast<long long>(first.size());
  k.n_later = static_cast<long long>(later.size());
  k.first_speed = mean_std(first);
  k.later_speed = mean_std(later);
  k.n_with_end = static_cast<long long>(lab.size());
  k.rebound_speed_lab = mean_std(lab);
  k.rebound_normal_speed = mean_std(normal);
  k.contact_duration = mean_std(duration);
  k.n_to_housing = static_cast<long long>(hs.size());
  k.housing_speed = mean_std(hs);
  k.housing_angle = mean_std(ha);
  k.flight_time = mean_std(ht);
  return s;
}

}  // namespace mill::post
