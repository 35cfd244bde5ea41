// erodem — the typed parameter set of one run. Names follow MODEL.md / INTERFACES.md.
// Values are held in SI units (m, s, m/s, 1/s, degrees for angles). The schema that
// fills and validates this structure from TOML, `--set` and Python keywords lives in
// schema.hpp: it is the only place where keys, defaults, ranges and docs are written.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace erodem {

enum class FlowScheme { pipes, local_inertial, shallow_water };
enum class TransportScheme { conservative, semi_lagrangian };

/// The schemes' names as configs, HDF5 attributes and logs spell them.
inline const char* scheme_name(FlowScheme s) {
  return s == FlowScheme::pipes            ? "pipes"
         : s == FlowScheme::local_inertial ? "local_inertial"
                                           : "shallow_water";
}
inline const char* scheme_name(TransportScheme s) {
  return s == TransportScheme::conservative ? "conservative" : "semi_lagrangian";
}
/// periodic: the east and west edges joined (boundary.periodic_x; east and west only).
enum class BoundaryKind { closed, open, fixed_level, periodic };
/// erosion.law: the physical closures (docs/model.md 3.5) or Mei et al. (2007)'s capacity law.
enum class ErosionLaw { physical, mei };
/// A bed layer's closure: non-cohesive grains (sand, gravel) or cohesive material (silt, clay,
/// soil, weathered rock).
enum class SedimentClosure { non_cohesive, cohesive };
/// The non-cohesive equilibrium: Engelund-Hansen's total load or Garcia-Parker's pick-up.
enum class Pickup { engelund_hansen, garcia_parker };

/// One layer of the bed (erosion.soil, erosion.bedrock): its closure and parameters.
struct BedLayer {
  SedimentClosure closure = SedimentClosure::non_cohesive;
  double porosity = 0.4;                   ///< phi (1): pore fraction of the layer's bulk volume
  double erodibility = 1.0;                ///< non-cohesive: multiplier of the pick-up (1)
  double erosion_rate = 0.0;               ///< cohesive: Partheniades' M (kg m^-2 s^-1)
  double critical_shear = 1.0;             ///< cohesive: tau_c,e (Pa), the threshold of erosion
  std::optional<double> deposition_shear;  ///< cohesive: Krone's tau_c,d (Pa); none = w_s c
};
enum class NodataKind { wall, sea };
enum class Precision { float32, float64 };

/// A parameter given either as one number (SI units) or as a raster file path.
struct ScalarOrRaster {
  double value = 0.0;
  std::string path;  ///< non-empty: a raster on the DEM grid (same size after window)
  bool is_raster() const { return !path.empty(); }
};

/// One point of a piecewise-linear time series: time (s), value (SI).
struct SeriesPoint {
  double t = 0.0;
  double value = 0.0;
};
using Series = std::vector<SeriesPoint>;

/// A point (one vertex) or line (two or more vertices) inflow with a hydrograph.
struct InflowSpec {
  std::vector<std::array<double, 2>> vertices;  ///< x, y in the DEM's CRS
  Series hydrograph;                            ///< time (s), discharge (m^3/s)
  /// Volume concentration of solid sediment in the water it brings (1); 0 = clear water.
  double sediment_concentration = 0.0;
};

/// A cross-section ([[section]]): a polyline in the DEM's CRS across which the discharge and
/// the sediment flux are measured every step (sections.hpp).
struct SectionSpec {
  std::string name;                             ///< unique among sections and outlets
  std::vector<std::array<double, 2>> vertices;  ///< x, y in the DEM's CRS, two or more
};

/// An outlet ([[outlet]]): what leaves the grid through a whole boundary edge, or through
/// the faces one cell shares with the outside (the grid's edge or a nodata cell).
struct OutletSpec {
  std::string name;                   ///< unique among sections and outlets
  std::string edge;                   ///< "north", "south", "east", "west", or "" for a point
  std::array<double, 2> point{0, 0};  ///< x, y in the DEM's CRS (when edge is "")
};

struct Params {
  struct Dem {
    std::string path;       ///< DEM file (GDAL raster); empty when `synthetic` is set
    std::string synthetic;  ///< "", or a generator kind: fbm, ridged, diamond_square, hill, lake,
                            ///< valley, ridge
    int size = 256;         ///< synthetic: grid size (cells per side)
    int seed = 1;           ///< synthetic: random seed
    double relief = 100.0;  ///< synthetic: elevation range (m)
    std::optional<std::array<int, 4>> window;  ///< col, row, width, height (pixels)
    double resample = 0.0;                     ///< coarser cell size (m); 0 = none
    int resample_factor = 0;                   ///< integer averaging factor; 0 = none
    double z_scale = 1.0;                      ///< multiplier of stored values (1)
    double cell_size = 0.0;              ///< m; for files without georeferencing (and synthetic)
    std::string crs;                     ///< CRS for files without georeferencing
    std::optional<double> nodata_value;  ///< stored value to treat as nodata (before z_scale)
    /// every valid cell's elevation (after z_scale) must lie within +-this (m): a cell beyond
    /// it is a broken value (a float's -3.4e38 fill), not terrain
    double elevation_limit = 12000.0;
  } dem;

