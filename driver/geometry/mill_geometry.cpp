// Parametric beater-mill surfaces (STL) from the case file's mill.* keys.
#include "geometry/mill_geometry.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "config/case_config.h"

namespace mill::geometry {
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Append the quad p0-p1-p2-p3 (planar, convex) as two facets whose normal
// points along `facing`; skipped when degenerate.
void add_quad(Surface& s, Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, const Vec3& facing) {
  const Vec3 n = cross(sub(p1, p0), sub(p2, p0));
  if (std::sqrt(dot(n, n)) < 1e-14) return;
  if (dot(n, facing) < 0) std::swap(p1, p3);
  s.push_back({p0, p1, p2});
  s.push_back({p0, p2, p3});
}

// A wall at y = `y` spanning the housing in x and z, with a square hole of
// side `size` centred at (hole_x, 0); normal along `facing`.
void wall_with_hole(Surface& s, const MillGeometry& g, double y, double hole_x, double size,
                    const Vec3& facing) {
  const double X0 = -0.5 * g.width, X1 = 0.5 * g.width, Z0 = -0.5 * g.depth, Z1 = 0.5 * g.depth;
  const double x0 = hole_x - 0.5 * size, x1 = hole_x + 0.5 * size, z0 = -0.5 * size,
               z1 = 0.5 * size;
  auto rect = [&](double xa, double xb, double za, double zb) {
    if (xb - xa <= 1e-12 || zb - za <= 1e-12) return;
    add_quad(s, {xa, y, za}, {xb, y, za}, {xb, y, zb}, {xa, y, zb}, facing);
  };
  rect(X0, x0, Z0, Z1);
  rect(x1, X1, Z0, Z1);
  rect(x0, x1, Z0, z0);
  rect(x0, x1, z1, Z1);
}

// The flywheel's cross-section in the x-y plane: hub circle with the plates
// as radial arms, counter-clockwise, star-shaped about the axis.
std::vector<std::array<double, 2>> flywheel_profile(const MillGeometry& g) {
  const double rh = g.hub_radius(), rt = g.tip_radius(), t2 = 0.5 * g.plate_thickness;
  const double alpha = std::asin(t2 / rh);
  const double xtip = std::sqrt(rt * rt - t2 * t2);
  const double dtheta = 2 * kPi / g.n_plates;
  std::vector<std::array<double, 2>> pts;
  auto at = [&](double theta, double radial, double tangential) {
    const double c = std::cos(theta), s = std::sin(theta);
    pts.push_back(
        {g.axis_x + radial * c - tangential * s, g.axis_height + radial * s + tangential * c});
  };
  for (int i = 0; i < g.n_plates; ++i) {
    const double th = i * dtheta + g.rotor_angle;
    at(th, std::sqrt(rh * rh - t2 * t2), -t2);
    at(th, xtip, -t2);
    at(th, xtip, t2);
    at(th, std::sqrt(rh * rh - t2 * t2), t2);
    // Hub arc up to the next plate.
    const double a0 = th + alpha, a1 = th + dtheta - alpha;
    const int nseg =
        std::max(1, static_cast<int>(std::ceil(g.arc_segments * (a1 - a0) / (2 * kPi))));
    for (int k = 1; k < nseg; ++k) {
      const double a = a0 + (a1 - a0) * k / nseg;
      pts.push_back({g.axis_x + rh * std::cos(a), g.axis_height + rh * std::sin(a)});
    }
  }
  return pts;
}

// "case.yaml:12: mill.x" when a document is at hand, else the key.
std::string where(const config::Document* doc, const std::string& key) {
  return doc ? doc->where(key) : key;
}

// All fit checks; `doc` only decorates the messages.
void check(const MillGeometry& g, const config::Document* doc) {
  auto fail = [&](const std::string& key, const std::string& what) {
    throw std::invalid_argument(fmt::format("{}: {}", where(doc, key), what));
  };
  if (g.hub_diameter >= g.tip_diameter)
    fail("mill.flywheel.hub_diameter",
         fmt::format("hub diameter {:g} m must be below the tip diameter {:g} m", g.hub_diameter,
                     g.tip_diameter));
  if (g.plate_thickness >= g.hub_diameter * std::sin(kPi / g.n_plates))
    fail("mill.flywheel.plate_thickness",
         fmt::format("{:g} m plates do not fit {} times around a {:g} m hub (reduce thickness or "
                     "n_plates)",
                     g.plate_thickness, g.n_plates, g.hub_diameter));
  if (g.plate_width > g.depth)
    fail(
        "mill.flywheel.plate_width",
        fmt::format("plate width {:g} m exceeds the housing depth {:g} m", g.plate_width, g.depth));
  const double rt = g.tip_radius();
  if (g.axis_height - rt <= 0 || g.axis_height + rt >= g.height)
    fail("mill.flywheel.axis_height",
         fmt::format("flywheel (tip radius {:g} m) at height {:g} m does not fit between floor and "
                     "roof (0..{:g} m)",
                     rt, g.axis_height, g.height));
  if (std::abs(g.axis_x) + rt >= 0.5 * g.width)
    fail("mill.flywheel.axis_x",
         fmt::format(
             "flywheel (tip radius {:g} m) at x = {:g} m touches the side walls (x = +-{:g} m)", rt,
             g.axis_x, 0.5 * g.width));
  auto opening = [&](const std::string& name, double cx, double size) {
    if (size > g.depth)
      fail("mill." + name + ".size",
           fmt::format("{} size {:g} m exceeds the housing depth {:g} m", name, size, g.depth));
    if (std::abs(cx) + 0.5 * size > 0.5 * g.width)
      fail("mill." + name + ".center_x",
           fmt::format("{} square (side {:g} m) at x = {:g} m leaves the housing (x = +-{:g} m)",
                       name, size, cx, 0.5 * g.width));
  };
  opening("inlet", g.inlet_x, g.inlet_size);
  opening("outlet", g.outlet_x, g.outlet_size);
}

}  // namespace

