// Uniform-grid gas field in HDF5: writer, reader, trilinear lookup.
#include "postprocess/flow_field_io.h"

#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <stdexcept>
#include <utility>

#include "postprocess/fragments.h"
#include "postprocess/h5_util.h"

namespace mill::post {
namespace fs = std::filesystem;

namespace {

constexpr int kFormatVersion = 1;
constexpr const char* kIndexOrder = "[z][y][x] (x fastest); U adds a last axis of 3 components";

using h5::Handle;

// Attaches a 1-D numeric attribute of n values, stored as `type` itself.
template <typename T>
void put_array(hid_t obj, const char* name, hid_t type, const T* v, hsize_t n) {
  h5::WriteAttr(obj, name, type, type, v, {n});
}

// Reads a string attribute; "" if absent.
std::string get_string(hid_t obj, const char* name) {
  const h5::Quiet quiet;
  if (H5Aexists(obj, name) <= 0) return "";
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, obj,
              std::string("open attribute '") + name + "'");
  Handle ftype(H5Aget_type(attr), H5Tclose, obj, std::string("read attribute '") + name + "'");
  if (H5Tget_class(ftype) != H5T_STRING) return "";
  if (H5Tis_variable_str(ftype) > 0) {
    char* s = nullptr;
    Handle mtype(H5Tcopy(H5T_C_S1), H5Tclose, obj, std::string("read attribute '") + name + "'");
    H5Tset_size(mtype, H5T_VARIABLE);
    if (H5Aread(attr, mtype, &s) < 0 || !s) return "";
    std::string out(s);
    H5free_memory(s);
    return out;
  }
  const size_t n = H5Tget_size(ftype);
  std::string buf(n, '\0');
  Handle mtype(H5Tcopy(H5T_C_S1), H5Tclose, obj, std::string("read attribute '") + name + "'");
  H5Tset_size(mtype, n);
  if (H5Aread(attr, mtype, buf.data()) < 0) return "";
  buf.resize(buf.find('\0') == std::string::npos ? n : buf.find('\0'));
  return buf;
}

// Reads a numeric attribute of exactly n values; throws naming it otherwise.
template <typename T>
void get_array(hid_t obj, const char* name, hid_t mtype, T* out, hsize_t n, const fs::path& file) {
  const h5::Quiet quiet;
  if (H5Aexists(obj, name) <= 0)
    throw PostError(file.string() + ": missing attribute '" + name + "'");
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, obj,
              std::string("open attribute '") + name + "'");
  Handle space(H5Aget_space(attr), H5Sclose, obj, std::string("read attribute '") + name + "'");
  if (static_cast<hsize_t>(H5Sget_simple_extent_npoints(space)) != n)
    throw PostError(file.string() + ": attribute '" + name + "' should hold " + std::to_string(n) +
                    " values");
  h5::Check(H5Aread(attr, mtype, out), obj, std::string("read attribute '") + name + "'");
}

// Writes one dataset of the given shape, gzip-compressed in z-slabs, with its
// unit and description attributes.
void put_dataset(hid_t file, const char* name, hid_t ftype, hid_t mtype, const void* data,
                 const std::vector<hsize_t>& shape, const std::string& unit,
                 const std::string& doc) {
  const std::string op = std::string("create dataset '") + name + "'";
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, file, op);
  std::vector<hsize_t> chunk = shape;
  chunk[0] = 1;  // one z-slab per chunk
  h5::Check(H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data()), file, op);
  h5::Check(H5Pset_deflate(dcpl, 4), file, op);
  const Handle ds = h5::WriteDataset(file, name, ftype, mtype, data, shape, unit, dcpl);
  h5::WriteStringAttr(ds, "description", doc);
}

