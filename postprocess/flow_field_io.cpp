// Uniform-grid gas field in HDF5: writer, reader, trilinear lookup.
#include "postprocess/flow_field_io.h"

#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace mill::post {
namespace fs = std::filesystem;

namespace {

constexpr int kFormatVersion = 1;
constexpr const char* kIndexOrder = "[z][y][x] (x fastest); U adds a last axis of 3 components";

// Owns an HDF5 handle and closes it with the matching close function.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error(what);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Silence HDF5's own error stack printing while this object lives.
class QuietHdf5 {
 public:
  QuietHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// Attach a string attribute to an object.
void put_string(hid_t obj, const char* name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "H5Tcopy");
  H5Tset_size(type, value.empty() ? 1 : value.size());
  H5Tset_strpad(type, H5T_STR_NULLTERM);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "H5Screate");
  Handle attr(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("cannot create attribute ") + name);
  if (H5Awrite(attr, type, value.c_str()) < 0)
    throw std::runtime_error(std::string("cannot write attribute ") + name);
}

// Attach a 1-D numeric attribute of n values.
template <typename T>
void put_array(hid_t obj, const char* name, hid_t type, const T* v, hsize_t n) {
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose, "H5Screate_simple");
  Handle attr(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("cannot create attribute ") + name);
  if (H5Awrite(attr, type, v) < 0)
    throw std::runtime_error(std::string("cannot write attribute ") + name);
}

// Read a string attribute; "" if absent.
std::string get_string(hid_t obj, const char* name) {
  QuietHdf5 quiet;
  if (H5Aexists(obj, name) <= 0) return "";
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose,
              std::string("cannot open attribute ") + name);
  Handle ftype(H5Aget_type(attr), H5Tclose, "H5Aget_type");
  if (H5Tget_class(ftype) != H5T_STRING) return "";
  if (H5Tis_variable_str(ftype) > 0) {
    char* s = nullptr;
    Handle mtype(H5Tcopy(H5T_C_S1), H5Tclose, "H5Tcopy");
    H5Tset_size(mtype, H5T_VARIABLE);
    if (H5Aread(attr, mtype, &s) < 0 || !s) return "";
    std::string out(s);
    H5free_memory(s);
    return out;
  }
  const size_t n = H5Tget_size(ftype);
  std::string buf(n, '\0');
  Handle mtype(H5Tcopy(H5T_C_S1), H5Tclose, "H5Tcopy");
  H5Tset_size(mtype, n);
  if (H5Aread(attr, mtype, buf.data()) < 0) return "";
  buf.resize(buf.find('\0') == std::string::npos ? n : buf.find('\0'));
  return buf;
}

// Read a numeric attribute of exactly n values; throws naming it otherwise.
template <typename T>
void get_array(hid_t obj, const char* name, hid_t mtype, T* out, hsize_t n, const fs::path& file) {
  QuietHdf5 quiet;
  if (H5Aexists(obj, name) <= 0)
    throw std::runtime_error(file.string() + ": missing attribute '" + name + "'");
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose,
              std::string("cannot open attribute ") + name);
  Handle space(H5Aget_space(attr), H5Sclose, "H5Aget_space");
  if (static_cast<hsize_t>(H5Sget_simple_extent_npoints(space)) != n)
    throw std::runtime_error(file.string() + ": attribute '" + name + "' should hold " +
                             std::to_string(n) + " values");
  if (H5Aread(attr, mtype, out) < 0)
    throw std::runtime_error(file.string() + ": cannot read attribute '" + name + "'");
}

