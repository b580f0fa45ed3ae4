// Stage 'sample': resample each flow solution on a uniform grid.
//
// Reads the declared outputs of stage flow (<run>/flow/<rpm label>/case and
// flow_report.json) and writes, at once (rename of a temp folder):
//   <run>/sample/<rpm label>/field.h5          U, rho, mask (+ k, omega), see
//   postprocess/flow_field_io.h <run>/sample/<rpm label>/field.vti         the same for ParaView
//   <run>/sample/<rpm label>/midplane_speed.png  |U| on the mid-plane z = 0 (normal to the axis)
//   <run>/sample/<rpm label>/sample_report.json  grid, gas fraction, speed range of the picture
#pragma once

#include <array>
#include <filesystem>
#include <string>

#include "postprocess/flow_field_io.h"
#include "stages/stage.h"

namespace mill {

class SampleStage : public Stage {
 public:
  std::string name() const override { return "sample"; }
  std::string description() const override {
    return "resample the gas velocity on a uniform grid (field.h5, field.vti)";
  }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job,
               const std::filesystem::path& job_dir) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
};

namespace sample {

struct GridSpec {
  std::array<double, 3> lo{0, 0, 0}, hi{1, 1, 1};  // box to cover, m
  double spacing = 0.05;                           // m
  // The outermost points are probed this far inside [lo, hi] (m): snapHexMesh
  // moves housing-wall points by up to ~0.4 mm, which would mask wall points.
  double wall_inset = 0;
};

// Points of a grid of exactly `spacing` centred in [lo, hi] (at least 2 per axis).
post::FlowField make_grid(const GridSpec& g);

struct Options {
  bool turbulence = false;  // also k and omega
  double constant_rho =
      -1;  // > 0: rho is this constant (incompressible); else read rho (or p/(R T))
};

// Resample the latest time of an OpenFOAM case (reconstructed, internal mesh)
// on the grid with VTK (vtkOpenFOAMReader + vtkResampleToImage). Points not in
// any cell get mask 0 and zero values. Throws naming the case on failure.
post::FlowField resample_case(const std::filesystem::path& case_dir, const GridSpec& grid,
                              const Options& opt);

// The same field as VTK XML image data (.vti), mask as an unsigned char array.
void write_vti(const std::filesystem::path& file, const post::FlowField& f);

// |U| on the grid plane nearest to z, colour-mapped (blue -> red, solids grey)
// with a colour bar on the right; returns the speed range mapped.
std::array<double, 2> write_midplane_png(const std::filesystem::path& file,
                                         const post::FlowField& f, double z);

}  // namespace sample
}  // namespace mill
