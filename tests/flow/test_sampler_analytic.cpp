// The VTK sampler against analytic fields on a blockMesh box: solid-body
// rotation u = Omega x r (linear, so reproduced exactly away from the walls)
// and points outside the mesh masked.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>

#include "engine/runner.h"
#include "stages/sample_stage.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill;

namespace {

constexpr double kOmega = 10.0;  // rad/s about +z through the origin
constexpr int kN[3] = {20, 20, 4};
constexpr double kLo[3] = {-0.5, -0.5, 0.0}, kHi[3] = {0.5, 0.5, 0.2};

const char* kHeader = "FoamFile { version 2.0; format ascii; class %s; object %s; }\n";

std::string header(const std::string& cls, const std::string& obj) {
  char buf[256];
  snprintf(buf, sizeof buf, kHeader, cls.c_str(), obj.c_str());
  return buf;
}

// A one-block box case with U written at time 1 from the cell centres
// (blockMesh numbers the cells of one block x fastest, then y, then z).
// half: the face z = 0 is the symmetryPlane patch `symmetry`, as in the flow
// stage's half-domain case (flow.domain = half).
// Removed when the test passes.
mill::test::TempDir make_case(bool half = false) {
  mill::test::TempDir d("mill_sampler_" + std::to_string(getpid()));
  fs::create_directories(d / "system");
  fs::create_directories(d / "1");
  std::ofstream(d / "system" / "controlDict")
      << header("dictionary", "controlDict")
      << "application none;\nstartFrom startTime;\nstartTime 0;\nstopAt endTime;\nendTime "
         "1;\ndeltaT 1;\n"
         "writeControl timeStep;\nwriteInterval 1;\n";
  std::ofstream(d / "system" / "blockMeshDict")
      << header("dictionary", "blockMeshDict") << "scale 1;\nvertices\n(\n"
      << "(-0.5 -0.5 0) (0.5 -0.5 0) (0.5 0.5 0) (-0.5 0.5 0)\n"
      << "(-0.5 -0.5 0.2) (0.5 -0.5 0.2) (0.5 0.5 0.2) (-0.5 0.5 0.2)\n);\n"
      << "blocks ( hex (0 1 2 3 4 5 6 7) (20 20 4) simpleGrading (1 1 1) );\n"
      << (half ? "boundary ( walls { type wall; faces ( (4 5 6 7) (0 4 7 3) (1 2 6 5) (0 1 5 4) "
                 "(3 7 6 2) ); }\n  symmetry { type symmetryPlane; faces ( (0 3 2 1) ); } );\n"
               : "boundary ( walls { type wall; faces ( (0 3 2 1) (4 5 6 7) (0 4 7 3) (1 2 6 5) "
                 "(0 1 5 4) (3 7 6 2) ); } );\n");
  std::ofstream u(d / "1" / "U");
  u << header("volVectorField", "U") << "dimensions [0 1 -1 0 0 0 0];\n"
    << "internalField nonuniform List<vector>\n"
    << kN[0] * kN[1] * kN[2] << "\n(\n";
  for (int k = 0; k < kN[2]; ++k)
    for (int j = 0; j < kN[1]; ++j)
      for (int i = 0; i < kN[0]; ++i) {
        const double x = kLo[0] + (i + 0.5) * (kHi[0] - kLo[0]) / kN[0];
        const double y = kLo[1] + (j + 0.5) * (kHi[1] - kLo[1]) / kN[1];
        u << "(" << -kOmega * y << " " << kOmega * x << " 0)\n";
      }
  u << ");\nboundaryField { walls { type zeroGradient; } symmetry { type symmetryPlane; } }\n";
  u.close();
  engine::Runner r;
  engine::Command c;
  c.argv = {"blockMesh"};
  c.cwd = d;
  c.log = d / "log.blockMesh";
  c.env = engine::openfoam_env();
  c.engine = engine::Engine::OpenFoam;
  c.job = "test/sampler";
  r.run(c);
  return d;
}

}  // namespace

