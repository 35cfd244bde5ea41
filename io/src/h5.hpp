// erodem — HDF5 helpers of the result files (private to io/src): handles, errors, attributes
// written and read as netCDF-4 does, datasets, rows appended along the unlimited dimension;
// and the names of the gauge series, which the writer and the reader share (h5.cpp).
#pragma once

#include <hdf5.h>

#include <string>
#include <utility>
#include <vector>

#include "erodem/sections.hpp"

namespace erodem::io {

// ---- HDF5 handles and errors --------------------------------------------------------------

/// Turns HDF5's automatic error printing off on this thread for its lifetime (failures
/// become erodem::Error messages instead).
class QuietH5 {
 public:
  QuietH5() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietH5() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietH5(const QuietH5&) = delete;
  QuietH5& operator=(const QuietH5&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// ": <innermost HDF5 message>" or "" when the error stack is empty.
std::string h5_reason();
/// h5_reason() of a file that would not open or be created at `path`; when HDF5 says the
/// file is locked, also that another process has it open and which one when /proc/locks
/// tells (paths.hpp lock_holder).
std::string h5_open_reason(const std::string& path);

/// An owned HDF5 identifier of any kind, closed by its kind's close function.
class H5Id {
 public:
  H5Id() = default;
  explicit H5Id(hid_t id) : id_(id) {}
  ~H5Id() { reset(); }
  H5Id(H5Id&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)) {}
  H5Id& operator=(H5Id&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
    }
    return *this;
  }
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }  // NOLINT: handles are used as hid_t
  bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ < 0) return;
    switch (H5Iget_type(id_)) {
      case H5I_FILE:
        H5Fclose(id_);
        break;
      case H5I_GROUP:
        H5Gclose(id_);
        break;
      case H5I_DATASET:
        H5Dclose(id_);
        break;
      case H5I_DATASPACE:
        H5Sclose(id_);
        break;
      case H5I_DATATYPE:
        H5Tclose(id_);
        break;
      case H5I_ATTR:
        H5Aclose(id_);
        break;
      case H5I_GENPROP_LST:
        H5Pclose(id_);
        break;
      default:
        break;
    }
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
};

/// Thrown for a failed HDF5 call while writing `path`.
[[noreturn]] void write_failed(const std::string& path, const std::string& what);

H5Id checked(hid_t id, const std::string& path, const std::string& what);
void checked(herr_t status, const std::string& path, const std::string& what);

constexpr unsigned kCreationOrder = H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED;

// ---- MPI: one result file written by every rank (parallel HDF5) ----------------------------

// collective_files() (results.hpp): every rank makes the same HDF5 calls, in the same order,
// with the same values, on one file (MPI-IO). What changes the file's structure (datasets,
// attributes, extents, flushes) is collective in parallel HDF5, and so is every write here (a
// compressed dataset takes no other).

/// The access properties of a result file: MPI-IO over every rank where collective_files(),
/// else HDF5's defaults.
H5Id file_access(const std::string& path);

/// Rank 0's `value` on every rank where collective_files() (collective), else `value`.
std::string root_text(const std::string& value);

/// Writes `data`, which every rank holds alike, to the selection of `file_space` (H5S_ALL: the
/// whole dataset) from `mem_space`: collectively, rank 0's values, where collective_files();
/// as one H5Dwrite otherwise.
void write_shared(hid_t ds, hid_t mem_type, hid_t mem_space, hid_t file_space, const void* data,
                  const std::string& path, const std::string& name);

// ---- attributes -----------------------------------------------------------------------------

/// A text attribute as netCDF-4 writes one (NC_CHAR: fixed-length string, scalar). Values
/// shorter than 2 bytes are null-padded to 2 so that h5py/h5netcdf decode them to str. Where
/// collective_files(), rank 0's value (the time of `created` may differ between ranks).
void put_text(hid_t obj, const char* name, const std::string& value, const std::string& path);

/// A numeric attribute: one value (scalar) or an array.
void put_numbers(hid_t obj, const char* name, hid_t file_type, hid_t mem_type, const void* data,
                 hsize_t n, const std::string& path);

/// A text attribute (fixed or variable length); false when absent or not text.
bool get_text(hid_t obj, const char* name, std::string& out);

// ---- datasets -------------------------------------------------------------------------------

/// Creates a dataset as netCDF-4 does (attribute creation order, no time stamps).
/// `chunk` empty = contiguous; `compress` = shuffle + deflate 4; `fill` = fill value.
H5Id create_dataset(hid_t loc, const std::string& name, hid_t type,
                    const std::vector<hsize_t>& dims, const std::vector<hsize_t>& maxdims,
                    const std::vector<hsize_t>& chunk, bool compress, const void* fill,
                    const std::string& path);

/// Appends `rows` rows to dataset `ds` along its first (unlimited) dimension.
void append_rows(hid_t ds, hid_t mem_type, hsize_t rows, const void* data, const std::string& path,
                 const std::string& name);

/// Reads row `row` (along the first dimension) of dataset `ds` into `data`, as `mem_type`.
void read_row(hid_t ds, hid_t mem_type, hsize_t row, void* data, const std::string& path,
              const std::string& name);

/// Adds one row along the first (unlimited) dimension of dataset `ds` (its fill value until
/// written); returns that row's index.
hsize_t grow_row(hid_t ds, const std::string& path, const std::string& name);

/// Writes (write_strip) or reads (read_strip) `data`, the rows [y0, y0 + rows) of row
/// `index` of a dataset (time, y, x): a snapshot's field a strip at a time. Where
/// collective_files(), write_strip is collective and each rank gives the rows it computed
/// (Simulation::own_field_rows; `rows` 0: none); read_strip reads independently.
void write_strip(hid_t ds, hid_t mem_type, hsize_t index, hsize_t y0, hsize_t rows,
                 const void* data, const std::string& path, const std::string& name);
void read_strip(hid_t ds, hid_t mem_type, hsize_t index, hsize_t y0, hsize_t rows, void* data,
                const std::string& path, const std::string& name);

/// Whether `path` names an existing object (every link on the way exists).
bool exists(hid_t loc, const std::string& path);

// ---- the layout -----------------------------------------------------------------------------

/// The series of gauges/, in the order of GaugeSeries (the writer's and the reader's).
constexpr const char* kGaugeSeries[] = {"water_depth", "water_level", "speed"};

/// The per-step series of sections/, (step, section), in file order (sections.hpp).
struct SectionSeriesInfo {
  const char* name;
  double SectionState::*member;
  const char* units;
  const char* long_name;
};
inline constexpr SectionSeriesInfo kSectionSeries[] = {
    {"discharge", &SectionState::discharge, "m3 s-1", "discharge through the section in the step"},
    {"sediment_flux", &SectionState::sediment_flux, "m3 s-1",
     "solid sediment volume per second through the section in the step"},
    {"volume", &SectionState::volume, "m3", "cumulative water volume through the section"},
    {"sediment_volume", &SectionState::sediment_volume, "m3",
     "cumulative solid sediment volume through the section"},
};

}  // namespace erodem::io
