// erodem — HDF5 helpers of the result files (h5.hpp): error messages, attributes, datasets
// and appended rows.
#include "h5.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <utility>

#include "erodem/error.hpp"
#include "erodem/io/paths.hpp"
#include "erodem/io/results.hpp"
#include "erodem/parallel.hpp"

namespace erodem::io {

void skip_hdf5_exit_cleanup() {
  H5dont_atexit();
}

std::string h5_reason() {
  std::string msg;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
        if (n == 0 && e->desc != nullptr) *static_cast<std::string*>(out) = e->desc;
        return 0;
      },
      &msg);
  return msg.empty() ? "" : ": " + msg;
}

std::string h5_open_reason(const std::string& path) {
  std::string reason = h5_reason();
  bool lock = false;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* e, void* out) -> herr_t {
        if (e->desc != nullptr && std::strstr(e->desc, "lock") != nullptr)
          *static_cast<bool*>(out) = true;
        return 0;
      },
      &lock);
  if (!lock) return reason;
  const std::string holder = lock_holder(path);
  return reason + "; another process has it open (HDF5 file lock" +
         (holder.empty() || holder == "another process" ? "" : ", held by " + holder) + ")";
}

[[noreturn]] void write_failed(const std::string& path, const std::string& what) {
  throw Error(ExitCode::io, path + ": writing " + what + " failed" + h5_reason());
}

H5Id checked(hid_t id, const std::string& path, const std::string& what) {
  if (id < 0) write_failed(path, what);
  return H5Id(id);
}
void checked(herr_t status, const std::string& path, const std::string& what) {
  if (status < 0) write_failed(path, what);
}

bool built_with_parallel_hdf5() {
#ifdef ERODEM_PARALLEL_HDF5
  return true;
#else
  return false;
#endif
}

bool collective_files() {
  return built_with_parallel_hdf5() && parallel::size() > 1;
}

H5Id file_access(const std::string& path) {
  H5Id fapl = checked(H5Pcreate(H5P_FILE_ACCESS), path, "file access properties");
#ifdef ERODEM_PARALLEL_HDF5
  if (collective_files())
    checked(H5Pset_fapl_mpio(fapl, MPI_COMM_WORLD, MPI_INFO_NULL), path, "MPI-IO file access");
#endif
  return fapl;
}

std::string root_text(const std::string& value) {
  return collective_files() ? parallel::root_string(value) : value;
}

namespace {

/// The transfer properties of a write: collective MPI-IO where collective_files().
H5Id write_transfer(const std::string& path) {
  H5Id dxpl = checked(H5Pcreate(H5P_DATASET_XFER), path, "transfer properties");
#ifdef ERODEM_PARALLEL_HDF5
  if (collective_files())
    checked(H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE), path, "collective transfer");
#endif
  return dxpl;
}

/// The dataset's type in memory (native): a collective write that would convert types falls
/// back to independent I/O, which a compressed dataset refuses, so the writes convert first.
H5Id native_type(hid_t ds, const std::string& path, const std::string& name) {
  const H5Id file_type = checked(H5Dget_type(ds), path, name);
  return checked(H5Tget_native_type(file_type, H5T_DIR_ASCEND), path, name);
}

/// `n` values of `mem_type` at `data` as `type` (native_type): the conversion H5Dwrite makes
/// (H5Tconvert), so the file holds the same bits.
std::vector<unsigned char> converted(hid_t type, hid_t mem_type, std::size_t n, const void* data,
                                     const std::string& path, const std::string& name) {
  const std::size_t from = H5Tget_size(mem_type), to = H5Tget_size(type);
  std::vector<unsigned char> bytes(n * std::max(from, to));
  if (n == 0) return bytes;
  std::memcpy(bytes.data(), data, n * from);
  if (H5Tequal(type, mem_type) <= 0)
    checked(H5Tconvert(mem_type, type, n, bytes.data(), nullptr, H5P_DEFAULT), path,
            name + " (converting)");
  return bytes;
}

}  // namespace