  struct Initial {
    std::optional<double> water_level;  ///< fill active cells up to this surface (m)
    ScalarOrRaster water_depth;         ///< uniform depth (m) or raster
  } initial;

  struct Time {
    long steps = 1000;      ///< number of steps (used when duration == 0)
    double duration = 0.0;  ///< simulated time (s); 0 = use steps
    double dt = 0.05;       ///< fixed step (s)
    bool adaptive = false;  ///< CFL-adaptive step
    double cfl = 0.7;       ///< Courant number alpha (1)
    double dt_max = 5.0;    ///< upper bound of the adaptive step (s)
  } time;

  struct Flow {
    FlowScheme scheme = FlowScheme::local_inertial;
    ScalarOrRaster manning_n{0.03, {}};  ///< Manning n (s m^-1/3)
    double theta = 0.8;                  ///< de Almeida weighting (1)
    double pipe_area = 1.0;              ///< pipes: cross-section A (m^2)
    double pipe_length = 0.0;            ///< pipes: length l (m); 0 = the cell size
    double gravity = 9.81;               ///< g (m/s^2)
    double water_density = 1000.0;       ///< rho (kg/m^3): the bed shear stress
    int order = 1;  ///< shallow_water: 1 (first-order Godunov) or 2 (MUSCL-minmod + Heun)
  } flow;

  struct Rain {
    double rate = 0.0;  ///< uniform rate (m/s), used when `series` is empty
    Series series;      ///< time (s), rate (m/s), linear in between, held at the end values outside
    std::string raster;  ///< optional spatial multiplier raster (1)
    /// Gridded rain that varies in time (radar, reanalysis): a multi-band raster on the DEM
    /// grid (or a netCDF variable, NETCDF:"file.nc":var), band k the rate at grid_times[k], or
    /// the netCDF time coordinate's grid_start + (time k - time 1), or grid_start + k
    /// grid_interval, linear in between, held at the ends; "" = none (rate or series instead).
    std::string grids;
    double grid_start = 0.0;              ///< time of band 1 (s)
    double grid_interval = 3600.0;        ///< time between bands (s)
    std::vector<double> grid_times;       ///< the bands' times (s), increasing; empty = above
    double grid_scale = 1.0e-3 / 3600.0;  ///< the rate one unit of the bands stands for (m/s)
  } rain;

  std::vector<InflowSpec> inflow;
  std::vector<SectionSpec> section;  ///< [[section]] tables
  std::vector<OutletSpec> outlet;    ///< [[outlet]] tables

  struct Erosion {
    bool enabled = false;
    ErosionLaw law = ErosionLaw::physical;
    // the physical law (docs/model.md 3.5): one grain-size class over two bed layers
    double grain_size = 0.5e-3;               ///< D (m): sieve diameter of the grains
    double sediment_density = 2650.0;         ///< rho_s (kg/m^3)
    double kinematic_viscosity = 1.0e-6;      ///< nu (m^2/s): water at 20 degrees C
    std::optional<double> settling_velocity;  ///< w_s (m/s); none = Ferguson & Church (2004)
    double settling_shape = 1.0;             ///< Ferguson & Church's C2 (1): 1 natural, 0.4 spheres
    std::optional<double> critical_shields;  ///< theta_c (1); none = Soulsby & Whitehouse (1997)
    bool slope_threshold = true;             ///< raise theta_c on slopes (Lamb et al. 2008)
    Pickup pickup = Pickup::engelund_hansen;
    double max_concentration = 0.1;  ///< c_max (1): cap of the equilibrium volume concentration
    ScalarOrRaster soil_thickness{1.0, {}};  ///< loose layer over the bedrock (m), or a raster
    double morfac = 1.0;  ///< morphological acceleration factor (1), Roelvink (2006)
    BedLayer soil{};      ///< the loose layer
    BedLayer bedrock{SedimentClosure::cohesive, 0.0, 1.0, 0.0, 1.0, {}};  ///< below it
    // Mei et al. (2007)'s law (erosion.law = "mei")
    double sediment_capacity = 1.0;    ///< K_c (s): capacity per unit speed and tilt
    double dissolving_rate = 0.5;      ///< K_s (1/s)
    double deposition_rate = 1.0;      ///< K_d (1/s)
    double min_tilt = 0.05;            ///< sin_min (1)
    ScalarOrRaster hardness{1.0, {}};  ///< R in [0, 1] (unused when hardness_noise)
    double min_depth = 0.0;            ///< d_erosion_min (m): capacity ramps to 0 below; 0 = off
    /// no erosion below this elevation (m); physical law: the soil is bed - bedrock_level thick
    std::optional<double> bedrock_level;
    bool hardness_noise = false;   ///< hardness = "noise": R from hardness_noise()
    double noise_amplitude = 0.5;  ///< a (1): the noise's R spans [1 - a, 1]
    double noise_scale = 500.0;    ///< wavelength of the noise's first octave (m)
    int noise_octaves = 5;         ///< octaves of the noise (lacunarity 2, gain 1/2)
    int noise_seed = 1;            ///< random seed of the noise
  } erosion;

