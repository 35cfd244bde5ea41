// erodem — the table of the parameter schema: every key of Params with its kind, dimension,
// range and doc line, grouped by section. The only place where keys, ranges, units and docs
// are written; parsing, `--set`, validation, dumping and --help follow from it (schema.cpp).
#include "erodem/fields.hpp"
#include "schema_kinds.hpp"

namespace erodem::schema_detail {

// ---- the table --------------------------------------------------------------------------

/// The dotted key and an accessor for a Params member, e.g. FIELD(time.dt).
#define ERODEM_FIELD(member)      \
#member, [](auto& p) -> auto& { \
    return p.member;              \
  }

/// The keys of one bed layer, erosion.<layer>.* (Params::Erosion::soil, ::bedrock).
#define ERODEM_BED_LAYER(layer, what)                                                           \
  choice(ERODEM_FIELD(erosion.layer.closure), closures,                                         \
         "physical: closure of " what                                                           \
         ": non_cohesive (sand, gravel) or cohesive (silt, clay, "                              \
         "soil, rock)"),                                                                        \
      number(ERODEM_FIELD(erosion.layer.porosity), D::dimensionless, right_open(0, 1),          \
             "physical: porosity phi of " what " (1)"),                                         \
      number(ERODEM_FIELD(erosion.layer.erodibility), D::dimensionless, at_least(0),            \
             "physical, non_cohesive: multiplier of the pick-up of " what " (1)"),              \
      number(ERODEM_FIELD(erosion.layer.erosion_rate), D::mass_flux, at_least(0),               \
             "physical, cohesive: Partheniades' erosion rate M of " what " (kg/m^2/s)"),        \
      number(ERODEM_FIELD(erosion.layer.critical_shear), D::stress, above(0),                   \
             "physical, cohesive: critical shear stress for erosion tau_c,e of " what " (Pa)"), \
      optional_number(ERODEM_FIELD(erosion.layer.deposition_shear), D::stress, above(0),        \
                      "physical, cohesive: Krone's critical shear stress for deposition "       \
                      "tau_c,d over " what " (Pa); not set = deposition w_s c at any stress")

