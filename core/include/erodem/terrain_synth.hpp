// erodem — seeded, reproducible synthetic terrain for controlled experiments
// (`erodem generate`, `[dem] synthetic = "..."`).
//
// Reproducibility: the generators use their own PRNG (splitmix64) and integer hashing,
// and only IEEE-754 correctly rounded operations (+, -, *, /, sqrt, floor, ldexp) with
// floating-point contraction (FMA fusion) disabled in terrain_synth.cpp, so the same
// arguments give bit-identical heights on every conforming machine and compiler.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// The synthetic terrain generators.
enum class SynthKind {
  fbm,             ///< fractal Brownian motion of 2-D Perlin gradient noise
  ridged,          ///< ridged multifractal: weighted octaves of (1 - |noise|)^2
  diamond_square,  ///< midpoint displacement on the next 2^k + 1 grid, cropped
  hill,            ///< one smooth Gaussian hill in the middle plus a little fbm
  lake,            ///< a closed circular depression (bowl) inside a raised rim
  valley,          ///< a valley sloping down towards +x (east) with a channel along its axis
  ridge,           ///< a ridge line along the grid diagonal, top-left to bottom-right
};

/// The generator names, in enum order: "fbm", "ridged", "diamond_square", "hill", "lake",
/// "valley", "ridge".
const std::vector<std::string>& synth_kind_names();

/// The name of `kind` (one of synth_kind_names()).
std::string to_string(SynthKind kind);

/// Parses a generator name (exact, lower case). Throws erodem::Error(ExitCode::usage)
/// listing the accepted names when `name` is none of them.
SynthKind synth_kind_from_string(const std::string& name);

/// Generates a synthetic terrain.
///
/// @param kind         the generator
/// @param nx           number of columns (cells, >= 1)
/// @param ny           number of rows (cells, >= 1); row 0 is the north edge
/// @param cell_size_m  horizontal cell size (m, finite, > 0). The shapes are defined
///                     relative to the grid extent (in cells), so the heights do not depend
///                     on it; it is validated so that callers cannot pass nonsense.
/// @param relief_m     elevation range (m, finite, > 0): the output spans [0, relief_m]
///                     (exactly 0 and relief_m at its minimum and maximum when nx*ny > 1)
/// @param seed         random seed (any value); the same seed gives bit-identical output
/// @return             nx * ny heights (m), row-major (index row * nx + col), in [0, relief_m]
///
/// Throws erodem::Error(ExitCode::usage) for non-positive sizes or a bad cell size or
/// relief, and when nx * ny exceeds 2^30 cells.
std::vector<double> generate_terrain(SynthKind kind, int nx, int ny, double cell_size_m,
                                     double relief_m, std::uint64_t seed);

/// Combines this process's least and largest value (`lo`, `hi`) with every other process's:
/// the MPI ranks', each of its own rows (io::load_terrain). nullptr: this process's are the
/// grid's.
using RangeReduce = std::function<void(double& lo, double& hi)>;

/// Rows [r0, r1) of generate_terrain(kind, nx, ny, ..., relief_m, seed) (row-major,
/// (r1 - r0) x nx), those rows of the whole grid bit for bit without making the others: each
/// cell's shape and noise are its own (diamond-square's lattices are made on the rows these
/// read of them: about 1.33 (r1 - r0) n values, n + 1 the lattice's side), and the ranges
/// that scale the noise and the heights are those of the
/// rows [o0, o1) this process owns (inside [r0, r1)) combined by `reduce` into the whole
/// grid's. The sizes, relief and seed are as generate_terrain checks them.
std::vector<double> generate_terrain_rows(SynthKind kind, int nx, int ny, double relief_m,
                                          std::uint64_t seed, int r0, int r1, int o0, int o1,
                                          const RangeReduce& reduce);