// Reads a dataset whose total size must be n values.
template <typename T>
std::vector<T> get_dataset(hid_t file, const char* name, hid_t mtype, size_t n,
                           const fs::path& path, bool optional) {
  const h5::Quiet quiet;
  if (H5Lexists(file, name, H5P_DEFAULT) <= 0) {
    if (optional) return {};
    throw PostError(path.string() + ": missing dataset '/" + name + "'");
  }
  Handle ds(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, file,
            std::string("open dataset '") + name + "'");
  Handle space(H5Dget_space(ds), H5Sclose, ds, "read the values");
  if (static_cast<size_t>(H5Sget_simple_extent_npoints(space)) != n)
    throw PostError(path.string() + ": dataset '/" + name + "' has " +
                    std::to_string(H5Sget_simple_extent_npoints(space)) + " values, dims say " +
                    std::to_string(n));
  std::vector<T> v(n);
  h5::Check(H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), ds, "read the values");
  return v;
}

}  // namespace

// Zero-filled arrays of the right sizes.
void FlowField::allocate(bool turbulence) {
  const size_t n = size();
  U.assign(3 * n, 0.0);
  rho.assign(n, 0.0);
  mask.assign(n, 0);
  k.assign(turbulence ? n : 0, 0.0);
  omega.assign(turbulence ? n : 0, 0.0);
}

// Trilinear interpolation inside a cell of 8 gas points.
bool FlowField::velocity_at(const std::array<double, 3>& x, std::array<double, 3>& u) const {
  return interpolate<false>(x, u, nullptr);
}

bool FlowField::gas_at(const std::array<double, 3>& x, std::array<double, 3>& u,
                       double& rho) const {
  return interpolate<true>(x, u, &rho);
}

template <bool kWithRho>
bool FlowField::interpolate(const std::array<double, 3>& x, std::array<double, 3>& u,
                            double* rho) const {
  int idx[3];
  double w[3];
  for (int d = 0; d < 3; ++d) {
    const double s = (x[d] - origin[d]) / spacing[d];
    if (!(s >= 0) || s > dims[d] - 1) return false;
    idx[d] = std::min(static_cast<int>(std::floor(s)), std::max(dims[d] - 2, 0));
    w[d] = dims[d] > 1 ? s - idx[d] : 0.0;
  }
  std::array<double, 3> acc{0, 0, 0};
  double r = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    const double wt = (di ? w[0] : 1 - w[0]) * (dj ? w[1] : 1 - w[1]) * (dk ? w[2] : 1 - w[2]);
    const int i = std::min(idx[0] + di, dims[0] - 1), j = std::min(idx[1] + dj, dims[1] - 1),
              kk = std::min(idx[2] + dk, dims[2] - 1);
    const size_t p = point(i, j, kk);
    if (wt > 0 && !mask[p]) return false;
    for (int d = 0; d < 3; ++d) acc[d] += wt * U[3 * p + d];
    if constexpr (kWithRho) r += wt * this->rho[p];
  }
  u = acc;
  if constexpr (kWithRho) *rho = r;
  return true;
}