// Build from the mill.* keys and validate with file:line messages.
MillGeometry MillGeometry::from_config(const config::Document& doc) {
  MillGeometry g;
  g.height = doc.real("mill.housing.height");
  g.width = doc.real("mill.housing.width");
  g.depth = doc.real("mill.housing.depth");
  g.tip_diameter = doc.real("mill.flywheel.diameter");
  g.hub_diameter = doc.real("mill.flywheel.hub_diameter");
  g.n_plates = static_cast<int>(doc.integer("mill.flywheel.n_plates"));
  g.plate_width = doc.real("mill.flywheel.plate_width");
  g.plate_thickness = doc.real("mill.flywheel.plate_thickness");
  g.axis_height = doc.real("mill.flywheel.axis_height");
  g.axis_x = doc.real("mill.flywheel.axis_x");
  g.inlet_x = doc.real("mill.inlet.center_x");
  g.inlet_size = doc.real("mill.inlet.size");
  g.outlet_x = doc.real("mill.outlet.center_x");
  g.outlet_size = doc.real("mill.outlet.size");
  g.validate(doc);
  return g;
}

// Validate without a document (messages name the keys only).
void MillGeometry::validate() const { check(*this, nullptr); }

// Validate with file:line prefixes.
void MillGeometry::validate(const config::Document& doc) const { check(*this, &doc); }

// Housing box walls, normals inwards, with the two openings cut out.
Surface housing_surface(const MillGeometry& g) {
  Surface s;
  const double X0 = -0.5 * g.width, X1 = 0.5 * g.width, Z0 = -0.5 * g.depth, Z1 = 0.5 * g.depth;
  const double H = g.height;
  wall_with_hole(s, g, 0.0, g.outlet_x, g.outlet_size, {0, 1, 0});
  wall_with_hole(s, g, H, g.inlet_x, g.inlet_size, {0, -1, 0});
  add_quad(s, {X0, 0, Z0}, {X0, H, Z0}, {X0, H, Z1}, {X0, 0, Z1}, {1, 0, 0});
  add_quad(s, {X1, 0, Z0}, {X1, H, Z0}, {X1, H, Z1}, {X1, 0, Z1}, {-1, 0, 0});
  add_quad(s, {X0, 0, Z0}, {X1, 0, Z0}, {X1, H, Z0}, {X0, H, Z0}, {0, 0, 1});
  add_quad(s, {X0, 0, Z1}, {X1, 0, Z1}, {X1, H, Z1}, {X0, H, Z1}, {0, 0, -1});
  return s;
}

// Hub + plates: the star profile extruded over the plate width, centred in z.
Surface flywheel_surface(const MillGeometry& g) {
  const auto prof = flywheel_profile(g);
  const double z0 = -0.5 * g.plate_width, z1 = 0.5 * g.plate_width;
  const Vec3 cb{g.axis_x, g.axis_height, z0}, ct{g.axis_x, g.axis_height, z1};
  Surface s;
  const size_t n = prof.size();
  for (size_t k = 0; k < n; ++k) {
    const auto& p = prof[k];
    const auto& q = prof[(k + 1) % n];
    const Vec3 pb{p[0], p[1], z0}, qb{q[0], q[1], z0}, pt{p[0], p[1], z1}, qt{q[0], q[1], z1};
    s.push_back({ct, pt, qt});  // top cap, +z
    s.push_back({cb, qb, pb});  // bottom cap, -z
    s.push_back({pb, qb, qt});  // side, outwards
    s.push_back({pb, qt, pt});
  }
  return s;
}