  struct Transport {
    TransportScheme scheme = TransportScheme::conservative;
  } transport;

  struct Thermal {
    bool enabled = false;
    double talus_angle = 35.0;  ///< degrees
    double rate = 0.15;         ///< K_t (1/s)
    /// talus angle of wet ground (degrees): cells whose wetness is above wet_threshold;
    /// none = talus_angle everywhere
    std::optional<double> wet_talus_angle;
    double wet_threshold = 0.01;  ///< wetness (m, the running mean of the depth) of wet ground
  } thermal;

  struct Evaporation {
    double rate = 0.0;  ///< K_e (1/s)
  } evaporation;

  struct Snow {
    bool enabled = false;
    ScalarOrRaster initial{0.0, {}};        ///< initial snow water equivalent S_0 (m)
    std::optional<double> snow_line;        ///< the initial pack lies where bed >= this (m)
    double melt_factor = 4.0e-3 / 86400.0;  ///< degree-day factor DDF (m/s per K): 4 mm/d/K
    double melt_temperature = 0.0;          ///< T_melt (degrees C)
    double air_temperature = 0.0;           ///< T_ref, the air temperature at z_ref (degrees C)
    /// T_ref(t): time (s), degrees C, linear in between, held at the end values outside;
    /// when not empty it replaces air_temperature (the same key, snow.air_temperature)
    Series air_temperature_series;
    double reference_elevation = 0.0;  ///< z_ref (m)
    double lapse_rate = -0.0065;       ///< dT/dz (K/m)
    /// precipitation falls as snow where T < this (degrees C): Jennings et al. (2018)'s mean
    /// rain-snow threshold over the Northern Hemisphere, 1.0 degrees C
    double snowfall_temperature = 1.0;
    /// liquid water the pack holds per unit of snow water equivalent (1): HBV's CWH, 0.1
    double retention = 0.1;
    /// width of the band over which the initial pack ramps from 0 to snow.initial, centred on
    /// snow_line (m); 0 = a sharp line
    double transition = 0.0;
    /// the initial pack lies only where the slope is below this (degrees); none = anywhere
    std::optional<double> max_slope;
    /// the pack slides towards neighbours lower than this angle below it (degrees); none = no
    /// sliding
    std::optional<double> slide_angle;
    /// the fraction of a sliding cell's pack that moves per second (1/s): 1/h
    double slide_rate = 1.0 / 3600.0;
    /// The air temperature at each cell in time (degrees C, no lapse correction): a multi-band
    /// raster on the DEM grid or a netCDF variable, its band times as rain.grids'; "" = none
    /// (air_temperature and the lapse rate instead).
    std::string temperature_grids;
    double temperature_grid_start = 0.0;         ///< time of band 1 (s)
    double temperature_grid_interval = 3600.0;   ///< time between bands (s)
    std::vector<double> temperature_grid_times;  ///< the bands' times (s); empty = above
  } snow;

  /// Green-Ampt infiltration (infiltration.h, docs/model.md section 3.11). The soil's K_sat,
  /// suction head and moisture deficit: uniform or rasters (Rawls et al. 1983's loam).
  struct Infiltration {
    bool enabled = false;
    ScalarOrRaster ksat{0.34e-2 / 3600.0, {}};  ///< saturated conductivity K_sat (m/s)
    ScalarOrRaster suction{0.0889, {}};         ///< wetting-front suction head psi (m)
    ScalarOrRaster moisture_deficit{0.3, {}};   ///< delta theta = theta_s - theta_i (1)
    /// depth L of the soil (m): the store holds at most L delta theta; none = unlimited
    std::optional<ScalarOrRaster> soil_depth;
    /// recovery constant k_r (1/s); none = SWMM's sqrt(K_sat in in/h) / 75 per hour
    std::optional<double> recovery_rate;
  } infiltration;

