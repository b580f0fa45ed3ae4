// Impact statistics of the transport stage: CSV and dump readers, statistics,
// transport.h5.
#include "postprocess/impact_stats.h"

#include <fmt/format.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

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

// Owns an HDF5 id and closes it with the matching close function.
class H5Handle {
 public:
  H5Handle(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw PostError("HDF5: cannot " + what);
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  ~H5Handle() {
    if (id_ >= 0) close_(id_);
  }
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Attaches a string attribute.
void attr_string(hid_t obj, const std::string& name, const std::string& value) {
  H5Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "copy string type");
  H5Tset_size(type, std::max<size_t>(1, value.size()));
  H5Tset_strpad(type, H5T_STR_NULLTERM);
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create scalar space");
  H5Handle a(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
             "create attribute " + name);
  std::string padded = value.empty() ? std::string(1, '\0') : value;
  if (H5Awrite(a, type, padded.data()) < 0) throw PostError("HDF5: cannot write attribute " + name);
}

// Attaches a scalar double attribute.
void attr_double(hid_t obj, const std::string& name, double value) {
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create scalar space");
  H5Handle a(H5Acreate2(obj, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose, "create attribute " + name);
  if (H5Awrite(a, H5T_NATIVE_DOUBLE, &value) < 0)
    throw PostError("HDF5: cannot write attribute " + name);
}

// Writes a dataset of n rows x cols values (cols 1: a vector) with a unit.
template <typename T>
void dataset(hid_t group, const std::string& name, const std::vector<T>& v, int cols,
             const std::string& unit, hid_t file_type, hid_t mem_type) {
  hsize_t dims[2] = {static_cast<hsize_t>(v.size() / cols), static_cast<hsize_t>(cols)};
  H5Handle space(H5Screate_simple(cols == 1 ? 1 : 2, dims, nullptr), H5Sclose,
                 "create space for " + name);
  H5Handle d(
      H5Dcreate2(group, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose, "create dataset " + name);
  if (!v.empty() && H5Dwrite(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
    throw PostError("HDF5: cannot write dataset " + name);
  attr_string(d, "unit", unit);
}
void doubles(hid_t g, const std::string& name, const std::vector<double>& v, int cols,
             const std::string& unit) {
  dataset(g, name, v, cols, unit, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE);
}
void integers(hid_t g, const std::string& name, const std::vector<long long>& v,
              const std::string& unit) {
  dataset(g, name, v, 1, unit, H5T_STD_I64LE, H5T_NATIVE_LLONG);
}

// Flattens a list of 3-vectors.
std::vector<double> flat3(const std::vector<std::array<double, 3>>& v) {
  std::vector<double> out;
  out.reserve(3 * v.size());
  for (const auto& a : v) out.insert(out.end(), a.begin(), a.end());
  return out;
}

}  // namespace

std::vector<ImpactRecord> ReadImpactsCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PostError(path + ": cannot open the impact file");
  std::string line;
  if (!std::getline(in, line)) throw PostError(path + ": empty (no header line)");
  const auto head = split_csv(line);
  std::map<std::string, size_t> col;
  for (size_t i = 0; i < head.size(); ++i) col[head[i]] = i;
  for (const char* need : {"time_s", "particle_id", "surface", "x_m", "speed_m_s",
                           "normal_speed_m_s", "tangential_speed_m_s", "angle_deg"})
    if (!col.count(need)) throw PostError(fmt::format("{}:1: missing column '{}'", path, need));
  std::vector<ImpactRecord> out;
  int lineno = 1;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty()) continue;
    const auto cells = split_csv(line);
    if (cells.size() != head.size())
      throw PostError(
          fmt::format("{}:{}: {} cells, header has {}", path, lineno, cells.size(), head.size()));
    const std::string where = fmt::format("{}:{}", path, lineno);
    auto get = [&](const std::string& c) {
      return col.count(c) ? cell_number(cells[col[c]], where, c) : 0.0;
    };
    ImpactRecord r;
    r.time_s = get("time_s");
    r.particle_id = std::llround(get("particle_id"));
    r.surface = cells[col["surface"]];
    const char* ax[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      r.position[k] = get(std::string(ax[k]) + "_m");
      r.contact[k] = get("contact_" + std::string(ax[k]) + "_m");
      r.normal[k] = get("normal_" + std::string(ax[k]));
      r.relative_velocity[k] = get("vrel_" + std::string(ax[k]) + "_m_s");
    }
    r.speed_m_s = get("speed_m_s");
    r.normal_speed_m_s = get("normal_speed_m_s");
    r.tangential_speed_m_s = get("tangential_speed_m_s");
    r.angle_deg = get("angle_deg");
    r.surface_speed_m_s = get("surface_speed_m_s");
    r.particle_speed_m_s = get("particle_speed_m_s");
    r.axis_distance_m = get("axis_distance_m");
    out.push_back(r);
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
                                     const std::vector<double>& insert_time_s) {
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
  for (const char* name : {"flywheel", "housing"}) cols[name].resize(6);
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
  return s;
}

void WriteTransportH5(const std::string& path, const std::vector<ImpactRecord>& records,
                      const TransportStats& stats, const std::vector<double>& insert_time_s,
                      const Trajectories& traj, const TransportMeta& meta) {
  const std::string tmp = path + ".tmp." + std::to_string(getpid());
  {
    H5Handle f(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
               "create " + tmp);
    attr_string(
        f, "content",
        "transport stage: impacts on flywheel and housing, per-particle counts, trajectories");
    for (const auto& [k, v] : meta.scalars) {
      attr_double(f, k, v);
      const auto u = meta.units.find(k);
      if (u != meta.units.end() && !u->second.empty()) attr_string(f, k + "_unit", u->second);
    }
    // Impacts.
    {
      H5Handle g(H5Gcreate2(f, "impacts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                 "create /impacts");
      std::vector<double> t, speed, vn, vt, ang, ws, vp, ra;
      std::vector<long long> id, code;
      std::vector<std::array<double, 3>> pos, con, nrm, vr;
      for (const auto& r : records) {
        t.push_back(r.time_s);
        id.push_back(r.particle_id);
        code.push_back(r.surface == "flywheel" ? 0 : r.surface == "housing" ? 1 : 2);
        pos.push_back(r.position);
        con.push_back(r.contact);
        nrm.push_back(r.normal);
        vr.push_back(r.relative_velocity);
        speed.push_back(r.speed_m_s);
        vn.push_back(r.normal_speed_m_s);
        vt.push_back(r.tangential_speed_m_s);
        ang.push_back(r.angle_deg);
        ws.push_back(r.surface_speed_m_s);
        vp.push_back(r.particle_speed_m_s);
        ra.push_back(r.axis_distance_m);
      }
      attr_string(g, "surface_codes", "0 = flywheel, 1 = housing, 2 = other");
      doubles(g, "time", t, 1, "s");
      integers(g, "particle_id", id, "1");
      integers(g, "surface", code, "1");
      doubles(g, "position", flat3(pos), 3, "m");
      doubles(g, "contact_point", flat3(con), 3, "m");
      doubles(g, "normal", flat3(nrm), 3, "1");
      doubles(g, "relative_velocity", flat3(vr), 3, "m/s");
      doubles(g, "speed", speed, 1, "m/s");
      doubles(g, "normal_speed", vn, 1, "m/s");
      doubles(g, "tangential_speed", vt, 1, "m/s");
      doubles(g, "angle", ang, 1, "deg");
      doubles(g, "surface_speed", ws, 1, "m/s");
      doubles(g, "particle_speed", vp, 1, "m/s");
      doubles(g, "axis_distance", ra, 1, "m");
    }
    // Per particle.
    {
      H5Handle g(H5Gcreate2(f, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                 "create /particles");
      integers(g, "id", stats.ids, "1");
      doubles(g, "insert_time", insert_time_s, 1, "s");
      integers(g, "n_impacts", stats.impacts_per_particle, "1");
      integers(g, "n_flywheel_impacts", stats.flywheel_impacts_per_particle, "1");
      doubles(g, "first_impact_time", stats.first_impact_time_s, 1, "s");
    }
    // Trajectories.
    {
      H5Handle g(H5Gcreate2(f, "trajectories", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                 "create /trajectories");
      std::vector<double> speed;
      for (const auto& v : traj.velocity)
        speed.push_back(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
      doubles(g, "time", traj.time_s, 1, "s");
      integers(g, "particle_id", traj.particle_id, "1");
      doubles(g, "position", flat3(traj.position), 3, "m");
      doubles(g, "velocity", flat3(traj.velocity), 3, "m/s");
      doubles(g, "speed", speed, 1, "m/s");
    }
    {
      H5Handle g(H5Gcreate2(f, "geometry", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                 "create /geometry");
      attr_string(g, "length_unit", "m");
      for (const auto& [k, v] : meta.geometry) attr_double(g, k, v);
    }
  }
  fs::rename(tmp, path);
}

}  // namespace mill::post