// Everything into FILE.tmp.<pid>, then rename.
void write_flow_field(const fs::path& file, const FlowField& f) {
  const size_t n = f.size();
  if (n == 0)
    throw std::invalid_argument("write_flow_field: empty grid (dims " + std::to_string(f.dims[0]) +
                                "x" + std::to_string(f.dims[1]) + "x" + std::to_string(f.dims[2]) +
                                ")");
  if (f.U.size() != 3 * n || f.rho.size() != n || f.mask.size() != n)
    throw std::invalid_argument("write_flow_field: U, rho or mask size does not match dims");
  const bool turb = !f.k.empty() || !f.omega.empty();
  if (turb && (f.k.size() != n || f.omega.size() != n))
    throw std::invalid_argument("write_flow_field: k and omega must both match dims");

  if (!file.parent_path().empty()) fs::create_directories(file.parent_path());
  const std::string tmp = file.string() + ".tmp." + std::to_string(getpid());
  h5::WriteFileAtomically(file.string(), tmp, [&](hid_t h) {
    const int version = kFormatVersion;
    put_array(h, "format_version", H5T_NATIVE_INT, &version, 1);
    put_array(h, "dims", H5T_NATIVE_INT, f.dims.data(), 3);
    put_array(h, "origin", H5T_NATIVE_DOUBLE, f.origin.data(), 3);
    put_array(h, "spacing", H5T_NATIVE_DOUBLE, f.spacing.data(), 3);
    put_array(h, "rpm", H5T_NATIVE_DOUBLE, &f.rpm, 1);
    h5::WriteStringAttr(h, "length_unit", "m");
    h5::WriteStringAttr(h, "index_order", kIndexOrder);
    h5::WriteStringAttr(h, "frame", "absolute");
    h5::WriteStringAttr(h, "gas_model", f.gas_model);
    h5::WriteStringAttr(h, "source", f.source);

    const std::vector<hsize_t> s3{hsize_t(f.dims[2]), hsize_t(f.dims[1]), hsize_t(f.dims[0])};
    const std::vector<hsize_t> s4{s3[0], s3[1], s3[2], 3};
    put_dataset(h, "U", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, f.U.data(), s4, "m/s",
                "gas velocity, absolute (lab) frame; 0 where mask = 0");
    put_dataset(h, "rho", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, f.rho.data(), s3, "kg/m^3",
                "gas density; 0 where mask = 0");
    put_dataset(h, "mask", H5T_STD_U8LE, H5T_NATIVE_UINT8, f.mask.data(), s3, "1",
                "1 = point in the gas, 0 = inside a solid or outside the housing");
    if (turb) {
      put_dataset(h, "k", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, f.k.data(), s3, "m^2/s^2",
                  "turbulent kinetic energy");
      put_dataset(h, "omega", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, f.omega.data(), s3, "1/s",
                  "specific dissipation rate");
    }
    h5::Check(H5Fflush(h, H5F_SCOPE_GLOBAL), h, "flush the file");
  });
}

// Read and check sizes against the dims attribute.
FlowField read_flow_field(const fs::path& file) {
  if (!fs::exists(file)) throw PostError(file.string() + ": no such file");
  const h5::Quiet quiet;
  const Handle h = h5::OpenFile(file.string(), H5F_ACC_RDONLY);
  FlowField f;
  int version = 0;
  get_array(h, "format_version", H5T_NATIVE_INT, &version, 1, file);
  if (version != kFormatVersion)
    throw PostError(file.string() + ": format_version " + std::to_string(version) +
                    " is not supported (expected " + std::to_string(kFormatVersion) + ")");
  get_array(h, "dims", H5T_NATIVE_INT, f.dims.data(), 3, file);
  get_array(h, "origin", H5T_NATIVE_DOUBLE, f.origin.data(), 3, file);
  get_array(h, "spacing", H5T_NATIVE_DOUBLE, f.spacing.data(), 3, file);
  get_array(h, "rpm", H5T_NATIVE_DOUBLE, &f.rpm, 1, file);
  for (int d = 0; d < 3; ++d)
    if (f.dims[d] < 1 || !(f.spacing[d] > 0))
      throw PostError(file.string() + ": bad dims/spacing attributes");
  f.gas_model = get_string(h, "gas_model");
  f.source = get_string(h, "source");
  const size_t n = f.size();
  f.U = get_dataset<double>(h, "U", H5T_NATIVE_DOUBLE, 3 * n, file, false);
  f.rho = get_dataset<double>(h, "rho", H5T_NATIVE_DOUBLE, n, file, false);
  f.mask = get_dataset<std::uint8_t>(h, "mask", H5T_NATIVE_UINT8, n, file, false);
  f.k = get_dataset<double>(h, "k", H5T_NATIVE_DOUBLE, n, file, true);
  f.omega = get_dataset<double>(h, "omega", H5T_NATIVE_DOUBLE, n, file, true);
  return f;
}

// The "unit" attribute of one dataset.
std::string dataset_unit(const fs::path& file, const std::string& dataset) {
  const h5::Quiet quiet;
  const Handle h = h5::OpenFile(file.string(), H5F_ACC_RDONLY);
  if (H5Lexists(h, dataset.c_str(), H5P_DEFAULT) <= 0) return "";
  const Handle ds(H5Dopen2(h, dataset.c_str(), H5P_DEFAULT), H5Dclose, h,
                  "open dataset '" + dataset + "'");
  return get_string(ds, "unit");
}

}  // namespace mill::post