  /// The parameters one terrain class gives its cells (terrain_classes.<class>.*): each one
  /// set replaces the uniform value on the class's cells; a raster of the parameter overrides
  /// both (docs/model.md section 3.12).
  struct ClassValues {
    std::optional<double> manning_n;         ///< Manning n (s m^-1/3)
    std::optional<double> talus_angle;       ///< talus angle (degrees)
    std::optional<double> ksat;              ///< Green-Ampt K_sat (m/s)
    std::optional<double> suction;           ///< Green-Ampt suction head psi (m)
    std::optional<double> moisture_deficit;  ///< Green-Ampt moisture deficit delta theta (1)
    std::optional<double> soil_depth;        ///< depth L of the soil store (m)
    std::optional<double> erodibility;       ///< erodibility R (the hardness field, 1)
    bool any() const {
      return manning_n || talus_angle || ksat || suction || moisture_deficit || soil_depth ||
             erodibility;
    }
  };

  /// Terrain classes (terrain_class.h, docs/model.md section 3.12): every active cell is snow,
  /// water, rock, mud or grass by a rule on its bed, slope, wetness and snow pack, recomputed
  /// every `interval` steps, and each class may give its cells its own parameters.
  struct TerrainClasses {
    bool enabled = false;
    int interval = 10;                ///< steps between classifications (the first step classifies)
    double snow_depth = 0.01;         ///< a pack (snow water equivalent, m) above this makes snow
    std::optional<double> snow_line;  ///< a bed above this (m) is snow; none = by the pack only
    double water_wetness = 0.3;       ///< wetness (m) above which a cell is water
    double rock_slope = 0.7;          ///< slope (m/m; 0.7 is 35 degrees) above which ... rock
    std::optional<double> rock_elevation;  ///< ... where the bed is above this (m); none = any
    double mud_wetness = 0.01;             ///< wetness (m) above which a cell is mud
    ClassValues grass, mud, rock, snow, water;
  } terrain_classes;

  struct Boundary {
    BoundaryKind north = BoundaryKind::closed;
    BoundaryKind south = BoundaryKind::closed;
    BoundaryKind east = BoundaryKind::closed;
    BoundaryKind west = BoundaryKind::closed;
    double sea_level = 0.0;  ///< level of fixed_level edges and sea nodata cells (m)
    /// A stage hydrograph: the level (m) of every fixed-level cell over time, in place of
    /// sea_level; empty: sea_level, constant.
    Series stage;
    /// Raster of boundary codes on the DEM grid (0 none, 1 closed, 2 open, 3 fixed_level):
    /// on an edge cell the condition of the edge there, inside the grid a wall (1) or a cell
    /// held at the level (3); "" = none.
    std::string raster;
    /// Volume concentration of solid sediment in the water that fixed_level edges and sea
    /// nodata cells give (1); 0 = clear water.
    double sediment_concentration = 0.0;
    NodataKind nodata = NodataKind::wall;
    /// The east and west edges joined (water leaving east enters west): true, false, or
    /// none = on where the grid spans 360 degrees of longitude (or boundary.east and .west
    /// are both "periodic"), else off (boundary_codes.hpp periodic_x).
    std::optional<bool> periodic_x;
    /// Latitude (degrees, (0, 90]) poleward of which the rows of a lat/lon grid are walls:
    /// their tiny east-west cells would set the time step; none = no cap.
    std::optional<double> latitude_cap;
  } boundary;

  struct Output {
    std::string path = "run.h5";
    long every = 100;       ///< steps between snapshots
    double interval = 0.0;  ///< simulated seconds between snapshots; 0 = use `every`
    std::vector<std::string> fields{"bed",        "water_depth", "sediment",
                                    "velocity_x", "velocity_y",  "erosion"};
    std::vector<std::array<double, 2>> gauges;  ///< x, y in the DEM's CRS
    bool restart_state = true;  ///< store the full state at the snapshots (restartable)
    long restart_every = 1;     ///< the state at every N-th snapshot (and the last)
  } output;

  struct Numerics {
    Precision precision = Precision::float32;
    double dry_depth = 1e-6;  ///< m: faces shallower than this carry no flow (local_inertial)
    double velocity_min_depth = 1e-3;  ///< d_min (m): velocity is 0 below this mean depth
    double wetness_time = 3600.0;      ///< s: time constant of the wetness running mean
    int threads = 0;                   ///< CPU threads; 0 = all cores
    /// Run the passes process.hpp step_passes() fuses as one pass where the backend can (the
    /// same bits); false: every process its own sweep, the reference the bench compares.
    bool fused_sweeps = true;
  } numerics;
};

}  // namespace erodem