/// The keys of one terrain class's table, terrain_classes.<cls>.* (Params::ClassValues).
#define ERODEM_CLASS_TABLE(cls)                                                                  \
  optional_number(ERODEM_FIELD(terrain_classes.cls.manning_n), D::manning, closed(0, 1),         \
                  "Manning n of " #cls " cells (s m^-1/3); not set = flow.manning_n"),           \
      optional_number(ERODEM_FIELD(terrain_classes.cls.talus_angle), D::angle, open(0, 90),      \
                      "talus angle of " #cls " cells (degrees); not set = thermal.talus_angle"), \
      optional_number(ERODEM_FIELD(terrain_classes.cls.ksat), D::speed, at_least(0),             \
                      "K_sat of " #cls " cells (m/s); not set = infiltration.ksat"),             \
      optional_number(ERODEM_FIELD(terrain_classes.cls.suction), D::length, at_least(0),         \
                      "suction head psi of " #cls " cells (m); not set = infiltration.suction"), \
      optional_number(                                                                           \
          ERODEM_FIELD(terrain_classes.cls.moisture_deficit), D::dimensionless, closed(0, 1),    \
          "moisture deficit of " #cls " cells (1); not set = infiltration.moisture_deficit"),    \
      optional_number(ERODEM_FIELD(terrain_classes.cls.soil_depth), D::length, at_least(0),      \
                      "soil store depth L of " #cls                                              \
                      " cells (m); not set = infiltration.soil_depth"),                          \
      optional_number(ERODEM_FIELD(terrain_classes.cls.erodibility), D::dimensionless,           \
                      closed(0, 1),                                                              \
                      "erodibility R of " #cls                                                   \
                      " cells (1, the hardness field); not set = "                               \
                      "erosion.hardness")

const std::vector<Descriptor>& descriptor_table() {
  using D = Dimension;
  static const Choices<BoundaryKind> boundary{{"closed", BoundaryKind::closed},
                                              {"open", BoundaryKind::open},
                                              {"fixed_level", BoundaryKind::fixed_level},
                                              {"periodic", BoundaryKind::periodic}};
  static const Choices<SedimentClosure> closures{{"non_cohesive", SedimentClosure::non_cohesive},
                                                 {"cohesive", SedimentClosure::cohesive}};
  static const std::vector<Descriptor> table{
      text(ERODEM_FIELD(dem.path), "DEM file (GDAL raster); relative to the config file"),
      choice(ERODEM_FIELD(dem.synthetic),
             Choices<std::string>{{"", ""},
                                  {"fbm", "fbm"},
                                  {"ridged", "ridged"},
                                  {"diamond_square", "diamond_square"},
                                  {"hill", "hill"},
                                  {"lake", "lake"},
                                  {"valley", "valley"},
                                  {"ridge", "ridge"}},
             "synthetic terrain generator instead of a DEM file (\"\" = none)"),
      integer(ERODEM_FIELD(dem.size), closed(2, 32768),
              "synthetic terrain: grid size (cells per side)"),
      integer(ERODEM_FIELD(dem.seed), closed(-2147483648.0, 2147483647.0),
              "synthetic terrain: random seed"),
      number(ERODEM_FIELD(dem.relief), D::length, above(0),
             "synthetic terrain: elevation range (m)"),
      window(ERODEM_FIELD(dem.window), "pixel window [col, row, width, height] of the DEM"),
      resample_descriptor("dem.resample",
                          "coarser cell size by averaging (m), or an integer factor; 0 = none"),
      number(ERODEM_FIELD(dem.z_scale), D::dimensionless, above(0),
             "multiplier of the stored elevations (1)"),
      number(ERODEM_FIELD(dem.cell_size), D::length, at_least(0),
             "cell size (m) for files without georeferencing and synthetic terrain; 0 = from "
             "the file"),
      text(ERODEM_FIELD(dem.crs), "CRS (e.g. \"EPSG:32610\") for files without georeferencing"),
      number(ERODEM_FIELD(dem.elevation_limit), D::length, above(0),
             "every valid cell's elevation must lie within +- this (m; 12 km holds every summit "
             "and sea floor on Earth): beyond it a value is broken (exit 65), not terrain"),
      optional_number(ERODEM_FIELD(dem.nodata_value), D::dimensionless, any_finite(),
                      "stored value to treat as nodata, in the file's units before z_scale "
                      "(e.g. 0 for a heightmap whose sea is 0; with boundary.nodata = \"sea\" "
                      "such cells hold the sea level)"),

      optional_number(ERODEM_FIELD(initial.water_level), D::length, any_finite(),
                      "fill every active cell up to this water surface elevation (m)"),
      scalar_or_raster(ERODEM_FIELD(initial.water_depth), D::length, at_least(0),
                       "initial water depth (m), uniform or a raster path"),

      integer(ERODEM_FIELD(time.steps), at_least(1),
              "number of steps (used when time.duration is 0)"),
      number(ERODEM_FIELD(time.duration), D::time, at_least(0),
             "simulated time (s); 0 = use time.steps"),
      number(ERODEM_FIELD(time.dt), D::time, above(0), "fixed time step (s)"),
      boolean(ERODEM_FIELD(time.adaptive), "CFL-adaptive time step"),
      number(ERODEM_FIELD(time.cfl), D::dimensionless, left_open(0, 1),
             "Courant number alpha of the adaptive step (1)"),
      number(ERODEM_FIELD(time.dt_max), D::time, above(0), "upper bound of the adaptive step (s)"),

      choice(ERODEM_FIELD(flow.scheme),
             Choices<FlowScheme>{{"pipes", FlowScheme::pipes},
                                 {"local_inertial", FlowScheme::local_inertial},
                                 {"shallow_water", FlowScheme::shallow_water}},
             "flow scheme: pipes (Mei 2007), local_inertial (Bates 2010) or shallow_water "
             "(HLLC, Chen & Noelle 2017)"),
      scalar_or_raster(ERODEM_FIELD(flow.manning_n), D::manning, at_least(0),
                       "Manning roughness n (s m^-1/3), uniform or a raster path"),
      number(ERODEM_FIELD(flow.theta), D::dimensionless, closed(0, 1),
             "local_inertial: de Almeida weighting theta (1)"),
      number(ERODEM_FIELD(flow.pipe_area), D::area, above(0), "pipes: pipe cross-section A (m^2)"),
      pipe_length_descriptor("flow.pipe_length",
                             "pipes: pipe length l (m), or \"cell\" for the cell size"),
      number(ERODEM_FIELD(flow.gravity), D::acceleration, above(0),
             "gravitational acceleration g (m/s^2)"),
      number(ERODEM_FIELD(flow.water_density), D::density, above(0),
             "water density rho (kg/m^3), for the bed shear stress"),
      integer(
          ERODEM_FIELD(flow.order), closed(1, 2),
          "shallow_water: order of accuracy, 1 (first-order Godunov) or 2 (MUSCL reconstruction "
          "with the minmod limiter and Heun's method)"),

      number(ERODEM_FIELD(rain.rate), D::speed, closed(0, 1),
             "uniform rain rate (m/s, at most 1 m/s: 3.6e6 mm/h), used when rain.series is "
             "empty"),
      series(ERODEM_FIELD(rain.series), D::speed, closed(0, 1),
             "rain rate series [[time (s), rate (m/s)], ...], linear in between, held at the end "
             "values outside"),
      text(ERODEM_FIELD(rain.raster), "raster path of a spatial rain multiplier (1); \"\" = none"),
      text(ERODEM_FIELD(rain.grids),
           "multi-band raster path of gridded rain on the DEM grid (radar), or a netCDF "
           "variable NETCDF:\"file.nc\":var (a file.nc of one variable needs no name): band k "
           "is the rate at rain.grid_times[k], else at rain.grid_start + the netCDF time "
           "coordinate's time since band 1, else at rain.grid_start + k rain.grid_interval; "
           "linear in between, held at the ends; \"\" = none"),
      number(ERODEM_FIELD(rain.grid_start), D::time, any_finite(), "time of the first band (s)"),
      number(ERODEM_FIELD(rain.grid_interval), D::time, above(0),
             "time between bands (s), where neither rain.grid_times nor a netCDF time "
             "coordinate gives the bands' times"),
      times(ERODEM_FIELD(rain.grid_times),
            "the bands' times [t1, t2, ...] (s, increasing, one per band): irregular bands; "
            "replaces rain.grid_start, rain.grid_interval and a netCDF time coordinate"),
      number(ERODEM_FIELD(rain.grid_scale), D::speed, above(0),
             "the rain rate one unit of the bands' values stands for (m/s; default '1 mm/h')"),

      inflow_descriptor("inflow",
                        "point or line inflows with a hydrograph [[time (s), discharge (m^3/s)]]"),
      section_descriptor("section",
                         "cross-sections: the discharge (m^3/s) and sediment flux (m^3/s of "
                         "solid) through a polyline, every step (results.md, sections/)"),
      outlet_descriptor("outlet",
                        "outlets: the discharge (m^3/s) and sediment flux (m^3/s of solid) "
                        "out of the grid through an edge or a cell's outer faces, every step"),

      boolean(ERODEM_FIELD(erosion.enabled), "hydraulic erosion and deposition"),
      choice(ERODEM_FIELD(erosion.law),
             Choices<ErosionLaw>{{"physical", ErosionLaw::physical}, {"mei", ErosionLaw::mei}},
             "erosion law: physical (shear-stress closures in physical units, a layered bed) or "
             "mei (Mei et al. 2007's transport capacity, a comparison and terrain-generation "
             "law)"),
      number(ERODEM_FIELD(erosion.grain_size), D::length, above(0),
             "physical: grain (sieve) diameter D of the sediment (m)"),
      number(ERODEM_FIELD(erosion.sediment_density), D::density, above(0),
             "physical: grain density rho_s (kg/m^3)"),
      number(ERODEM_FIELD(erosion.kinematic_viscosity), D::viscosity, above(0),
             "physical: kinematic viscosity of the water nu (m^2/s)"),
      optional_number(ERODEM_FIELD(erosion.settling_velocity), D::speed, above(0),
                      "physical: settling velocity w_s (m/s); not set = Ferguson & Church "
                      "(2004) from the grain size"),
      number(ERODEM_FIELD(erosion.settling_shape), D::dimensionless, above(0),
             "physical: Ferguson & Church's C2 (1): 1 natural grains, 0.4 smooth spheres, 1.2 "
             "angular"),
      optional_number(ERODEM_FIELD(erosion.critical_shields), D::dimensionless, above(0),
                      "physical: critical Shields number theta_c on a flat bed (1); not set = "
                      "Soulsby & Whitehouse (1997)"),
      boolean(ERODEM_FIELD(erosion.slope_threshold),
              "physical: raise theta_c on steep beds to 0.15 S^0.25 (Lamb et al. 2008)"),
      choice(ERODEM_FIELD(erosion.pickup),
             Choices<Pickup>{{"engelund_hansen", Pickup::engelund_hansen},
                             {"garcia_parker", Pickup::garcia_parker}},
             "physical, non-cohesive: equilibrium concentration from Engelund & Hansen (1967) "
             "total load or Garcia & Parker (1991) pick-up"),
      number(ERODEM_FIELD(erosion.max_concentration), D::dimensionless, left_open(0, 1),
             "physical: cap of the equilibrium volume concentration c_max (1)"),
      scalar_or_raster(ERODEM_FIELD(erosion.soil_thickness), D::length, at_least(0),
                       "physical: thickness of the loose layer (soil) over the bedrock (m), "
                       "uniform or a raster path"),
      number(ERODEM_FIELD(erosion.morfac), D::dimensionless, at_least(1),
             "physical: morphological acceleration factor (1), Roelvink (2006): the bed "
             "changes morfac times what the suspension exchanges"),
      number(ERODEM_FIELD(erosion.sediment_capacity), D::time, at_least(0),
             "mei: sediment capacity K_c (s): capacity per unit speed and tilt"),
      number(ERODEM_FIELD(erosion.dissolving_rate), D::inverse_time, at_least(0),
             "mei: dissolving (erosion) rate K_s (1/s)"),
      number(ERODEM_FIELD(erosion.deposition_rate), D::inverse_time, at_least(0),
             "mei: deposition rate K_d (1/s)"),
      number(ERODEM_FIELD(erosion.min_tilt), D::dimensionless, closed(0, 1),
             "mei: minimum tilt sin_min in the capacity (1)"),
      hardness_descriptor("erosion.hardness",
                          "hardness R in [0, 1] (1): uniform, a raster path, or \"noise\" (fBm "
                          "in [1 - erosion.noise_amplitude, 1])"),
      number(ERODEM_FIELD(erosion.noise_amplitude), D::dimensionless, closed(0, 1),
             "hardness \"noise\": amplitude a (1), R = 1 - a (1 - n) with n in [0, 1]"),
      number(ERODEM_FIELD(erosion.noise_scale), D::length, above(0),
             "hardness \"noise\": wavelength of the first octave (m)"),
      integer(ERODEM_FIELD(erosion.noise_octaves), closed(1, 16),
              "hardness \"noise\": number of octaves (wavelengths halve from octave to octave)"),
      integer(ERODEM_FIELD(erosion.noise_seed), closed(-2147483648.0, 2147483647.0),
              "hardness \"noise\": random seed"),
      number(ERODEM_FIELD(erosion.min_depth), D::length, at_least(0),
             "mei: depth below which the capacity ramps to 0 (m); 0 = off"),
      optional_number(ERODEM_FIELD(erosion.bedrock_level), D::length, any_finite(),
                      "no erosion below this bed elevation (m); physical: the soil is bed - "
                      "bedrock_level thick (an alias of soil_thickness)"),
      ERODEM_BED_LAYER(soil, "the loose layer"),
      ERODEM_BED_LAYER(bedrock, "the bedrock"),

      choice(ERODEM_FIELD(transport.scheme),
             Choices<TransportScheme>{{"conservative", TransportScheme::conservative},
                                      {"semi_lagrangian", TransportScheme::semi_lagrangian}},
             "sediment transport: conservative (flux form) or semi_lagrangian (Mei 2007)"),

      boolean(ERODEM_FIELD(thermal.enabled), "thermal erosion (slope collapse)"),
      number(ERODEM_FIELD(thermal.talus_angle), D::angle, open(0, 90), "talus angle (degrees)"),
      number(ERODEM_FIELD(thermal.rate), D::inverse_time, at_least(0), "thermal rate K_t (1/s)"),
      optional_number(ERODEM_FIELD(thermal.wet_talus_angle), D::angle, open(0, 90),
                      "talus angle of wet ground (degrees): cells whose wetness exceeds "
                      "thermal.wet_threshold collapse to it (MODEL.md step 6); not set = "
                      "thermal.talus_angle everywhere"),
      number(ERODEM_FIELD(thermal.wet_threshold), D::length, at_least(0),
             "wetness (m, the running mean of the depth, numerics.wetness_time) above which "
             "ground is wet"),

      number(ERODEM_FIELD(evaporation.rate), D::inverse_time, at_least(0),
             "evaporation rate K_e (1/s)"),

      boolean(ERODEM_FIELD(snow.enabled),
              "a snow pack: snowfall, degree-day melt, rain on snow, liquid water"),
      scalar_or_raster(ERODEM_FIELD(snow.initial), D::length, at_least(0),
                       "initial snow water equivalent S_0 (m), uniform or a raster path; times "
                       "the snow line's share where snow.snow_line is given"),
      optional_number(ERODEM_FIELD(snow.snow_line), D::length, any_finite(),
                      "the initial pack lies only where the bed is at or above this (m)"),
      number(ERODEM_FIELD(snow.melt_factor), D::speed, at_least(0),
             "degree-day factor DDF: melt per kelvin above snow.melt_temperature (m/s per K; "
             "e.g. '4 mm/d')"),
      number(ERODEM_FIELD(snow.melt_temperature), D::dimensionless, any_finite(),
             "air temperature above which snow melts, T_melt (degrees C)"),
      number_or_series(
          ERODEM_FIELD(snow.air_temperature),
          [](auto& p) -> auto& { return p.snow.air_temperature_series; }, D::dimensionless,
          any_finite(),
          "air temperature T_ref at snow.reference_elevation (degrees C), constant or a series "
          "[[time (s), T_ref (degrees C)], ...], linear in between, held at the end values "
          "outside, taken at each step's midpoint"),
      number(ERODEM_FIELD(snow.reference_elevation), D::length, any_finite(),
             "elevation z_ref of snow.air_temperature (m)"),
      number(ERODEM_FIELD(snow.lapse_rate), D::dimensionless, any_finite(),
             "air temperature lapse rate dT/dz (K/m; -0.0065 is -6.5 K/km)"),
      number(ERODEM_FIELD(snow.snowfall_temperature), D::dimensionless, any_finite(),
             "the step's rain falls on the pack as snow where the air temperature is below this "
             "(degrees C; 1.0: Jennings et al. 2018)"),
      number(ERODEM_FIELD(snow.retention), D::dimensionless, at_least(0),
             "liquid water the pack holds per unit of its snow water equivalent (1; 0.1: HBV's "
             "CWH); melt and rain on the pack beyond it reach the depth"),
      number(ERODEM_FIELD(snow.transition), D::length, at_least(0),
             "width of the band centred on snow.snow_line over which the initial pack ramps "
             "linearly from 0 to snow.initial (m); 0 = a sharp line"),
      optional_number(ERODEM_FIELD(snow.slide_angle), D::angle, open(0, 90),
                      "the pack slides towards the active neighbours whose bed lies lower than "
                      "this angle below it (degrees; Bernhardt & Schulz 2010 use 25 - 60); not "
                      "set = the pack does not move"),
      number(ERODEM_FIELD(snow.slide_rate), D::inverse_time, at_least(0),
             "fraction of a sliding cell's pack that moves per second (1/s; min(1, rate dt) "
             "per step)"),
      optional_number(ERODEM_FIELD(snow.max_slope), D::angle, closed(0, 90),
                      "the initial pack lies only where the bed's slope (central differences) "
                      "is below this (degrees); not set = on any slope"),
      text(ERODEM_FIELD(snow.temperature_grids),
           "multi-band raster path or netCDF variable (as rain.grids) of the air temperature "
           "at each cell (degrees C, in [-100, 100]; no lapse correction), replacing "
           "snow.air_temperature, snow.lapse_rate and snow.reference_elevation; its band times "
           "as rain.grids' (snow.temperature_grid_*); \"\" = none"),
      number(ERODEM_FIELD(snow.temperature_grid_start), D::time, any_finite(),
             "time of the first band of snow.temperature_grids (s)"),
      number(ERODEM_FIELD(snow.temperature_grid_interval), D::time, above(0),
             "time between bands of snow.temperature_grids (s), where neither "
             "snow.temperature_grid_times nor a netCDF time coordinate gives them"),
      times(ERODEM_FIELD(snow.temperature_grid_times),
            "the times [t1, t2, ...] of snow.temperature_grids' bands (s, increasing, one per "
            "band); replaces the start, interval and a netCDF time coordinate"),

      boolean(ERODEM_FIELD(infiltration.enabled),
              "Green-Ampt infiltration of the water depth into the soil"),
      scalar_or_raster(ERODEM_FIELD(infiltration.ksat), D::speed, at_least(0),
                       "saturated hydraulic conductivity K_sat (m/s; e.g. '0.34 cm/h'), uniform "
                       "or a raster path"),
      scalar_or_raster(ERODEM_FIELD(infiltration.suction), D::length, at_least(0),
                       "wetting-front suction head psi (m), uniform or a raster path"),
      scalar_or_raster(ERODEM_FIELD(infiltration.moisture_deficit), D::dimensionless, closed(0, 1),
                       "moisture deficit delta theta = theta_s - theta_i (1), uniform or a raster "
                       "path"),
      optional_scalar_or_raster(ERODEM_FIELD(infiltration.soil_depth), D::length, at_least(0),
                                "depth L of the soil store (m), uniform or a raster path: it "
                                "holds at most L delta theta of water; not set = unlimited"),
      optional_number(ERODEM_FIELD(infiltration.recovery_rate), D::inverse_time, at_least(0),
                      "recovery constant k_r (1/s): a dry cell's infiltrated depth decays as "
                      "e^(-k_r t); not set = SWMM's sqrt(K_sat in in/h) / 75 per hour"),

      boolean(ERODEM_FIELD(terrain_classes.enabled),
              "terrain classes: every active cell is snow, water, rock, mud or grass, and each "
              "class may give its cells their own parameters (terrain_classes.<class>.*)"),
      integer(ERODEM_FIELD(terrain_classes.interval), closed(1, 1e9),
              "steps between two classifications (the first step classifies)"),
      number(ERODEM_FIELD(terrain_classes.snow_depth), D::length, at_least(0),
             "a cell whose snow pack (snow water equivalent) exceeds this is snow (m)"),
      optional_number(ERODEM_FIELD(terrain_classes.snow_line), D::length, any_finite(),
                      "a cell whose bed lies above this is snow (m); not set = by its pack only"),
      number(ERODEM_FIELD(terrain_classes.water_wetness), D::length, at_least(0),
             "a cell whose wetness (the running mean of its depth) exceeds this is water (m)"),
      number(ERODEM_FIELD(terrain_classes.rock_slope), D::dimensionless, at_least(0),
             "a cell whose bed slope exceeds this is rock (m/m; 0.7 is 35 degrees)"),
      optional_number(ERODEM_FIELD(terrain_classes.rock_elevation), D::length, any_finite(),
                      "rock only where the bed lies above this (m); not set = at any elevation"),
      number(ERODEM_FIELD(terrain_classes.mud_wetness), D::length, at_least(0),
             "a cell whose wetness exceeds this is mud (m)"),
      ERODEM_CLASS_TABLE(grass),
      ERODEM_CLASS_TABLE(mud),
      ERODEM_CLASS_TABLE(rock),
      ERODEM_CLASS_TABLE(snow),
      ERODEM_CLASS_TABLE(water),

      choice(ERODEM_FIELD(boundary.north), boundary,
             "north edge: closed, open or fixed_level (periodic is for east and west only)"),
      choice(ERODEM_FIELD(boundary.south), boundary,
             "south edge: closed, open or fixed_level (periodic is for east and west only)"),
      choice(ERODEM_FIELD(boundary.east), boundary,
             "east edge: closed, open, fixed_level, or periodic (with the other of east and west; "
             "boundary.periodic_x)"),
      choice(ERODEM_FIELD(boundary.west), boundary,
             "west edge: closed, open, fixed_level, or periodic (with the other of east and west; "
             "boundary.periodic_x)"),
      number(ERODEM_FIELD(boundary.sediment_concentration), D::dimensionless, right_open(0, 1),
             "volume concentration of solid sediment in the water fixed_level edges and sea "
             "nodata cells give (1); 0 = clear water"),
      number(ERODEM_FIELD(boundary.sea_level), D::length, any_finite(),
             "water level of fixed_level edges and sea nodata cells (m)"),
      series(ERODEM_FIELD(boundary.stage), D::length, any_finite(),
             "stage hydrograph [[time (s), level (m)], ...] of every fixed-level cell (edges, "
             "sea nodata cells, boundary.raster's held cells), linear in between, held at the end "
             "values outside; not set = boundary.sea_level"),
      text(ERODEM_FIELD(boundary.raster),
           "raster path of boundary codes on the DEM grid: 0 as the edges say, 1 closed, 2 "
           "open, 3 fixed_level; on an edge cell the edge's condition there, inside the grid "
           "a wall (1) or a cell held at the level (3); \"\" = none"),
      choice(ERODEM_FIELD(boundary.nodata),
             Choices<NodataKind>{{"wall", NodataKind::wall}, {"sea", NodataKind::sea}},
             "nodata cells: wall, or sea at boundary.sea_level"),
      optional_boolean(ERODEM_FIELD(boundary.periodic_x),
                       "join the east and west edges (water leaving east enters west): true, "
                       "false, or not set = on where the grid spans 360 degrees of longitude"),
      optional_number(ERODEM_FIELD(boundary.latitude_cap), D::angle, left_open(0, 90),
                      "lat/lon grids: the rows poleward of +-cap (degrees) are walls, so their "
                      "narrow cells do not set the time step; not set = none"),

      text(ERODEM_FIELD(output.path), "result file (.h5)"),
      integer(ERODEM_FIELD(output.every), at_least(1),
              "steps between snapshots (used when output.interval is 0)"),
      number(ERODEM_FIELD(output.interval), D::time, at_least(0),
             "simulated time between snapshots (s); 0 = use output.every"),
      name_list(ERODEM_FIELD(output.fields), output_field_names(),  // fields.cpp's table
                "fields written in each snapshot"),
      points(ERODEM_FIELD(output.gauges),
             "gauge points [[x, y], ...] in the DEM's CRS: depth, level and speed every step"),
      boolean(ERODEM_FIELD(output.restart_state),
              "store the full state at the snapshots, so a run can restart from them"),
      integer(ERODEM_FIELD(output.restart_every), at_least(1),
              "snapshots between stored states: the state at every N-th snapshot (the first "
              "included) and always at the last"),

      choice(ERODEM_FIELD(numerics.precision),
             Choices<Precision>{{"float32", Precision::float32}, {"float64", Precision::float64}},
             "floating-point precision of the CPU reference: float32 or float64"),
      number(
          ERODEM_FIELD(numerics.dry_depth), D::length, at_least(0),
          "local_inertial: faces shallower than this carry no flow (m); below 1e-16 m none does"),
      number(ERODEM_FIELD(numerics.velocity_min_depth), D::length, at_least(0),
             "velocity is 0 below this mean depth d_min (m)"),
      number(ERODEM_FIELD(numerics.wetness_time), D::time, above(0),
             "time constant of the wetness running mean (s)"),
      integer(ERODEM_FIELD(numerics.threads), closed(0, 65536), "CPU threads (0 = all cores)"),
      boolean(ERODEM_FIELD(numerics.fused_sweeps),
              "run flow, sources and water as one pass over memory where the backend can (the "
              "same bits); false: each process its own sweep"),
  };
  return table;
}

#undef ERODEM_FIELD

}  // namespace erodem::schema_detail
