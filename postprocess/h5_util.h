// HDF5 plumbing shared by every HDF5 writer and reader of postprocess/
// (breakage_results, flow_field_io, transport_h5): an owning handle, a
// silencer for HDF5's own error printing, the check of a status, and the few
// writes they all make. Every failed HDF5 call becomes one PostError worded
//   <file>[:/<object>]: HDF5 could not <operation>
// e.g. "run/breakage.h5.tmp:/impacts/v150.0_a90_r0: HDF5 could not create
// dataset 'mass'". Plain HDF5 C API; no driver/ includes.
#pragma once

#include <hdf5.h>

#include <functional>
#include <string>
#include <vector>

namespace mill::post::h5 {

// Throws the PostError "<where>: HDF5 could not <operation>".
[[noreturn]] void Fail(const std::string& where, const std::string& operation);

// The file an open object lives in, then ":/<its path>" unless it is the file
// itself; for messages.
std::string Where(hid_t obj);

// Throws Fail(Where(obj), operation) when an HDF5 call at obj returned < 0.
void Check(herr_t status, hid_t obj, const std::string& operation);

// Owns an HDF5 id and closes it with the matching H5*close. A negative id
// (the call that made it failed) throws, naming where and the operation.
class Handle {
 public:
  // An id made by `operation` at the open object `at`.
  Handle(hid_t id, herr_t (*close)(hid_t), hid_t at, const std::string& operation);
  // An id made by `operation` on the file `path` (creating or opening it).
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& path, const std::string& operation);
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  ~Handle();
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Silences HDF5's own printing of its error stack while it lives: failures
// reach the user as the PostError of Check or Handle only.
class Quiet {
 public:
  Quiet();
  ~Quiet();
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// Opens an existing file (flags H5F_ACC_RDONLY or H5F_ACC_RDWR).
Handle OpenFile(const std::string& path, unsigned flags);

// Creates the group `name` in loc.
Handle CreateGroup(hid_t loc, const std::string& name);

// Writes a file whole or not at all: `write` fills a new file at tmp, which
// is then renamed over path; on any error tmp is removed and the error passes
// on. HDF5's error printing is silenced meanwhile.
void WriteFileAtomically(const std::string& path, const std::string& tmp,
                         const std::function<void(hid_t file)>& write);

// Attaches a scalar string attribute (fixed length, null-terminated, at least
// one byte).
void WriteStringAttr(hid_t obj, const std::string& name, const std::string& value);

// Attaches a numeric attribute stored as file_type: a scalar when dims is
// empty, else an array of that shape.
void WriteAttr(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type,
               const void* value, const std::vector<hsize_t>& dims = {});

// Creates a dataset of the given shape stored as file_type (layout from dcpl),
// writes data unless it is null, and attaches its `unit` attribute. Returns
// the dataset, still open, for further attributes.
Handle WriteDataset(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type,
                    const void* data, const std::vector<hsize_t>& dims, const std::string& unit,
                    hid_t dcpl = H5P_DEFAULT);

// A dataset of doubles stored as float64 (nothing written when v is empty).
void WriteDataset(hid_t loc, const std::string& name, const std::vector<double>& v,
                  const std::vector<hsize_t>& dims, const std::string& unit);

// A dataset of integers stored as int64 (nothing written when v is empty).
void WriteDataset(hid_t loc, const std::string& name, const std::vector<long long>& v,
                  const std::vector<hsize_t>& dims, const std::string& unit);

// Every value of the dataset `name` in loc as doubles (any shape, row-major);
// throws naming the place when it is missing or cannot be read.
std::vector<double> ReadDoubles(hid_t loc, const std::string& name);

}  // namespace mill::post::h5