// Write one dataset of the given shape with its unit attribute (gzip-compressed).
void put_dataset(hid_t file, const char* name, hid_t ftype, hid_t mtype, const void* data,
                 const std::vector<hsize_t>& shape, const std::string& unit,
                 const std::string& doc) {
  Handle space(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose,
               "H5Screate_simple");
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "H5Pcreate");
  std::vector<hsize_t> chunk = shape;
  chunk[0] = 1;  // one z-slab per chunk
  H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data());
  H5Pset_deflate(dcpl, 4);
  Handle ds(H5Dcreate2(file, name, ftype, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose,
            std::string("cannot create dataset ") + name);
  if (H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw std::runtime_error(std::string("cannot write dataset ") + name);
  put_string(ds, "unit", unit);
  put_string(ds, "description", doc);
}

// Read a dataset whose total size must be n values.
template <typename T>
std::vector<T> get_dataset(hid_t file, const char* name, hid_t mtype, size_t n,
                           const fs::path& path, bool optional) {
  QuietHdf5 quiet;
  if (H5Lexists(file, name, H5P_DEFAULT) <= 0) {
    if (optional) return {};
    throw std::runtime_error(path.string() + ": missing dataset '/" + name + "'");
  }
  Handle ds(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose,
            std::string("cannot open dataset ") + name);
  Handle space(H5Dget_space(ds), H5Sclose, "H5Dget_space");
  if (static_cast<size_t>(H5Sget_simple_extent_npoints(space)) != n)
    throw std::runtime_error(path.string() + ": dataset '/" + name + "' has " +
                             std::to_string(H5Sget_simple_extent_npoints(space)) +
                             " values, dims say " + std::to_string(n));
  std::vector<T> v(n);
  if (H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
    throw std::runtime_error(path.string() + ": cannot read dataset '/" + name + "'");
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
  int idx[3];
  double w[3];
  for (int d = 0; d < 3; ++d) {
    const double s = (x[d] - origin[d]) / spacing[d];
    if (!(s >= 0) || s > dims[d] - 1) return false;
    idx[d] = std::min(static_cast<int>(std::floor(s)), std::max(dims[d] - 2, 0));
    w[d] = dims[d] > 1 ? s - idx[d] : 0.0;
  }
  std::array<double, 3> acc{0, 0, 0};
  for (int c = 0; c < 8; ++c) {
    const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    const double wt = (di ? w[0] : 1 - w[0]) * (dj ? w[1] : 1 - w[1]) * (dk ? w[2] : 1 - w[2]);
    const int i = std::min(idx[0] + di, dims[0] - 1), j = std::min(idx[1] + dj, dims[1] - 1),
              kk = std::min(idx[2] + dk, dims[2] - 1);
    const size_t p = point(i, j, kk);
    if (wt > 0 && !mask[p]) return false;
    for (int d = 0; d < 3; ++d) acc[d] += wt * U[3 * p + d];
  }
  u = acc;
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
  const fs::path tmp = file.string() + ".tmp." + std::to_string(getpid());
  {
    Handle h(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
             "cannot create " + tmp.string());
    const int version = kFormatVersion;
    put_array(h, "format_version", H5T_NATIVE_INT, &version, 1);
    put_array(h, "dims", H5T_NATIVE_INT, f.dims.data(), 3);
    put_array(h, "origin", H5T_NATIVE_DOUBLE, f.origin.data(), 3);
    put_array(h, "spacing", H5T_NATIVE_DOUBLE, f.spacing.data(), 3);
    put_array(h, "rpm", H5T_NATIVE_DOUBLE, &f.rpm, 1);
    put_string(h, "length_unit", "m");
    put_string(h, "index_order", kIndexOrder);
    put_string(h, "frame", "absolute");
    put_string(h, "gas_model", f.gas_model);
    put_string(h, "source", f.source);

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
    if (H5Fflush(h, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error("cannot flush " + tmp.string());
  }
  fs::rename(tmp, file);
}

// Read and check sizes against the dims attribute.
FlowField read_flow_field(const fs::path& file) {
  if (!fs::exists(file)) throw std::runtime_error(file.string() + ": no such file");
  QuietHdf5 quiet;
  Handle h(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose,
           file.string() + ": not an HDF5 file or unreadable");
  FlowField f;
  int version = 0;
  get_array(h, "format_version", H5T_NATIVE_INT, &version, 1, file);
  if (version != kFormatVersion)
    throw std::runtime_error(file.string() + ": format_version " + std::to_string(version) +
                             " is not supported (expected " + std::to_string(kFormatVersion) + ")");
  get_array(h, "dims", H5T_NATIVE_INT, f.dims.data(), 3, file);
  get_array(h, "origin", H5T_NATIVE_DOUBLE, f.origin.data(), 3, file);
  get_array(h, "spacing", H5T_NATIVE_DOUBLE, f.spacing.data(), 3, file);
  get_array(h, "rpm", H5T_NATIVE_DOUBLE, &f.rpm, 1, file);
  for (int d = 0; d < 3; ++d)
    if (f.dims[d] < 1 || !(f.spacing[d] > 0))
      throw std::runtime_error(file.string() + ": bad dims/spacing attributes");
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
  QuietHdf5 quiet;
  Handle h(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose,
           file.string() + ": cannot open");
  if (H5Lexists(h, dataset.c_str(), H5P_DEFAULT) <= 0) return "";
  Handle ds(H5Dopen2(h, dataset.c_str(), H5P_DEFAULT), H5Dclose, "cannot open " + dataset);
  return get_string(ds, "unit");
}

}  // namespace mill::post
