// The parametric beater mill: housing box, flywheel (hub + flat beater
// plates), inlet and outlet squares, as ASCII STL surfaces shared by the
// OpenFOAM case (snappyHexMesh) and the LIGGGHTS transport stage (walls and
// the rotating flywheel).
//
// Frame (metres): x across the housing (width, centred: x in [-w/2, w/2]),
// y up (floor y = 0, roof y = h), z along the rotor axis (depth, centred:
// z in [-d/2, d/2]). The rotor axis is the line (axis_x, axis_height, z).
// Every STL normal points INTO THE GAS: housing walls inwards, the flywheel
// outwards, the inlet (on the roof) down, the outlet (on the floor) up.
// One solid per file, named after the file (housing, flywheel, inlet, outlet).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace mill::config {
class Document;
}

namespace mill::geometry {

using Vec3 = std::array<double, 3>;

// One facet; the normal follows from the vertex order (right-hand rule).
struct Triangle {
  Vec3 a, b, c;
};
using Surface = std::vector<Triangle>;

struct MillGeometry {
  double height = 4.0, width = 1.6, depth = 0.5;  // housing box
  double tip_diameter = 1.0, hub_diameter = 0.3;  // flywheel
  int n_plates = 6;
  double plate_width = 0.3, plate_thickness = 0.02;  // along z, tangential
  double axis_x = 0.0, axis_height = 1.2;            // rotor axis position
  double inlet_x = 0.0, inlet_size = 0.3;            // square on the roof
  double outlet_x = 0.0, outlet_size = 0.4;          // square on the floor
  int arc_segments = 96;                             // facets of the hub circle
  // Angular position of the flywheel [rad], counter-clockwise about +z: plate
  // i points at i * 2 pi / n_plates + rotor_angle. 0 puts plate 0 along +x.
  // Used for frozen-rotor positions (flow) and a flywheel caught mid-turn.
  double rotor_angle = 0.0;

  // Read the mill.* keys of a case file and validate them.
  static MillGeometry from_config(const config::Document& doc);
  // Throw std::invalid_argument naming the key when the parts do not fit.
  void validate() const;
  // Same, with "case.yaml:12: mill.x" prefixes from the document.
  void validate(const config::Document& doc) const;

  double tip_radius() const { return 0.5 * tip_diameter; }
  double hub_radius() const { return 0.5 * hub_diameter; }
  Vec3 axis_centre() const { return {axis_x, axis_height, 0.0}; }
};

// Housing walls: the box without the inlet and outlet openings.
Surface housing_surface(const MillGeometry& g);
// Flywheel: hub disc and plates as one closed, watertight star prism.
Surface flywheel_surface(const MillGeometry& g);
// Inlet square in the roof plane; outlet square in the floor plane.
Surface inlet_surface(const MillGeometry& g);
Surface outlet_surface(const MillGeometry& g);

// Write one ASCII STL solid (units m). Written to a temp name, then renamed.
void write_stl(const std::filesystem::path& file, const std::string& solid, const Surface& s);
// Read back an ASCII STL (for tests and checks).
Surface read_stl(const std::filesystem::path& file);

struct StlSet {
  std::filesystem::path housing, flywheel, inlet, outlet;
};
// Write housing.stl, flywheel.stl, inlet.stl, outlet.stl into dir.
StlSet write_stl_set(const MillGeometry& g, const std::filesystem::path& dir);

// Signed volume enclosed by a closed surface (divergence theorem): positive
// when normals point outwards.
double signed_volume(const Surface& s);
// Total area of a surface.
double area(const Surface& s);
// Exact flywheel volume (hub disc plus the plate parts outside it).
double flywheel_volume(const MillGeometry& g);

}  // namespace mill::geometry