TEST(Sampler, SolidBodyRotationMatchesAnalyticAndOutsideIsMasked) {
  const auto d = make_case();
  sample::GridSpec g;
  g.lo = {-0.6, -0.6, 0.0};  // wider than the mesh in x and y: those points are outside
  g.hi = {0.6, 0.6, 0.2};
  g.spacing = 0.04;  // not aligned with the 0.05 m cells
  sample::Options opt;
  opt.constant_rho = 1.2;
  const auto f = sample::resample_case(d, g, opt);
  ASSERT_EQ(f.dims[0], 31);
  ASSERT_EQ(f.dims[2], 6);
  const double h = 0.05;
  int inner = 0, outside = 0;
  double worst_inner = 0, worst_edge = 0;
  for (int k = 0; k < f.dims[2]; ++k)
    for (int j = 0; j < f.dims[1]; ++j)
      for (int i = 0; i < f.dims[0]; ++i) {
        const size_t p = f.point(i, j, k);
        const double x = f.origin[0] + i * f.spacing[0], y = f.origin[1] + j * f.spacing[1],
                     z = f.origin[2] + k * f.spacing[2];
        const bool in_box = std::abs(x) < 0.5 - 1e-9 && std::abs(y) < 0.5 - 1e-9;
        if (std::abs(x) > 0.5 + 1e-9 || std::abs(y) > 0.5 + 1e-9) {
          EXPECT_EQ(f.mask[p], 0) << "outside the mesh at " << x << " " << y;
          EXPECT_EQ(f.U[3 * p], 0.0);
          EXPECT_EQ(f.rho[p], 0.0);
          ++outside;
          continue;
        }
        if (!in_box) continue;
        EXPECT_EQ(f.mask[p], 1) << x << " " << y << " " << z;
        EXPECT_DOUBLE_EQ(f.rho[p], 1.2);
        const double err =
            std::hypot(f.U[3 * p] + kOmega * y, f.U[3 * p + 1] - kOmega * x, f.U[3 * p + 2]);
        // Away from the walls (> one cell) the linear field is reproduced exactly;
        // within a cell of a wall the cell-to-point step is one-sided: error <= Omega h.
        const bool deep = std::abs(x) < 0.5 - h && std::abs(y) < 0.5 - h && z > h && z < 0.2 - h;
        if (deep) {
          worst_inner = std::max(worst_inner, err);
          ++inner;
        } else {
          worst_edge = std::max(worst_edge, err);
        }
      }
  EXPECT_GT(inner, 100);
  EXPECT_GT(outside, 100);
  EXPECT_LT(worst_inner, 1e-6 * kOmega * 0.5)
      << "interior: interpolation of a linear field is exact";
  EXPECT_LT(worst_edge, kOmega * h)
      << "near the walls: within the interpolation error at the cell size";
}

// A half-domain case (flow.domain = half) is the part z >= 0 of the mill,
// recognised by its symmetryPlane patch `symmetry`; the sampler probes it and
// reflects it about z = 0. The box mesh above is such a half (z in [0, 0.2]);
// solid-body rotation about z is mirror-symmetric, so the whole grid z in
// [-0.2, 0.2] must match the analytic field, the plane z = 0 must be gas, and
// the field must be even in z (U_z odd, here 0).
TEST(Sampler, HalfDomainIsMirroredAboutTheMidPlane) {
  const auto d = make_case(true);
  sample::Options opt;
  opt.constant_rho = 1.2;
  for (double spacing : {0.04, 0.07}) {  // 11 planes (one at z = 0), 6 planes (none)
    sample::GridSpec g;
    g.lo = {-0.5, -0.5, -0.2};
    g.hi = {0.5, 0.5, 0.2};
    g.spacing = spacing;
    // wall_inset 0: the plane z = 0 is probed only 1e-6 x spacing inside the
    // half mesh (the least inset the sampler uses), and x, y are not squeezed.
    const auto f = sample::resample_case(d, g, opt);
    const int nz = f.dims[2];
    ASSERT_EQ(nz, spacing == 0.04 ? 11 : 6);
    EXPECT_NEAR(f.origin[2], -0.5 * (nz - 1) * spacing, 1e-12);
    double worst = 0;
    int gas = 0;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < f.dims[1]; ++j)
        for (int i = 0; i < f.dims[0]; ++i) {
          const size_t p = f.point(i, j, k), m = f.point(i, j, nz - 1 - k);
          const double x = f.origin[0] + i * f.spacing[0], y = f.origin[1] + j * f.spacing[1];
          EXPECT_EQ(f.mask[p], 1) << "the whole box is gas, z = " << f.origin[2] + k * spacing;
          gas += f.mask[p];
          EXPECT_EQ(f.mask[p], f.mask[m]);
          EXPECT_EQ(f.U[3 * p], f.U[3 * m]);
          EXPECT_EQ(f.U[3 * p + 1], f.U[3 * m + 1]);
          EXPECT_EQ(f.U[3 * p + 2], -f.U[3 * m + 2]);
          EXPECT_EQ(f.rho[p], f.rho[m]);
          if (std::abs(x) < 0.5 - 0.05 && std::abs(y) < 0.5 - 0.05)
            worst = std::max(worst, std::hypot(f.U[3 * p] + kOmega * y,
                                               f.U[3 * p + 1] - kOmega * x, f.U[3 * p + 2]));
        }
    EXPECT_EQ(gas, static_cast<int>(f.size()));
    EXPECT_LT(worst, 1e-6 * kOmega * 0.5) << "spacing " << spacing;
  }
  // The mirror needs a box symmetric about z = 0.
  sample::GridSpec bad;
  bad.lo = {-0.5, -0.5, -0.1};
  bad.hi = {0.5, 0.5, 0.2};
  bad.spacing = 0.05;
  EXPECT_THROW(sample::resample_case(d, bad, opt), std::invalid_argument);
}