void write_shared(hid_t ds, hid_t mem_type, hid_t mem_space, hid_t file_space, const void* data,
                  const std::string& path, const std::string& name) {
  if (!collective_files()) {
    checked(H5Dwrite(ds, mem_type, mem_space, file_space, H5P_DEFAULT, data), path, name);
    return;
  }
  const H5Id dxpl = write_transfer(path);
  if (parallel::rank() == 0) {
    H5Id all;
    if (mem_space == H5S_ALL) all = checked(H5Dget_space(ds), path, name);
    // the memory space's whole extent: `data` holds it (callers select all of it)
    const hssize_t n = H5Sget_simple_extent_npoints(mem_space == H5S_ALL ? all.get() : mem_space);
    const H5Id type = native_type(ds, path, name);
    const auto bytes = converted(type, mem_type, static_cast<std::size_t>(n), data, path, name);
    checked(H5Dwrite(ds, type, mem_space, file_space, dxpl, bytes.data()), path, name);
    return;
  }
  // the other ranks take part in the collective write with nothing selected
  H5Id none_file = checked(H5Dget_space(ds), path, name);
  H5Sselect_none(none_file);
  const hsize_t one = 1;
  H5Id none_mem = checked(H5Screate_simple(1, &one, nullptr), path, name);
  H5Sselect_none(none_mem);
  checked(H5Dwrite(ds, native_type(ds, path, name), none_mem, none_file, dxpl, data), path, name);
}

void put_text(hid_t obj, const char* name, const std::string& text, const std::string& path) {
  const std::string value = root_text(text);
  const std::size_t size = std::max<std::size_t>(value.size(), 2);
  std::string buf = value;
  buf.resize(size, '\0');
  const bool ascii = std::all_of(value.begin(), value.end(),
                                 [](char c) { return static_cast<unsigned char>(c) < 0x80; });
  H5Id type = checked(H5Tcopy(H5T_C_S1), path, "a string type");
  H5Tset_size(type, size);
  H5Tset_strpad(type, H5T_STR_NULLTERM);
  H5Tset_cset(type, ascii ? H5T_CSET_ASCII : H5T_CSET_UTF8);
  H5Id space = checked(H5Screate(H5S_SCALAR), path, "a dataspace");
  H5Id attr = checked(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT), path,
                      std::string("attribute ") + name);
  checked(H5Awrite(attr, type, buf.data()), path, std::string("attribute ") + name);
}

void put_numbers(hid_t obj, const char* name, hid_t file_type, hid_t mem_type, const void* data,
                 hsize_t n, const std::string& path) {
  H5Id space = checked(n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), path,
                       "a dataspace");
  H5Id attr = checked(H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT), path,
                      std::string("attribute ") + name);
  checked(H5Awrite(attr, mem_type, data), path, std::string("attribute ") + name);
}

bool get_text(hid_t obj, const char* name, std::string& out) {
  if (H5Aexists(obj, name) <= 0) return false;
  H5Id attr(H5Aopen(obj, name, H5P_DEFAULT));
  if (!attr.valid()) return false;
  H5Id type(H5Aget_type(attr));
  if (H5Tget_class(type) != H5T_STRING) return false;
  H5Id space(H5Aget_space(attr));
  if (H5Sget_simple_extent_npoints(space) != 1) return false;
  if (H5Tis_variable_str(type) > 0) {
    H5Id mem(H5Tcopy(H5T_C_S1));
    H5Tset_size(mem, H5T_VARIABLE);
    H5Tset_cset(mem, H5Tget_cset(type));
    char* s = nullptr;
    if (H5Aread(attr, mem, &s) < 0) return false;
    out = s != nullptr ? s : "";
    H5free_memory(s);
    return true;
  }
  const std::size_t size = H5Tget_size(type);
  std::string buf(size, '\0');
  if (H5Aread(attr, type, buf.data()) < 0) return false;
  buf.resize(std::strlen(buf.c_str()));
  out = buf;
  return true;
}

H5Id create_dataset(hid_t loc, const std::string& name, hid_t type,
                    const std::vector<hsize_t>& dims, const std::vector<hsize_t>& maxdims,
                    const std::vector<hsize_t>& chunk, bool compress, const void* fill,
                    const std::string& path) {
  H5Id space = checked(
      dims.empty() ? H5Screate(H5S_SCALAR)
                   : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), maxdims.data()),
      path, "dataspace of " + name);
  H5Id dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), path, "properties of " + name);
  H5Pset_attr_creation_order(dcpl, kCreationOrder);
  H5Pset_obj_track_times(dcpl, 0);
  if (!chunk.empty()) {
    checked(H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data()), path,
            "chunks of " + name);
    if (compress) {
      checked(H5Pset_shuffle(dcpl), path, "shuffle filter of " + name);
      checked(H5Pset_deflate(dcpl, 4), path, "deflate filter of " + name);
    }
  }
  if (fill != nullptr) checked(H5Pset_fill_value(dcpl, type, fill), path, "fill of " + name);
  // Compressed (field) datasets are written a whole chunk at a time (the writer's strips), so
  // they need no chunk cache: HDF5's default keeps up to 1 MiB per open dataset, 25 MiB for
  // the fields of a run's result file at 512^2 chunks, for the whole run.
  H5Id dapl = checked(H5Pcreate(H5P_DATASET_ACCESS), path, "access properties of " + name);
  if (!chunk.empty() && compress)
    checked(H5Pset_chunk_cache(dapl, H5D_CHUNK_CACHE_NSLOTS_DEFAULT, 0, H5D_CHUNK_CACHE_W0_DEFAULT),
            path, "chunk cache of " + name);
  return checked(H5Dcreate2(loc, name.c_str(), type, space, H5P_DEFAULT, dcpl, dapl), path,
                 "dataset " + name);
}

