// transport.h5, the results file of the transport stage: each table (impacts,
// contact ends, strikes) declared once as a list of columns, written by one
// function.
#include "postprocess/transport_h5.h"

#include <fmt/format.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "postprocess/fragments.h"
#include "postprocess/h5_util.h"

namespace mill::post {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Attaches a scalar double attribute.
void attr_double(hid_t obj, const std::string& name, double value) {
  h5::WriteAttr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

// Writes a float64 dataset of n rows x cols values (cols 1: a vector) with a unit.
void doubles(hid_t g, const std::string& name, const std::vector<double>& v, int cols,
             const std::string& unit) {
  const hsize_t rows = v.size() / static_cast<size_t>(cols);
  std::vector<hsize_t> dims = {rows};
  if (cols != 1) dims.push_back(static_cast<hsize_t>(cols));
  h5::WriteDataset(g, name, v, dims, unit);
}

// Writes an int64 vector dataset with a unit.
void integers(hid_t g, const std::string& name, const std::vector<long long>& v,
              const std::string& unit) {
  h5::WriteDataset(g, name, v, {v.size()}, unit);
}

// Flattens a list of 3-vectors.
std::vector<double> flat3(const std::vector<std::array<double, 3>>& v) {
  std::vector<double> out;
  out.reserve(3 * v.size());
  for (const auto& a : v) out.insert(out.end(), a.begin(), a.end());
  return out;
}

// One column of a table: the dataset name, its unit, the value of a row
// (exactly one getter: float64, int64, or float64 n x 3) and, for integer
// codes, what they mean (the group attribute <name>_codes).
template <typename Row>
struct Column {
  std::string name, unit;
  std::function<double(const Row&)> real;
  std::function<long long(const Row&)> integer;
  std::function<std::array<double, 3>(const Row&)> vec3;
  std::string codes;

  static Column Real(std::string name, std::string unit, std::function<double(const Row&)> get) {
    return {std::move(name), std::move(unit), std::move(get), {}, {}, {}};
  }
  static Column Integer(std::string name, std::string unit,
                        std::function<long long(const Row&)> get, std::string codes = {}) {
    return {std::move(name), std::move(unit), {}, std::move(get), {}, std::move(codes)};
  }
  static Column Vec3(std::string name, std::string unit,
                     std::function<std::array<double, 3>(const Row&)> get) {
    return {std::move(name), std::move(unit), {}, {}, std::move(get), {}};
  }
};

// Writes the rows into group g: first the <name>_codes attributes of the
// columns that have codes, then one dataset per column, in column order.
template <typename Row>
void write_table(hid_t g, const std::vector<Row>& rows, const std::vector<Column<Row>>& columns) {
  for (const auto& c : columns)
    if (!c.codes.empty()) h5::WriteStringAttr(g, c.name + "_codes", c.codes);
  for (const auto& c : columns) {
    if (c.integer) {
      std::vector<long long> v;
      v.reserve(rows.size());
      for (const auto& r : rows) v.push_back(c.integer(r));
      integers(g, c.name, v, c.unit);
      continue;
    }
    std::vector<double> v;
    v.reserve((c.vec3 ? 3 : 1) * rows.size());
    for (const auto& r : rows) {
      if (c.vec3) {
        const auto a = c.vec3(r);
        v.insert(v.end(), a.begin(), a.end());
      } else {
        v.push_back(c.real(r));
      }
    }
    doubles(g, c.name, v, c.vec3 ? 3 : 1, c.unit);
  }
}

// The columns a contact table (impacts, contact ends) starts with: time,
// particle_id and the surface code (0 flywheel, 1 housing, 2 any other
// surface); then `more`.
template <typename Row>
std::vector<Column<Row>> contact_columns(std::vector<Column<Row>> more) {
  using C = Column<Row>;
  std::vector<C> out = {
      C::Real("time", "s", &Row::time_s),
      C::Integer("particle_id", "1", &Row::particle_id),
      C::Integer(
          "surface", "1",
          [](const Row& r) -> long long {
            return r.surface == "flywheel" ? 0 : r.surface == "housing" ? 1 : 2;
          },
          "0 = flywheel, 1 = housing, 2 = other"),
  };
  out.insert(out.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  return out;
}

// The columns of /impacts: one row per contact onset, with its labels.
std::vector<Column<ImpactRecord>> impact_columns() {
  using C = Column<ImpactRecord>;
  const auto& names = PartNames();
  std::string part_codes = "-1 = not classified";
  for (size_t k = 0; k < names.size(); ++k) part_codes += fmt::format(", {} = {}", k, names[k]);
  return contact_columns<ImpactRecord>({
      C::Vec3("position", "m", &ImpactRecord::position),
      C::Vec3("contact_point", "m", &ImpactRecord::contact),
      C::Vec3("normal", "1", &ImpactRecord::normal),
      C::Vec3("relative_velocity", "m/s", &ImpactRecord::relative_velocity),
      C::Real("speed", "m/s", &ImpactRecord::speed_m_s),
      C::Real("normal_speed", "m/s", &ImpactRecord::normal_speed_m_s),
      C::Real("tangential_speed", "m/s", &ImpactRecord::tangential_speed_m_s),
      C::Real("angle", "deg", &ImpactRecord::angle_deg),
      C::Real("surface_speed", "m/s", &ImpactRecord::surface_speed_m_s),
      C::Real("particle_speed", "m/s", &ImpactRecord::particle_speed_m_s),
      C::Real("axis_distance", "m", &ImpactRecord::axis_distance_m),
      C::Integer(
          "part", "1",
          [&names](const ImpactRecord& r) -> long long {
            const auto p = std::find(names.begin(), names.end(), r.part);
            return p == names.end() ? -1 : p - names.begin();
          },
          part_codes),
      C::Integer("sliding", "1",
                 [](const ImpactRecord& r) -> long long { return r.sliding ? 1 : 0; }),
      C::Integer("strike", "1", &ImpactRecord::strike,
                 "0 = not a strike, 1 = the lump's first strike, 2 = a later one"),
  });
}

// The columns of /contact_ends: one row per contact end.
std::vector<Column<ContactEnd>> contact_end_columns() {
  using C = Column<ContactEnd>;
  return contact_columns<ContactEnd>({
      C::Real("start_time", "s", &ContactEnd::start_time_s),
      C::Real("duration", "s", &ContactEnd::duration_s),
      C::Vec3("velocity", "m/s", &ContactEnd::velocity),
      C::Real("speed", "m/s", &ContactEnd::speed_m_s),
      C::Real("normal_speed", "m/s", &ContactEnd::normal_speed_m_s),
  });
}

// The columns of /strikes: one row per beater strike, its contact end and the
// housing impact that follows it (NaN where there is none).
std::vector<Column<Strike>> strike_columns(const std::vector<ImpactRecord>& records,
                                           const std::vector<ContactEnd>& ends) {
  using C = Column<Strike>;
  const auto rec = [&records](const Strike& c) -> const ImpactRecord& { return records[c.record]; };
  // A field of the strike's contact end or of the housing impact that follows it; NaN if none.
  const auto end = [&ends](const Strike& c, double ContactEnd::*x) {
    return c.end >= 0 ? ends[static_cast<size_t>(c.end)].*x : kNaN;
  };
  const auto housing = [&records](const Strike& c, double ImpactRecord::*x) {
    return c.housing >= 0 ? records[static_cast<size_t>(c.housing)].*x : kNaN;
  };
  return {
      C::Real("time", "s", [rec](const Strike& c) { return rec(c).time_s; }),
      C::Integer("particle_id", "1", [rec](const Strike& c) { return rec(c).particle_id; }),
      C::Integer("first", "1",
                 [rec](const Strike& c) -> long long { return rec(c).strike == 1 ? 1 : 0; }),
      C::Real("impact_speed", "m/s", [rec](const Strike& c) { return rec(c).speed_m_s; }),
      C::Real("rebound_speed_lab", "m/s",
              [end](const Strike& c) { return end(c, &ContactEnd::speed_m_s); }),
      C::Real("contact_duration", "s",
              [end](const Strike& c) { return end(c, &ContactEnd::duration_s); }),
      C::Real("housing_speed", "m/s",
              [housing](const Strike& c) { return housing(c, &ImpactRecord::speed_m_s); }),
      C::Real("housing_angle", "deg",
              [housing](const Strike& c) { return housing(c, &ImpactRecord::angle_deg); }),
      C::Real("flight_time", "s",
              [](const Strike& c) { return c.housing >= 0 ? c.flight_time_s : kNaN; }),
  };
}

}  // namespace

void WriteTransportH5(const std::string& path, const std::vector<ImpactRecord>& records,
                      const TransportStats& stats, const std::vector<double>& insert_time_s,
                      const Trajectories& traj, const TransportMeta& meta,
                      const std::vector<ContactEnd>& ends) {
  const std::string tmp = path + ".tmp." + std::to_string(getpid());
  h5::WriteFileAtomically(path, tmp, [&](hid_t f) {
    h5::WriteStringAttr(
        f, "content",
        "transport stage: impacts on flywheel and housing, per-particle counts, trajectories");
    for (const auto& [k, v] : meta.scalars) {
      attr_double(f, k, v);
      const auto u = meta.units.find(k);
      if (u != meta.units.end() && !u->second.empty())
        h5::WriteStringAttr(f, k + "_unit", u->second);
    }
    write_table(h5::CreateGroup(f, "impacts"), records, impact_columns());
    write_table(h5::CreateGroup(f, "contact_ends"), ends, contact_end_columns());
    {
      const h5::Handle g = h5::CreateGroup(f, "strikes");
      h5::WriteStringAttr(g, "content",
                          "one row per beater strike (flywheel impact, not sliding); NaN where the "
                          "strike has no contact end or no following housing impact");
      write_table(g, stats.chains, strike_columns(records, ends));
    }
    {
      const h5::Handle g = h5::CreateGroup(f, "particles");
      integers(g, "id", stats.ids, "1");
      doubles(g, "insert_time", insert_time_s, 1, "s");
      integers(g, "n_impacts", stats.impacts_per_particle, "1");
      integers(g, "n_flywheel_impacts", stats.flywheel_impacts_per_particle, "1");
      doubles(g, "first_impact_time", stats.first_impact_time_s, 1, "s");
    }
    {
      const h5::Handle g = h5::CreateGroup(f, "trajectories");
      std::vector<double> speed;
      for (const auto& v : traj.velocity)
        speed.push_back(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
      doubles(g, "time", traj.time_s, 1, "s");
      integers(g, "particle_id", traj.particle_id, "1");
      doubles(g, "position", flat3(traj.position), 3, "m");
      doubles(g, "velocity", flat3(traj.velocity), 3, "m/s");
      doubles(g, "speed", speed, 1, "m/s");
    }
    const h5::Handle g = h5::CreateGroup(f, "geometry");
    h5::WriteStringAttr(g, "length_unit", "m");
    for (const auto& [k, v] : meta.geometry) attr_double(g, k, v);
  });
}

}  // namespace mill::post