/// The rows of a synthetic terrain one process makes (make_synthetic_terrain): rows
/// [row0, row1) (row1 < 0: all), of which it owns [own0, own1), with `reduce` as
/// generate_terrain_rows takes it.
struct SynthRows {
  int row0 = 0, row1 = -1, own0 = 0, own1 = -1;
  RangeReduce reduce;
};

/// Fractal Brownian motion of 2-D Perlin gradient noise sampled at the cell centres of
/// `grid`, in metres: `octaves` octaves, the first with a lattice spacing (wavelength) of
/// `scale_m`, each next one with half the wavelength and half the amplitude (lacunarity 2,
/// gain 1/2). Cell (col, row) lies at x = (col + 1/2) dx(row) east and y = dy(0) + ... +
/// dy(row - 1) + dy(row) / 2 south of the grid's north-west corner, from the grid's per-row
/// cell sizes: exact on projected grids; on geographic grids a local (sheared) map whose
/// distances are right along each row and each column. The pattern is therefore one of
/// position in metres, not of the resolution: two grids whose cell centres coincide get the
/// same values there, bit for bit.
///
/// @param grid     the grid (validated)
/// @param scale_m  wavelength of the first octave (m, finite, > 0)
/// @param octaves  number of octaves (1 to 16)
/// @param seed     random seed (any value); the same seed gives bit-identical output
/// @return         grid.cells() values, row-major, unnormalised (roughly in [-2, 2])
///
/// Throws erodem::Error(ExitCode::usage) for a bad scale or octave count, or a scale so
/// small that the last octave spans more than 2^40 wavelengths of the grid.
std::vector<double> fbm_field(const Grid& grid, double scale_m, int octaves, std::uint64_t seed);

/// Rows [row0, row1) of fbm_field (row-major ((row1 - row0), nx)): those rows of the whole
/// field bit for bit, without computing the others. Throws Error(internal) for rows off the
/// grid, and as fbm_field.
std::vector<double> fbm_rows(const Grid& grid, double scale_m, int octaves, std::uint64_t seed,
                             int row0, int row1);

/// The erodibility R of `erosion.hardness = "noise"` on `terrain`'s grid: n = fbm_field(grid,
/// erosion.noise_scale, erosion.noise_octaves, erosion.noise_seed) mapped linearly onto [0, 1]
/// over the active cells (their minimum to 0, their maximum to 1), and R = 1 - a (1 - n) with
/// a = erosion.noise_amplitude, so R spans [1 - a, 1] and reaches both ends. Nodata cells, and
/// every cell when the active ones hold one value, get R = 1. Computed once in double on the
/// host; the backends round it like a hardness raster, so every backend sees the same values.
/// Throws erodem::Error(ExitCode::config) naming the key for an out-of-range noise setting.
std::vector<double> hardness_noise(const Terrain& terrain, const Params::Erosion& erosion);

/// Rows [row0, row1) of hardness_noise (row-major ((row1 - row0), nx)), bit for bit, holding
/// no field of the whole grid: the range of the active cells is found a block of rows at a
/// time (an MPI band's initial state: build_padded_state).
std::vector<double> hardness_noise_rows(const Terrain& terrain, const Params::Erosion& erosion,
                                        int row0, int row1);

/// Builds a Terrain from the `[dem]` synthetic settings: kind `dem.synthetic`, a square grid
/// of `dem.size` cells per side (Grid::uniform, no CRS), cell size `dem.cell_size` (m; 10 m
/// when 0), relief `dem.relief` (m), seed `dem.seed`. All cells active; `source` describes
/// the generator, e.g. "synthetic:fbm size=256 seed=1 relief=100 m cell=10 m".
/// Throws erodem::Error(ExitCode::config) naming the key for invalid settings.
/// With `rows` of some rows only (rows.row1 >= 0): the bed of those rows
/// (Terrain::row0, row1), as generate_terrain_rows makes them.
Terrain make_synthetic_terrain(const Params::Dem& dem, const SynthRows& rows = {});

}  // namespace erodem
