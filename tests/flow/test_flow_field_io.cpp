// The uniform-grid HDF5 field: round trip, attributes, units, lookup, errors.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cmath>

#include "postprocess/flow_field_io.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using mill::post::FlowField;

namespace {

// A 4x3x2 grid with U = (x, 2y, 3z), rho = 1 + x, one masked point.
FlowField sample_field(bool turbulence) {
  FlowField f;
  f.dims = {4, 3, 2};
  f.origin = {-1.0, 0.5, 2.0};
  f.spacing = {0.5, 0.25, 0.1};
  f.allocate(turbulence);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) {
        const size_t p = f.point(i, j, k);
        const double x = f.origin[0] + i * f.spacing[0], y = f.origin[1] + j * f.spacing[1],
                     z = f.origin[2] + k * f.spacing[2];
        f.U[3 * p] = x, f.U[3 * p + 1] = 2 * y, f.U[3 * p + 2] = 3 * z;
        f.rho[p] = 1 + x;
        f.mask[p] = 1;
        if (turbulence) f.k[p] = p, f.omega[p] = 10.0 * p;
      }
  f.mask[f.point(3, 2, 1)] = 0;
  f.rpm = 2000;
  f.gas_model = "incompressible";
  f.source = "unit test";
  return f;
}

// A file path, removed when the test passes.
mill::test::TempPath tmp_file(const std::string& name) {
  return mill::test::TempPath("mill_ffio_" + std::to_string(getpid()) + "_" + name);
}

}  // namespace

TEST(FlowFieldIo, RoundTripKeepsDataAndAttributes) {
  const auto f = sample_field(true);
  const auto file = tmp_file("rt.h5");
  mill::post::write_flow_field(file, f);
  const auto g = mill::post::read_flow_field(file);
  EXPECT_EQ(g.dims, f.dims);
  EXPECT_EQ(g.origin, f.origin);
  EXPECT_EQ(g.spacing, f.spacing);
  EXPECT_EQ(g.U, f.U);
  EXPECT_EQ(g.rho, f.rho);
  EXPECT_EQ(g.mask, f.mask);
  EXPECT_EQ(g.k, f.k);
  EXPECT_EQ(g.omega, f.omega);
  EXPECT_EQ(g.rpm, 2000);
  EXPECT_EQ(g.gas_model, "incompressible");
  EXPECT_EQ(g.source, "unit test");
  EXPECT_EQ(mill::post::dataset_unit(file, "U"), "m/s");
  EXPECT_EQ(mill::post::dataset_unit(file, "rho"), "kg/m^3");
  EXPECT_EQ(mill::post::dataset_unit(file, "mask"), "1");
  EXPECT_EQ(mill::post::dataset_unit(file, "k"), "m^2/s^2");
  EXPECT_EQ(mill::post::dataset_unit(file, "omega"), "1/s");
  EXPECT_FALSE(fs::exists(file.string() + ".tmp." + std::to_string(getpid())));
}

TEST(FlowFieldIo, DatasetShapesAreZYXAndComponents) {
  const auto f = sample_field(false);
  const auto file = tmp_file("shape.h5");
  mill::post::write_flow_field(file, f);
  hid_t h = H5Fopen(file.path().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(h, 0);
  hid_t ds = H5Dopen2(h, "U", H5P_DEFAULT);
  hid_t sp = H5Dget_space(ds);
  hsize_t dims[4];
  ASSERT_EQ(H5Sget_simple_extent_ndims(sp), 4);
  H5Sget_simple_extent_dims(sp, dims, nullptr);
  EXPECT_EQ(dims[0], 2u);
  EXPECT_EQ(dims[1], 3u);
  EXPECT_EQ(dims[2], 4u);
  EXPECT_EQ(dims[3], 3u);
  H5Sclose(sp);
  H5Dclose(ds);
  EXPECT_GT(H5Lexists(h, "mask", H5P_DEFAULT), 0);
  EXPECT_EQ(H5Lexists(h, "k", H5P_DEFAULT), 0) << "k only when sampled";
  H5Fclose(h);
  const auto g = mill::post::read_flow_field(file);
  EXPECT_TRUE(g.k.empty());
}

TEST(FlowFieldIo, TrilinearLookupIsExactForLinearFieldAndHonoursMask) {
  const auto f = sample_field(false);
  std::array<double, 3> u{};
  ASSERT_TRUE(f.velocity_at({-0.8, 0.6, 2.05}, u));
  EXPECT_NEAR(u[0], -0.8, 1e-12);
  EXPECT_NEAR(u[1], 1.2, 1e-12);
  EXPECT_NEAR(u[2], 6.15, 1e-12);
  EXPECT_FALSE(f.velocity_at({0.4, 0.95, 2.05}, u)) << "a corner (3,2,1) is outside the gas";
  EXPECT_FALSE(f.velocity_at({-1.1, 0.6, 2.05}, u)) << "off the grid";
}

// gas_at (the drag's one-pass lookup): the same u as velocity_at to the last
// bit, rho exact for the linear rho = 1 + x, and false (nothing written)
// where velocity_at is false.
TEST(FlowFieldIo, GasAtGivesVelocityAtsVelocityAndTheLinearDensity) {
  const auto f = sample_field(false);
  int checked = 0;
  for (double x = -1.0; x <= 0.5; x += 0.037)
    for (double y = 0.5; y <= 1.0; y += 0.041)
      for (double z = 2.0; z <= 2.1; z += 0.013) {
        std::array<double, 3> u1{}, u2{};
        double rho = -1;
        const bool a = f.velocity_at({x, y, z}, u1), b = f.gas_at({x, y, z}, u2, rho);
        ASSERT_EQ(a, b) << x << " " << y << " " << z;
        if (!a) {
          EXPECT_EQ(rho, -1);
          continue;
        }
        EXPECT_EQ(u1, u2);
        EXPECT_NEAR(rho, 1 + x, 1e-12);
        ++checked;
      }
  EXPECT_GT(checked, 100);
}

TEST(FlowFieldIo, ErrorsNameTheFileAndItem) {
  const auto absent = tmp_file("absent.h5"), bad = tmp_file("bad.h5");
  try {
    mill::post::read_flow_field(absent);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("absent.h5"), std::string::npos);
  }
  auto f = sample_field(false);
  f.rho.pop_back();
  EXPECT_THROW(mill::post::write_flow_field(bad, f), std::invalid_argument);
  // A file without the field datasets.
  const auto file = tmp_file("empty.h5");
  hid_t h = H5Fcreate(file.path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  H5Fclose(h);
  try {
    mill::post::read_flow_field(file);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("format_version"), std::string::npos) << e.what();
  }
}
