// The uniform-grid gas field (HDF5): written by the sample stage, read by the
// LIGGGHTS drag fix. One writer, one reader, plain HDF5 C API; no driver/ or
// VTK includes.
//
// File layout (format_version 1):
//   /            attributes: format_version (int), dims (int[3] = nx, ny, nz,
//                point counts), origin (double[3], m), spacing (double[3], m),
//                length_unit "m", index_order, frame "absolute",
//                rpm (double), gas_model (string), source (string)
//   /U           double [nz][ny][nx][3], unit "m/s" (absolute frame)
//   /rho         double [nz][ny][nx],    unit "kg/m^3"
//   /mask        uint8  [nz][ny][nx],    unit "1": 1 = in the gas, 0 = inside
//                a solid or outside the housing (U, rho there are 0)
//   /k, /omega   double [nz][ny][nx], units "m^2/s^2", "1/s" (optional)
// Point (i, j, k) sits at origin + (i, j, k) * spacing; x varies fastest.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace mill::post {

struct FlowField {
  std::array<int, 3> dims{0, 0, 0};        // nx, ny, nz (points)
  std::array<double, 3> origin{0, 0, 0};   // m
  std::array<double, 3> spacing{1, 1, 1};  // m
  std::vector<double> U;                   // 3 per point, index 3 * point(i, j, k) + c
  std::vector<double> rho;                 // kg/m^3
  std::vector<std::uint8_t> mask;          // 1 = gas
  std::vector<double> k, omega;            // optional: empty when not sampled
  double rpm = 0;                          // rotor speed of the solution
  std::string gas_model;                   // incompressible | compressible
  std::string source;                      // where the field came from (free text)

  // Number of grid points.
  size_t size() const { return static_cast<size_t>(dims[0]) * dims[1] * dims[2]; }
  // Linear index of point (i, j, k): x fastest, z slowest.
  size_t point(int i, int j, int k) const {
    return (static_cast<size_t>(k) * dims[1] + j) * dims[0] + i;
  }
  // Allocate U, rho, mask (and k, omega when `turbulence`) filled with 0.
  void allocate(bool turbulence);
  // Trilinear interpolation of U at x; false (u untouched) when x is off the
  // grid or any of the 8 surrounding points is outside the gas.
  bool velocity_at(const std::array<double, 3>& x, std::array<double, 3>& u) const;
  // U and rho at x with the same weights in one pass (what the gas drag
  // needs each step): the very numbers velocity_at gives for u, and rho
  // interpolated with its weights; false (u, rho untouched) where
  // velocity_at is false.
  bool gas_at(const std::array<double, 3>& x, std::array<double, 3>& u, double& rho) const;

 private:
  template <bool kWithRho>
  bool interpolate(const std::array<double, 3>& x, std::array<double, 3>& u, double* rho) const;
};

// Write the field to `file` (via a temp file renamed at the end). Throws
// PostError (a std::runtime_error, fragments.h) naming the file on failure,
// std::invalid_argument when array sizes do not match dims.
void write_flow_field(const std::filesystem::path& file, const FlowField& f);

// Read a field written by write_flow_field. Throws PostError naming the file
// and the missing/bad item.
FlowField read_flow_field(const std::filesystem::path& file);

// Unit attribute of a dataset ("m/s" for "U"); "" if absent. For tests/tools.
std::string dataset_unit(const std::filesystem::path& file, const std::string& dataset);

}  // namespace mill::post