// Inlet square on the roof, normal down into the housing.
Surface inlet_surface(const MillGeometry& g) {
  Surface s;
  const double x0 = g.inlet_x - 0.5 * g.inlet_size, x1 = g.inlet_x + 0.5 * g.inlet_size;
  const double z0 = -0.5 * g.inlet_size, z1 = 0.5 * g.inlet_size, y = g.height;
  add_quad(s, {x0, y, z0}, {x1, y, z0}, {x1, y, z1}, {x0, y, z1}, {0, -1, 0});
  return s;
}

// Outlet square on the floor, normal up into the housing.
Surface outlet_surface(const MillGeometry& g) {
  Surface s;
  const double x0 = g.outlet_x - 0.5 * g.outlet_size, x1 = g.outlet_x + 0.5 * g.outlet_size;
  const double z0 = -0.5 * g.outlet_size, z1 = 0.5 * g.outlet_size;
  add_quad(s, {x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1}, {0, 1, 0});
  return s;
}

// ASCII STL writer: temp file then rename, so a reader never sees half a file.
void write_stl(const fs::path& file, const std::string& solid, const Surface& s) {
  fs::create_directories(file.parent_path().empty() ? fs::path(".") : file.parent_path());
  const fs::path tmp = file.string() + ".tmp." + std::to_string(getpid());
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
    out << "solid " << solid << "\n";
    for (const auto& t : s) {
      Vec3 n = cross(sub(t.b, t.a), sub(t.c, t.a));
      const double len = std::sqrt(dot(n, n));
      if (len > 0)
        for (auto& x : n) x /= len;
      out << fmt::format("  facet normal {:.9g} {:.9g} {:.9g}\n    outer loop\n", n[0], n[1], n[2]);
      for (const auto* v : {&t.a, &t.b, &t.c})
        out << fmt::format("      vertex {:.12g} {:.12g} {:.12g}\n", (*v)[0], (*v)[1], (*v)[2]);
      out << "    endloop\n  endfacet\n";
    }
    out << "endsolid " << solid << "\n";
    if (!out) throw std::runtime_error("error writing " + tmp.string());
  }
  fs::rename(tmp, file);
}

// Minimal ASCII STL reader: the vertices of each facet, in order.
Surface read_stl(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  Surface s;
  std::string word;
  std::vector<Vec3> v;
  while (in >> word) {
    if (word != "vertex") continue;
    Vec3 p;
    in >> p[0] >> p[1] >> p[2];
    v.push_back(p);
    if (v.size() == 3) {
      s.push_back({v[0], v[1], v[2]});
      v.clear();
    }
  }
  return s;
}

// The four surfaces into dir, one solid per file.
StlSet write_stl_set(const MillGeometry& g, const fs::path& dir) {
  StlSet set{dir / "housing.stl", dir / "flywheel.stl", dir / "inlet.stl", dir / "outlet.stl"};
  write_stl(set.housing, "housing", housing_surface(g));
  write_stl(set.flywheel, "flywheel", flywheel_surface(g));
  write_stl(set.inlet, "inlet", inlet_surface(g));
  write_stl(set.outlet, "outlet", outlet_surface(g));
  return set;
}

// Sum of a . (b x c) / 6 over the facets.
double signed_volume(const Surface& s) {
  double v = 0;
  for (const auto& t : s) v += dot(t.a, cross(t.b, t.c)) / 6.0;
  return v;
}

// Sum of the facet areas.
double area(const Surface& s) {
  double a = 0;
  for (const auto& t : s) {
    const Vec3 n = cross(sub(t.b, t.a), sub(t.c, t.a));
    a += 0.5 * std::sqrt(dot(n, n));
  }
  return a;
}

// Hub disc plus the plate parts outside it (ignoring the hub's polygon facets).
double flywheel_volume(const MillGeometry& g) {
  const double rh = g.hub_radius(), rt = g.tip_radius(), t2 = 0.5 * g.plate_thickness;
  const double alpha = std::asin(t2 / rh);
  // Plate outside the hub: rectangle from the chord at the hub to the tip corners,
  // minus the circular segment between chord and arc.
  const double xin = std::sqrt(rh * rh - t2 * t2), xtip = std::sqrt(rt * rt - t2 * t2);
  const double segment = 0.5 * rh * rh * (2 * alpha - std::sin(2 * alpha));
  const double plate = 2 * t2 * (xtip - xin) - segment;
  return (kPi * rh * rh + g.n_plates * plate) * g.plate_width;
}

}  // namespace mill::geometry
