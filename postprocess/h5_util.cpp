// HDF5 plumbing shared by the postprocess/ writers and readers; see h5_util.h.
#include "postprocess/h5_util.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "postprocess/fragments.h"

namespace mill::post::h5 {

// The one wording of a failed HDF5 call.
void Fail(const std::string& where, const std::string& operation) {
  throw PostError(fmt::format("{}: HDF5 could not {}", where, operation));
}

// "file" for a file id, "file:/group/dataset" for an object in one.
std::string Where(hid_t obj) {
  const ssize_t file_len = H5Fget_name(obj, nullptr, 0);
  if (file_len < 0) return "(HDF5 object)";
  std::string file(static_cast<std::size_t>(file_len) + 1, '\0');
  H5Fget_name(obj, file.data(), file.size());
  file.resize(static_cast<std::size_t>(file_len));
  if (H5Iget_type(obj) == H5I_FILE) return file;
  const ssize_t path_len = H5Iget_name(obj, nullptr, 0);
  if (path_len <= 0) return file;
  std::string path(static_cast<std::size_t>(path_len) + 1, '\0');
  H5Iget_name(obj, path.data(), path.size());
  path.resize(static_cast<std::size_t>(path_len));
  return file + ":" + path;
}

// Throws when an HDF5 status is negative.
void Check(herr_t status, hid_t obj, const std::string& operation) {
  if (status < 0) Fail(Where(obj), operation);
}

// Takes an id made at an open object; throws if the call failed.
Handle::Handle(hid_t id, herr_t (*close)(hid_t), hid_t at, const std::string& operation)
    : id_(id), close_(close) {
  if (id_ < 0) Fail(Where(at), operation);
}

// Takes an id made on a file by path; throws if the call failed.
Handle::Handle(hid_t id, herr_t (*close)(hid_t), const std::string& path,
               const std::string& operation)
    : id_(id), close_(close) {
  if (id_ < 0) Fail(path, operation);
}

// Closes the id.
Handle::~Handle() {
  if (id_ >= 0) close_(id_);
}

// Saves HDF5's error printer and turns it off.
Quiet::Quiet() {
  H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

// Restores HDF5's error printer.
Quiet::~Quiet() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

// An existing file, read-only or read-write.
Handle OpenFile(const std::string& path, unsigned flags) {
  const char* mode = flags == H5F_ACC_RDONLY ? "reading" : "writing";
  return {H5Fopen(path.c_str(), flags, H5P_DEFAULT), H5Fclose, path,
          fmt::format("open the file for {} (missing, not HDF5, or damaged?)", mode)};
}

// A new group in loc.
Handle CreateGroup(hid_t loc, const std::string& name) {
  return {H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, loc,
          fmt::format("create group '{}'", name)};
}

// tmp filled by `write`, then renamed over path; tmp removed on error.
void WriteFileAtomically(const std::string& path, const std::string& tmp,
                         const std::function<void(hid_t file)>& write) {
  Quiet quiet;
  try {
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose, tmp,
                "create the file (does its folder exist, and may it be written?)");
    write(file);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  std::filesystem::rename(tmp, path);
}

// A scalar fixed-length string attribute.
void WriteStringAttr(hid_t obj, const std::string& name, const std::string& value) {
  const std::string op = fmt::format("create attribute '{}'", name);
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, obj, op);
  Check(H5Tset_size(type, std::max<std::size_t>(1, value.size())), obj, op);
  Check(H5Tset_strpad(type, H5T_STR_NULLTERM), obj, op);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, obj, op);
  Handle attr(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, obj,
              op);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  Check(H5Awrite(attr, type, padded.data()), obj, fmt::format("write attribute '{}'", name));
}

// A scalar or array numeric attribute.
void WriteAttr(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type,
               const void* value, const std::vector<hsize_t>& dims) {
  const std::string op = fmt::format("create attribute '{}'", name);
  Handle space(dims.empty() ? H5Screate(H5S_SCALAR)
                            : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
               H5Sclose, obj, op);
  Handle attr(H5Acreate2(obj, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              obj, op);
  Check(H5Awrite(attr, mem_type, value), obj, fmt::format("write attribute '{}'", name));
}

// A dataset with its unit.
Handle WriteDataset(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type,
                    const void* data, const std::vector<hsize_t>& dims, const std::string& unit,
                    hid_t dcpl) {
  const std::string op = fmt::format("create dataset '{}'", name);
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, loc,
               op);
  Handle set(H5Dcreate2(loc, name.c_str(), file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT),
             H5Dclose, loc, op);
  if (data) {
    Check(H5Dwrite(set, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), set, "write the values");
  }
  WriteStringAttr(set, "unit", unit);
  return set;
}

// float64 dataset.
void WriteDataset(hid_t loc, const std::string& name, const std::vector<double>& v,
                  const std::vector<hsize_t>& dims, const std::string& unit) {
  WriteDataset(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, v.empty() ? nullptr : v.data(), dims,
               unit);
}

// int64 dataset.
void WriteDataset(hid_t loc, const std::string& name, const std::vector<long long>& v,
                  const std::vector<hsize_t>& dims, const std::string& unit) {
  WriteDataset(loc, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, v.empty() ? nullptr : v.data(), dims,
               unit);
}

// A dataset's values as doubles.
std::vector<double> ReadDoubles(hid_t loc, const std::string& name) {
  const Quiet quiet;
  const std::string op = fmt::format("read dataset '{}'", name);
  if (H5Lexists(loc, name.c_str(), H5P_DEFAULT) <= 0) Fail(Where(loc), op + " (missing)");
  Handle set(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose, loc, op);
  Handle space(H5Dget_space(set), H5Sclose, loc, op);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n < 0) Fail(Where(set), op);
  std::vector<double> v(static_cast<std::size_t>(n));
  if (n > 0)
    Check(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), set, op);
  return v;
}

}  // namespace mill::post::h5