void append_rows(hid_t ds, hid_t mem_type, hsize_t rows, const void* data, const std::string& path,
                 const std::string& name) {
  if (rows == 0) return;
  H5Id space = checked(H5Dget_space(ds), path, name);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  start[0] = dims[0];
  count[0] = rows;
  dims[0] += rows;
  checked(H5Dset_extent(ds, dims.data()), path, "(extending) " + name);
  H5Id file_space = checked(H5Dget_space(ds), path, name);
  checked(
      H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
      path, name);
  H5Id mem_space = checked(H5Screate_simple(rank, count.data(), nullptr), path, name);
  write_shared(ds, mem_type, mem_space, file_space, data, path, name);
}

void read_row(hid_t ds, hid_t mem_type, hsize_t row, void* data, const std::string& path,
              const std::string& name) {
  H5Id space = checked(H5Dget_space(ds), path, name);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  start[0] = row;
  count[0] = 1;
  checked(H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
          path, name);
  H5Id mem_space = checked(H5Screate_simple(rank, count.data(), nullptr), path, name);
  checked(H5Dread(ds, mem_type, mem_space, space, H5P_DEFAULT, data), path, "(reading) " + name);
}

hsize_t grow_row(hid_t ds, const std::string& path, const std::string& name) {
  H5Id space = checked(H5Dget_space(ds), path, name);
  std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  const hsize_t index = dims[0]++;
  checked(H5Dset_extent(ds, dims.data()), path, "(extending) " + name);
  return index;
}

namespace {

/// The file and memory spaces of rows [y0, y0 + rows) of row `index` of a dataset (time, y, x).
std::pair<H5Id, H5Id> strip_spaces(hid_t ds, hsize_t index, hsize_t y0, hsize_t rows,
                                   const std::string& path, const std::string& name) {
  H5Id space = checked(H5Dget_space(ds), path, name);
  std::array<hsize_t, 3> dims{};
  if (H5Sget_simple_extent_ndims(space) != 3)
    throw Error(ExitCode::internal, path + ": " + name + " is not a dataset (time, y, x)");
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  const std::array<hsize_t, 3> start{index, y0, 0}, count{1, rows, dims[2]};
  checked(H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
          path, name);
  H5Id memory = checked(H5Screate_simple(3, count.data(), nullptr), path, name);
  return {std::move(space), std::move(memory)};
}

}  // namespace

void write_strip(hid_t ds, hid_t mem_type, hsize_t index, hsize_t y0, hsize_t rows,
                 const void* data, const std::string& path, const std::string& name) {
  if (!collective_files()) {
    const auto [file_space, mem_space] = strip_spaces(ds, index, y0, rows, path, name);
    checked(H5Dwrite(ds, mem_type, mem_space, file_space, H5P_DEFAULT, data), path, name);
    return;
  }
  // every rank in the collective write, with its rows or with none selected
  const auto [file_space, mem_space] =
      strip_spaces(ds, index, y0, std::max<hsize_t>(rows, 1), path, name);
  if (rows == 0) {
    H5Sselect_none(file_space);
    H5Sselect_none(mem_space);
  }
  std::array<hsize_t, 3> dims{};
  H5Sget_simple_extent_dims(file_space, dims.data(), nullptr);
  const H5Id type = native_type(ds, path, name);
  const auto bytes =
      converted(type, mem_type, static_cast<std::size_t>(rows * dims[2]), data, path, name);
  checked(H5Dwrite(ds, type, mem_space, file_space, write_transfer(path), bytes.data()), path,
          name);
}

void read_strip(hid_t ds, hid_t mem_type, hsize_t index, hsize_t y0, hsize_t rows, void* data,
                const std::string& path, const std::string& name) {
  const auto [file_space, mem_space] = strip_spaces(ds, index, y0, rows, path, name);
  checked(H5Dread(ds, mem_type, mem_space, file_space, H5P_DEFAULT, data), path,
          "(reading) " + name);
}

bool exists(hid_t loc, const std::string& path) {
  std::size_t pos = 0;
  while (true) {
    pos = path.find('/', pos + 1);
    const std::string part = path.substr(0, pos);
    if (H5Lexists(loc, part.c_str(), H5P_DEFAULT) <= 0) return false;
    if (pos == std::string::npos) return true;
  }
}

}  // namespace erodem::io
