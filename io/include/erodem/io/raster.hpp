// erodem — raster input and output through GDAL: DEMs, parameter rasters, GeoTIFF export.
//
// All functions are safe to call from several threads (GDAL is registered once, GDAL's own
// messages are silenced per thread and turned into erodem::Error messages) and release
// every GDAL handle on every path, errors included.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/io/geodesy.hpp"
#include "erodem/params.hpp"

namespace erodem::io {

/// Reads a DEM with GDAL (any raster format GDAL reads: GeoTIFF, PNG, ESRI ASCII, ...).
///
/// Uses these `[dem]` settings:
/// - `path`: the file; missing -> Error(ExitCode::no_input); not a raster GDAL can read or
///   unreadable -> Error(ExitCode::data).
/// - `window` (col, row, width, height; pixels): reads only that part; a window not inside
///   the raster -> Error(ExitCode::data) naming the window and the raster size. The grid's
///   geotransform is shifted to the window's top-left corner.
/// - `z_scale` (1): multiplies the stored values, after the band's own scale and offset.
/// - `cell_size` (m) and `crs`: only for files without georeferencing (see below).
///
/// Band 1 is read as double. Cells that are nodata (the band's nodata value, mask band or
/// alpha) or not finite get mask 0 and bed NaN; `mask` is left empty when every cell is
/// valid. A file without any valid cell -> Error(ExitCode::data).
///
/// Georeferencing: a file is georeferenced when it has a geotransform and a CRS (or was
/// written by write_geotiff() from a grid without CRS, whose transform is in metres).
/// - Projected (or local) CRS: the file's geotransform and CRS (WKT); dx = |pixel width|
///   and dy = |pixel height| times the CRS's linear unit in metres. Rotated geotransforms
///   -> Error(ExitCode::data).
/// - Geographic (lat/lon) CRS: `is_geographic` is true, the transform stays in the CRS's
///   angular unit (degrees), and the per-row cell sizes and areas are geodesic ones on the
///   CRS's own ellipsoid (semi-major axis and inverse flattening from the CRS; e.g. GRS80
///   for NAD83): see set_geographic_rows() in geodesy.hpp. Rotated geotransforms or
///   latitudes outside [-90, 90] -> Error(ExitCode::data).
/// - No geotransform, or no CRS: requires `dem.cell_size` > 0, else
///   Error(ExitCode::config, "<path>: has no georeferencing; set dem.cell_size (and
///   dem.crs) ..."). The grid is then Grid::uniform(width, height, cell_size) (origin (0, 0)
///   at the bottom-left corner) with `has_transform` false; `dem.crs` with it must be
///   projected. Alternatively, for a file with a geotransform but no CRS (an ESRI ASCII grid
///   without .prj), `dem.crs` alone takes the file's transform as given in that CRS: a
///   projected CRS (transform in its linear unit) or a geographic one ("EPSG:4326":
///   transform in degrees, cell sizes as above). `dem.crs` is anything GDAL recognises
///   ("EPSG:32610", WKT, PROJ string); it becomes `crs_wkt`.
/// - `dem.cell_size` or `dem.crs` given for a file that is georeferenced already ->
///   Error(ExitCode::config) (they never silently override the file).
///
/// `source` is the path and `source_sha256` the SHA-256 of the file's bytes (lower-case
/// hex). Only `grid`, `bed`, `mask`, `source` and `source_sha256` are filled.
///
/// `rows` = [row0, row1) (row1 >= 0; rows of the window): only those rows' elevations are
/// read (an MPI rank's band: load_terrain); the grid stays the whole window's, `bed` and
/// `mask` hold those rows only (the mask always, Terrain::row0 and row1 say which), nothing is
/// checked for valid cells (load_terrain asks every rank: terrain_rows.hpp) and no checksum is
/// taken (load_terrain takes rank 0's). Resampling is refused there (Error(internal): load_terrain
/// coarsens the rows read).
Terrain read_dem(const Params::Dem& dem, std::array<int, 2> rows = {0, -1});

/// The averaging factor that `dem.resample` / `dem.resample_factor` ask for on `grid`
/// (1 = none). A cell size that is not a whole multiple of the grid's, or a cell size in
/// metres for a geographic grid (whose cells vary by row), is a config error.
int resample_factor(const Params::Dem& dem, const Grid& grid);

/// Averages `factor` x `factor` blocks of valid cells into one coarser cell (a block with no
/// valid cell is nodata); cell sizes and areas grow accordingly (recomputed exactly on the
/// ellipsoid for a geographic grid), partial blocks at the east and south edges are dropped.
/// The notes are kept. A band's rows (`fine.banded`, whole blocks of them: load_terrain) give
/// the coarse rows of those blocks and their mask.
Terrain coarsen(const Terrain& fine, int factor);

/// What a raster file says about itself, without reading its values (`erodem info`).
struct RasterHeader {
  std::string driver;       ///< GDAL driver short name ("GTiff", "AAIGrid", "PNG")
  std::string driver_long;  ///< its long name ("GeoTIFF", "Arc/Info ASCII Grid")
  int nx = 0, ny = 0, bands = 0;
  std::string data_type;         ///< band 1's data type ("Int16", "Float32")
  std::optional<double> nodata;  ///< band 1's declared nodata value
  bool has_transform = false;
  std::array<double, 6> transform{0.0, 1.0, 0.0, 0.0, 0.0, -1.0};
  std::string crs_wkt;         ///< empty when the file names no CRS
  bool erodem_metres = false;  ///< no CRS, but written by write_geotiff(): transform in metres
};

/// Opens `path` and reads its header. Missing -> Error(ExitCode::no_input); not a raster
/// GDAL can read -> Error(ExitCode::data).
RasterHeader read_raster_header(const std::string& path);

/// A CRS described for people.
struct CrsInfo {
  std::string name;       ///< the CRS's own name ("WGS 84", "WGS 84 / UTM zone 11N")
  std::string authority;  ///< "EPSG:4326" when the CRS carries an authority code, else ""
  bool geographic = false;
  bool projected = false;
  std::string unit;          ///< its linear (projected) or angular (geographic) unit's name
  double unit_factor = 1.0;  ///< metres per linear unit, or degrees per angular unit
  Ellipsoid ellipsoid;       ///< the CRS's ellipsoid
  std::string wkt;           ///< the CRS as WKT (as a DEM's crs_wkt holds it)
};

/// Describes a CRS given as WKT (or anything GDAL's user input takes). An empty or
/// unparsable text -> Error(ExitCode::data).
CrsInfo describe_crs(const std::string& crs);

/// Reads band 1 of a parameter raster (rain factor, Manning n, hardness, initial depth,
/// ...) that must lie on `grid`: after applying `window` (col, row, width, height; pixels;
/// the DEM's window), its size must be grid.nx x grid.ny, else Error(ExitCode::data) naming
/// the key `what`, the file and both sizes. When both the raster and the grid carry a
/// geotransform, they must agree (origin and pixel size within 1e-6 of a cell), else
/// Error(ExitCode::data). Values are in the file's units (times the band's scale, plus its
/// offset); nodata and non-finite cells are NaN. Missing file -> Error(ExitCode::no_input),
/// unreadable -> Error(ExitCode::data); messages start with `what` and the path.
/// `rows` = [row0, row1) (row1 >= 0): the grid's rows [row0, row1) only, row-major.
std::vector<double> read_raster_on_grid(const std::string& path, const Grid& grid,
                                        const std::optional<std::array<int, 4>>& window,
                                        const std::string& what, std::array<int, 2> rows = {0, -1});

/// Every band of a raster on `grid` (as read_raster_on_grid reads band 1), in band order; with
/// `all_bands` false, band 1 only.
std::vector<std::vector<double>> read_raster_bands_on_grid(
    const std::string& path, const Grid& grid, const std::optional<std::array<int, 4>>& window,
    const std::string& what, bool all_bands = true, std::array<int, 2> rows = {0, -1});

/// A netCDF variable named in GDAL's syntax: NETCDF:"file.nc":var (or NETCDF:file.nc:var).
struct NetcdfName {
  std::string file, variable;
};
/// The file and variable of a path in GDAL's netCDF syntax; nullopt for any other path.
std::optional<NetcdfName> parse_netcdf_name(const std::string& path);
/// NETCDF:"file":variable.
std::string netcdf_name(const NetcdfName& n);

/// The times of a raster's bands (s) from a netCDF time coordinate: the time of band k less
/// that of band 1, from its CF units "<seconds|minutes|hours|days> since <date>"; empty for a
/// file without one (a GeoTIFF, a netCDF variable of one time or no time dimension). Errors
/// (ExitCode::data, starting with `what` and the path): a second dimension besides time, units
/// not of that form (months and years are not of fixed length), times not increasing.
std::vector<double> read_band_times(const std::string& path, const std::string& what);

/// The units of a raster's band 1 (GDAL's unit type: a netCDF variable's `units` attribute, a
/// GeoTIFF band's unit); "" when it has none.
std::string read_band_units(const std::string& path, const std::string& what);

/// Writes `values` (grid.nx * grid.ny, row-major, row 0 north) as a float32 GeoTIFF with
/// the grid's geotransform and CRS (WKT), DEFLATE-compressed (floating-point predictor,
/// tiled, BigTIFF when needed). `description` becomes the band description and the
/// TIFF image description; `nodata` the band's nodata value (NaN by default: NaN cells are
/// nodata). A grid without CRS is tagged so that read_dem() takes its transform as metres.
///
/// The file is written to a temporary file in the same directory and renamed into place
/// only when complete, so `path` never holds partial output. On failure the temporary file
/// is removed and Error(ExitCode::cant_create) (cannot create the file) or
/// Error(ExitCode::io) (writing failed) naming `path` is thrown. A values size that does
/// not match the grid -> Error(ExitCode::internal).
void write_geotiff(const std::string& path, const Grid& grid, const std::vector<float>& values,
                   const std::string& description,
                   double nodata = std::numeric_limits<double>::quiet_NaN());

/// write_geotiff with several bands (a time series of rasters: rain.grids), each
/// grid.nx * grid.ny values.
void write_geotiff_bands(const std::string& path, const Grid& grid,
                         const std::vector<std::vector<float>>& bands,
                         const std::string& description,
                         double nodata = std::numeric_limits<double>::quiet_NaN());

/// Writes `bands` (grid.nx * grid.ny values each, row-major, row 0 north) as the netCDF
/// variable `variable`(time, y, x) of a new file `path`, with the cell centres of the grid's
/// transform as the x and y coordinates (projection_x/y_coordinate, m) and a time coordinate
/// "time" of `times` in `time_units` (CF, e.g. "hours since 2000-01-01"; `times` and `bands`
/// of one size), the variable's `units` attribute `units` (none when empty). For tests and
/// examples of gridded forcing. Error(cant_create) when it cannot be written.
void write_netcdf_bands(const std::string& path, const Grid& grid, const std::string& variable,
                        const std::vector<std::vector<float>>& bands, const std::string& time_units,
                        const std::vector<double>& times, const std::string& units = "");

/// SHA-256 of a file's bytes as 64 lower-case hex digits (GDAL /vsi paths work too).
/// Throws Error(ExitCode::no_input) when the file cannot be opened, Error(ExitCode::io)
/// when reading fails.
std::string file_sha256(const std::string& path);

/// SHA-256 of a byte string as 64 lower-case hex digits.
std::string sha256_hex(const void* data, std::size_t size);

}  // namespace erodem::io
