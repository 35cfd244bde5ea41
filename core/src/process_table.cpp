// erodem — the entries of the process table (process.hpp). Each entry says what its sweeps
// read and write as the cell functions of kernels/common/*.h and the loops of kernels/cpu/*.cpp
// and kernels/opencl/*.cl do; tests/test_process_table.cpp checks the derived sequence, byte
// model and bed-change set.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "common/terrain_class.h"
#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/process.hpp"

namespace erodem {
namespace {

constexpr Access R = Access::read, N = Access::read_neighbours, Wr = Access::write,
                 U = Access::update, UN = Access::update_neighbours;

bool always(const Params&) {
  return true;
}
bool erosion_on(const Params& p) {
  return p.erosion.enabled;
}
bool thermal_on(const Params& p) {
  return p.thermal.enabled;
}
bool snow_on(const Params& p) {
  return p.snow.enabled;
}
bool infiltration_on(const Params& p) {
  return p.infiltration.enabled;
}
bool classes_on(const Params& p) {
  return p.terrain_classes.enabled;
}
bool rains(const Params& p) {
  return p.rain.rate > 0 || !p.rain.series.empty() || !p.rain.grids.empty();
}

/// A sweep the backends run through their generic cell loop (SweepInfo::generic): its cell
/// function is `<name>_sweep_cell`, its kernel `<name>`.
SweepInfo generic_sweep(const char* name, std::vector<FieldUse> uses,
                        std::vector<const char*> tallies) {
  SweepInfo s{name, Domain::cells, std::move(uses), {name}};
  s.generic = true;
  s.tallies = std::move(tallies);
  return s;
}

// ---- the sweeps of each process --------------------------------------------------------

std::vector<SweepInfo> boundary_sweeps(const Params& p) {
  // boundary_fill_cell (boundary.h): the ghosts take the bed and depth their edge gives them
  // (the edge cell's and the one inside it: neighbours of the ghost). The ghost columns read
  // along their own row (a band fills them on its halo rows too, exact_in_band); a ghost row
  // of an open edge reads the bed two rows inside, beyond a band's own rows only where they
  // are fewer than 2, as the halo allows with pipes: then its first halo row (exact_in_band
  // takes the ghost columns' own row for what the sweep leaves on the halo rows).
  const int ghost_row_reach = std::max(0, 2 - band_halo_rows(p));
  std::vector<SweepInfo> s{
      {"boundary_fill",
       Domain::halo,
       {{"kind", N, 0}, {"bed", UN, ghost_row_reach}, {"water_depth", UN, 0}, {"sediment", U}},
       {"boundary_fill"}}};
  if (!p.boundary.stage.empty())
    // boundary_level_sweep_cell (boundary.h): the cells held at the level inside the grid
    // follow the stage hydrograph
    s.push_back(generic_sweep("boundary_level",
                              {{"kind", R}, {"bed", R}, {"water_depth", U}, {"sediment", U}}, {}));
  return s;
}

std::vector<SweepInfo> sources_sweeps(const Params& p) {
  // rain_cell (sources.h) over the cells where it rains; the inflows add at their cells
  std::vector<SweepInfo> s;
  if (rains(p))
    s.push_back({"sources_rain",
                 Domain::cells,
                 {{"kind", R}, {"rain_factor", R}, {"water_depth", U}},
                 {"sources_rain"}});
  if (!p.inflow.empty())
    s.push_back({"sources_points",
                 Domain::points,
                 {{"water_depth", U}, {"sediment", U}},  // the sediment it brings
                 {"sources_points"}});
  return s;
}

std::vector<SweepInfo> flow_sweeps(const Params& p) {
  // the outflows: the pipes update each cell's own; a local-inertial face reads the discharges
  // of the faces beside it (two cells along its axis)
  const Access fa = p.flow.scheme == FlowScheme::local_inertial ? UN : U;
  const std::vector<FieldUse> fluxes{
      {"flux_left", fa}, {"flux_right", fa}, {"flux_top", fa}, {"flux_bottom", fa}};
  if (p.flow.scheme == FlowScheme::shallow_water) {
    // shallow_water_cell (shallow_water.h): the four faces of each cell (Chen & Noelle
    // reconstruction, HLLC) give its outflows and its new unit discharges
    return {{"flow_shallow_water",
             Domain::cells,
             {{"kind", N},
              {"bed", N},
              {"water_depth", N},
              {"momentum_x", UN},  // the faces' states from the neighbours' unit discharges
              {"momentum_y", UN},
              {"manning_n", R},
              {"flux_left", Wr},
              {"flux_right", Wr},
              {"flux_top", Wr},
              {"flux_bottom", Wr}},
             {"flow_shallow_water", "flow_shallow_water_velocities", "flow_shallow_water_interior",
              "flow_shallow_water_muscl", "flow_shallow_water_muscl_interior",
              "flow_shallow_water_stage_depth"}}};
  }
  if (p.flow.scheme == FlowScheme::local_inertial) {
    // local_inertial_face + local_inertial_split (flow.h): the face discharges from the old
    // outflows, the levels and the face's Manning n; then the outflows of each cell
    std::vector<FieldUse> uses{{"kind", N}, {"bed", N}, {"water_depth", N}, {"manning_n", N}};
    uses.insert(uses.end(), fluxes.begin(), fluxes.end());
    return {{"flow_local_inertial",
             Domain::cells,
             uses,
             {"flow_local_inertial_faces", "flow_local_inertial_faces_x_interior",
              "flow_local_inertial_faces_y_interior", "flow_local_inertial_split",
              "flow_local_inertial_split_interior"}}};
  }
  // flow_pipes_outflows (flow.h): each pipe from the surface drop to its neighbour
  std::vector<FieldUse> uses{{"kind", N}, {"bed", N}, {"water_depth", N}};
  uses.insert(uses.end(), fluxes.begin(), fluxes.end());
  return {{"flow_pipes", Domain::cells, uses, {"flow_pipes", "flow_pipes_interior"}}};
}

std::vector<SweepInfo> water_sweeps(const Params& p) {
  // water_update_cell (water.h): the depth from the outflows in and out, the velocity from the
  // faces' discharges over their flow depths (bed and depth of the neighbours); the depth it
  // started from stays in the second buffer for conservative transport ("depth_flow"). It
  // reads the four neighbours: one row away.
  std::vector<SweepInfo> s{{"water_update",
                            Domain::cells,
                            {{"kind", N, 1},
                             {"bed", N, 1},
                             {"water_depth", UN, 1},  // the faces' flow depths
                             {"flux_left", N, 1},
                             {"flux_right", N, 1},
                             {"flux_top", N, 1},
                             {"flux_bottom", N, 1},
                             {"velocity_x", Wr},
                             {"velocity_y", Wr}},
                            {"water_update", "edge_tallies"},
                            {"depth_flow"}}};
  if (p.flow.scheme == FlowScheme::shallow_water)
    // shallow_water_velocity_sweep_cell (shallow_water.h): the velocity from the unit
    // discharges over the new depth, in place of the faces'
    s.push_back(generic_sweep("shallow_water_velocity",
                              {{"kind", R},
                               {"water_depth", R},
                               {"momentum_x", R},
                               {"momentum_y", R},
                               {"velocity_x", Wr},
                               {"velocity_y", Wr}},
                              {}));
  return s;
}

std::vector<SweepInfo> erosion_sweeps(const Params& p) {
  // both read the bed (and the kinds) of the four neighbours for the bed's slope: one row away
  if (p.erosion.law == ErosionLaw::physical)
    // sediment_cell (erosion.h): the bed shear stress and the bed's slope, the surface layer's
    // closure, the exact exchange over the step, Exner with the layer's porosity
    return {{"erosion_physical",
             Domain::cells,
             {{"kind", N, 1},
              {"bed", UN, 1},  // the bed's slope
              {"bed_residual", U},
              {"sediment", U},
              {"soil_thickness", U},
              {"water_depth", R},
              {"velocity_x", R},
              {"velocity_y", R},
              {"manning_n", R},
              {"hardness", R}},
             {"erosion_physical"}}};
  // erosion_cell (erosion.h): capacity from the speed and the bed's tilt, the exact transfer
  // between the bed pair and the sediment
  return {{"erosion",
           Domain::cells,
           {{"kind", N, 1},
            {"bed", UN, 1},  // the bed's slope
            {"bed_residual", U},
            {"sediment", U},
            {"water_depth", R},
            {"velocity_x", R},
            {"velocity_y", R},
            {"hardness", R}},
           {"erosion"}}};
}

std::vector<SweepInfo> transport_sweeps(const Params& p) {
  if (p.transport.scheme == TransportScheme::conservative)
    // transport_conservative_cell (transport.h): sediment moves with the outflows at the
    // concentration of the depth the flow saw, from the four neighbours (one row away)
    return {{"transport_conservative",
             Domain::cells,
             {{"kind", N, 1},
              {"sediment", UN, 1},
              {"depth_flow", N, 1},
              {"flux_left", N, 1},
              {"flux_right", N, 1},
              {"flux_top", N, 1},
              {"flux_bottom", N, 1}},
             {"transport_conservative", "edge_tallies"}}};
  // transport_semi_lagrangian_cell (transport.h): back-traced along the velocity
  return {{"transport_semi_lagrangian",
           Domain::cells,
           {{"kind", N}, {"sediment", UN}, {"velocity_x", R}, {"velocity_y", R}},
           {"transport_semi_lagrangian"}}};
}

std::vector<SweepInfo> thermal_sweeps(const Params& p) {
  // thermal_share_cell then thermal_apply_cell (thermal.h): what each cell gives, then what
  // it keeps and takes from its neighbours; each cell's dry talus slope from its class's table
  // where the terrain classes give talus angles; both read the four neighbours (one row away)
  std::vector<SweepInfo> s{{"thermal_share",
                            Domain::cells,
                            {{"kind", N, 1}, {"bed", N, 1}, {"wetness", R}, {"thermal_share", Wr}},
                            {"thermal_share"}},
                           {"thermal_apply",
                            Domain::cells,
                            {{"kind", N, 1},
                             {"bed", UN, 1},
                             {"bed_residual", U},
                             {"wetness", N, 1},
                             {"thermal_share", N, 1}},
                            {"thermal_apply"}}};
  if (class_tables(p).talus) {
    s[0].uses.push_back({"talus_slope", R});
    s[1].uses.push_back({"talus_slope", N, 1});
  }
  return s;
}

std::vector<SweepInfo> terrain_class_sweeps(const Params&) {
  // terrain_class_sweep_cell (terrain_class.h): each active cell's class from its bed, slope,
  // wetness and pack (on the steps of terrain_classes.interval), then its class's values into
  // the parameter fields the tables write (class_tables)
  return {generic_sweep("terrain_class",
                        {{"kind", N},
                         {"dx", R},
                         {"dy", R},
                         {"bed", N},
                         {"wetness", R},
                         {"snow", R},
                         {"terrain_class", U},
                         {"manning_n", Wr},
                         {"hardness", Wr},
                         {"infiltration_ksat", Wr},
                         {"infiltration_suction_deficit", Wr},
                         {"infiltration_store", Wr},
                         {"talus_slope", Wr}},
                        {})};
}

std::vector<SweepInfo> evaporation_sweeps(const Params& p) {
  // evaporation_sweep_cell (sources.h): the depth decays (when the rate > 0) and the wetness
  // follows it
  return {generic_sweep(
      "evaporation", {{"kind", R}, {"water_depth", p.evaporation.rate > 0 ? U : R}, {"wetness", U}},
      {"evaporated"})};
}

std::vector<SweepInfo> snow_sweeps(const Params& p) {
  std::vector<SweepInfo> s;
  if (p.snow.slide_angle) {
    // snow_slide_share_sweep_cell then snow_slide_sweep_cell (snow.h): what each pack gives
    // down slopes steeper than the slide angle, then what it keeps and takes (thermal's
    // pattern), before the melt
    s.push_back(generic_sweep(
        "snow_slide_share",
        {{"kind", N}, {"bed", N}, {"snow", R}, {"dx", R}, {"dy", R}, {"snow_slide_share", Wr}},
        {}));
    s.push_back(generic_sweep(
        "snow_slide",
        {{"kind", N}, {"bed", N}, {"snow", U}, {"dx", R}, {"dy", R}, {"snow_slide_share", N}}, {}));
  }
  // snow_sweep_cell (snow.h): snowfall and rain on snow from the step's rain on the depth,
  // the degree-day melt and the rain's heat, the liquid water beyond retention into the depth;
  // at T_ref + lapse (bed - z_ref), or with snow.temperature_grids (snow_gridded_sweep_cell)
  // at the air_temperature field the host interpolates from the bands
  const bool gridded = !p.snow.temperature_grids.empty();
  s.push_back(generic_sweep(gridded ? "snow_gridded" : "snow",
                            {{"kind", R},
                             {gridded ? "air_temperature" : "bed", R},
                             {"rain_factor", R},
                             {"snow", U},
                             {"snow_liquid", U},
                             {"water_depth", U}},
                            {"snowfall", "rain_on_snow", "snow_melted", "snow_runoff"}));
  return s;
}

/// The slope of the bed at DEM cell (col c, row r) in degrees: the angle of bed_slope_cell
/// (terrain_class.h, the terrain classes' slope), the gradient by central differences over
/// the active neighbours (one-sided where one of a pair is missing or not active; 0 along an
/// axis with neither).
double bed_slope_degrees(const Terrain& t, int c, int r) {
  const Grid& g = t.grid;
  const auto at = [&](int cc, int rr) { return static_cast<std::size_t>(rr) * g.nx + cc; };
  const auto usable = [&](int cc, int rr) {
    return cc >= 0 && cc < g.nx && rr >= 0 && rr < g.ny && t.active(at(cc, rr));
  };
  const auto bed = [&](int cc, int rr) { return usable(cc, rr) ? t.bed[t.held(at(cc, rr))] : 0.0; };
  const auto dy_between = [&](int r0, int r1) {
    return 0.5 * (g.dy[static_cast<std::size_t>(r0)] + g.dy[static_cast<std::size_t>(r1)]);
  };
  const int north = usable(c, r - 1), south = usable(c, r + 1);
  const double slope = cell::bed_slope_cell<double>(
      t.bed[t.held(at(c, r))], bed(c - 1, r), bed(c + 1, r), bed(c, r - 1), bed(c, r + 1),
      usable(c - 1, r), usable(c + 1, r), north, south, g.dx[static_cast<std::size_t>(r)],
      north ? dy_between(r - 1, r) : 0.0, south ? dy_between(r, r + 1) : 0.0);
  const double pi = 3.14159265358979323846;
  return std::atan(slope) * 180.0 / pi;
}

/// The share of snow.initial an initial pack at elevation z (m) gets: 1 where no snow line is
/// given; with one at z_s and a transition band w, 0 below z_s - w/2, 1 from z_s + w/2, linear
/// in between (w = 0: 1 at or above z_s, else 0).
double snow_line_share(double z, const Params::Snow& sn) {
  if (!sn.snow_line) return 1.0;
  const double line = *sn.snow_line, band = sn.transition;
  if (!(band > 0)) return z >= line ? 1.0 : 0.0;
  return std::clamp((z - (line - 0.5 * band)) / band, 0.0, 1.0);
}

/// The initial pack: snow.initial (uniform or its raster) on the active cells, times
/// snow_line_share of their bed, where the bed's slope is below snow.max_slope (when given).
std::vector<InitialField> snow_initial(const Terrain& t, const Params& p) {
  const auto& sn = p.snow;
  return {{FieldId::snow, [&t, &sn](std::size_t i) {
             if (!t.active(i)) return 0.0;
             const int c = static_cast<int>(i % static_cast<std::size_t>(t.grid.nx)),
                       r = static_cast<int>(i / static_cast<std::size_t>(t.grid.nx));
             if (sn.max_slope && !(bed_slope_degrees(t, c, r) < *sn.max_slope)) return 0.0;
             const double share = snow_line_share(t.bed[t.held(i)], sn);
             const double s0 =
                 t.snow_initial.empty() ? sn.initial.value : t.snow_initial[t.held(i)];
             return share > 0 ? (share == 1.0 ? s0 : s0 * share) : 0.0;
           }}};
}

std::vector<SweepInfo> infiltration_sweeps(const Params&) {
  // infiltration_sweep_cell (infiltration.h): Green-Ampt's implicit increment from the depth
  // into the store, or the store's recovery on a dry cell
  return {generic_sweep("infiltration",
                        {{"kind", R},
                         {"water_depth", U},
                         {"infiltrated", U},
                         {"infiltration_ksat", R},
                         {"infiltration_suction_deficit", R},
                         {"infiltration_store", R}},
                        {"infiltrated", "soil_drained"})};
}

/// The soil of infiltration on the DEM cells: K_sat, psi delta theta and the store
/// L delta theta (unlimited: the largest float), each from its uniform value or raster.
std::vector<InitialField> infiltration_initial(const Terrain& t, const Params& p) {
  const auto& in = p.infiltration;
  const auto value = [&t](const std::vector<double>& raster, const ScalarOrRaster& s,
                          std::size_t i) { return raster.empty() ? s.value : raster[t.held(i)]; };
  const auto deficit = [&t, &in, value](std::size_t i) {
    return value(t.moisture_deficit, in.moisture_deficit, i);
  };
  return {{FieldId::infiltration_ksat,
           [&t, &in, value](std::size_t i) { return value(t.ksat, in.ksat, i); }},
          {FieldId::infiltration_suction_deficit,
           [&t, &in, value, deficit](std::size_t i) {
             return value(t.suction, in.suction, i) * deficit(i);
           }},
          {FieldId::infiltration_store, [&t, &in, value, deficit](std::size_t i) {
             return in.soil_depth ? value(t.soil_depth, *in.soil_depth, i) * deficit(i)
                                  : static_cast<double>(std::numeric_limits<float>::max());
           }}};
}

/// The initial soil (physical law): erosion.soil_thickness (uniform or its raster), or bed -
/// bedrock_level (at least 0) where a bedrock level is given, on the active cells.
std::vector<InitialField> erosion_initial(const Terrain& t, const Params& p) {
  if (p.erosion.law != ErosionLaw::physical) return {};
  const auto& e = p.erosion;
  return {{FieldId::soil_thickness, [&t, &e](std::size_t i) {
             if (!t.active(i)) return 0.0;
             if (e.bedrock_level) return std::max(t.bed[t.held(i)] - *e.bedrock_level, 0.0);
             return t.soil_thickness.empty() ? e.soil_thickness.value : t.soil_thickness[t.held(i)];
           }}};
}

}  // namespace

ClassTables class_tables(const Params& p) {
  ClassTables t;
  const auto& tc = p.terrain_classes;
  if (!tc.enabled) return t;
  for (const Params::ClassValues* v : {&tc.grass, &tc.mud, &tc.rock, &tc.snow, &tc.water}) {
    t.manning = t.manning || v->manning_n;
    t.hardness = t.hardness || v->erodibility;
    t.ksat = t.ksat || v->ksat;
    t.soil = t.soil || v->suction || v->moisture_deficit || v->soil_depth;
    t.talus = t.talus || v->talus_angle;
  }
  const auto& in = p.infiltration;
  t.manning = t.manning && !p.flow.manning_n.is_raster();
  t.hardness = t.hardness && p.erosion.enabled && !p.erosion.hardness.is_raster() &&
               !p.erosion.hardness_noise;
  t.ksat = t.ksat && in.enabled && !in.ksat.is_raster();
  t.soil = t.soil && in.enabled;  // schema.cpp refuses class soils beside soil rasters
  t.talus = t.talus && p.thermal.enabled;
  return t;
}

const std::vector<ProcessInfo>& process_table() {
  static const std::vector<ProcessInfo> table{
      // first: the classes of the state the step starts from, and their parameters, before
      // any process reads them (Simulation::step runs it every terrain_classes.interval steps)
      {Process::terrain_class,
       "terrain_class",
       "terrain_classes",
       classes_on,
       terrain_class_sweeps,
       {},
       "terrain_class.cl"},
      {Process::boundary, "boundary", "boundary", always, boundary_sweeps, {}, "boundary.cl"},
      {Process::flow, "flow", "flow", always, flow_sweeps, {}, "flow.cl"},
      {Process::sources, "sources", "rain", always, sources_sweeps, {}, "sources.cl"},
      {Process::water,
       "water",
       "",
       always,
       water_sweeps,
       {"boundary_out", "clipped", "water_exchanged"},
       "water.cl"},
      {Process::erosion,
       "erosion",
       "erosion",
       erosion_on,
       erosion_sweeps,
       {"eroded", "deposited", "eroded_bedrock", "bed_bulking"},
       "erosion.cl",
       erosion_initial},
      // erosion.enabled switches transport too: what erosion lifts must move
      {Process::transport,
       "transport",
       "transport",
       erosion_on,
       transport_sweeps,
       {"sediment_out", "transport_change", "sediment_exchanged"},
       "transport.cl"},
      {Process::thermal,
       "thermal",
       "thermal",
       thermal_on,
       thermal_sweeps,
       {"thermal_moved"},
       "thermal.cl"},
      {Process::evaporation,
       "evaporation",
       "evaporation",
       always,
       evaporation_sweeps,
       {"evaporated"},
       "evaporation.cl"},
      {Process::snow,
       "snow",
       "snow",
       snow_on,
       snow_sweeps,
       {"snowfall", "rain_on_snow", "snow_melted", "snow_runoff"},
       "snow.cl",
       snow_initial},
      {Process::infiltration,
       "infiltration",
       "infiltration",
       infiltration_on,
       infiltration_sweeps,
       {"infiltrated", "soil_drained"},
       "infiltration.cl",
       infiltration_initial},
  };
  return table;
}

const std::vector<TallyInfo>& tally_table() {
  // ERODEM_TALLIES (ledger.hpp), in its order: the order Simulation::step adds them
  static const std::vector<TallyInfo> table{
#define ERODEM_TALLY_INFO(name, zero_if_absent, doc) {#name, &StepTally::name, &Ledger::name},
      ERODEM_TALLIES(ERODEM_TALLY_INFO)
#undef ERODEM_TALLY_INFO
  };
  return table;
}

const ProcessInfo& process_info(Process p) {
  for (const auto& e : process_table())
    if (e.id == p) return e;
  throw Error(ExitCode::internal, "process without a table entry");
}

const char* process_name(Process p) {
  return process_info(p).name;
}

const std::vector<std::string>& grid_inputs() {
  static const std::vector<std::string> inputs{"kind",
                                               "dx",
                                               "dy",
                                               "area",
                                               "hardness",
                                               "manning_n",
                                               "rain_factor",
                                               "air_temperature",
                                               "infiltration_ksat",
                                               "infiltration_suction_deficit",
                                               "infiltration_store"};
  return inputs;
}

std::vector<Process> step_sequence(const Params& params) {
  std::vector<Process> seq;
  for (const auto& e : process_table())
    if (e.enabled(params)) seq.push_back(e.id);
  return seq;
}

std::vector<std::pair<Process, SweepInfo>> step_sweeps(const Params& params) {
  std::vector<std::pair<Process, SweepInfo>> out;
  for (const auto& e : process_table())
    if (e.enabled(params))
      for (auto& s : e.sweeps(params)) out.emplace_back(e.id, std::move(s));
  return out;
}

std::vector<std::vector<Process>> fused_passes(const Params& params) {
  if (params.flow.scheme == FlowScheme::shallow_water) return {};
  for (const Process p : {Process::flow, Process::sources, Process::water})
    for (const auto& s : process_info(p).sweeps(params))
      if (s.generic) return {};
  std::vector<std::vector<Process>> runs{
      {Process::flow, Process::sources, Process::water, Process::evaporation}};
  bool erosion_generic = false;
  for (const auto& s : process_info(Process::erosion).sweeps(params))
    erosion_generic = erosion_generic || s.generic;
  if (!erosion_generic)
    runs.push_back({Process::flow, Process::sources, Process::water, Process::erosion});
  runs.push_back({Process::flow, Process::sources, Process::water});
  return runs;
}

std::vector<std::vector<Process>> step_passes(const Params& params, bool fused) {
  const std::vector<Process> seq = step_sequence(params);
  const auto runs = fused ? fused_passes(params) : std::vector<std::vector<Process>>{};
  std::vector<std::vector<Process>> passes;
  for (std::size_t k = 0; k < seq.size();) {
    std::size_t taken = 1;
    for (const auto& run : runs)  // the longest run that starts here
      if (run.size() > taken && k + run.size() <= seq.size() &&
          std::equal(run.begin(), run.end(), seq.begin() + static_cast<std::ptrdiff_t>(k)))
        taken = run.size();
    passes.emplace_back(seq.begin() + static_cast<std::ptrdiff_t>(k),
                        seq.begin() + static_cast<std::ptrdiff_t>(k + taken));
    k += taken;
  }
  return passes;
}

SweepInfo pass_sweep(const std::vector<Process>& pass, const Params& params) {
  SweepInfo out{"pass", Domain::cells, {}, {}};
  for (const Process p : pass)
    for (const auto& s : process_info(p).sweeps(params)) {
      if (s.domain != Domain::cells) continue;
      for (const auto& u : s.uses) {
        auto it = std::find_if(out.uses.begin(), out.uses.end(),
                               [&](const FieldUse& o) { return std::string(o.field) == u.field; });
        if (it == out.uses.end()) {
          out.uses.push_back(u);
          continue;
        }
        // read first, written later: an update; written first: a write (later reads hit the
        // cache); read twice: one read
        if (writes(u.access) && !writes(it->access))
          it->access = reads_neighbours(it->access) || reads_neighbours(u.access)
                           ? Access::update_neighbours
                           : Access::update;
      }
    }
  return out;
}

void check_sweeps(const std::vector<std::pair<Process, SweepInfo>>& sweeps) {
  std::set<std::string> provided(grid_inputs().begin(), grid_inputs().end());
  for (const auto& f : field_table())
    if (f.state) provided.insert(f.name);
  for (const auto& [p, s] : sweeps) {
    for (const auto& u : s.uses)
      if (u.access != Access::write && !provided.count(u.field))
        throw Error(ExitCode::internal,
                    fmt::format("process table: sweep '{}' of process '{}' reads '{}', which no "
                                "grid input, state field or earlier sweep of the step provides",
                                s.name, process_name(p), u.field));
    for (const auto& u : s.uses) provided.insert(u.field);
    for (const char* f : s.leaves) provided.insert(f);
  }
}

namespace {

/// Whether `f` is a grid input no sweep writes (the kinds, the per-row sizes).
bool grid_input(const std::string& f) {
  return f == "kind" || f == "dx" || f == "dy" || f == "area";
}

/// Adds `field` to `out` once, but not the grid inputs that no sweep writes (the kinds and
/// the per-row sizes): the lists of the halo exchange.
void add_halo_field(std::vector<std::string>& out, const std::string& field) {
  if (grid_input(field)) return;
  if (std::find(out.begin(), out.end(), field) == out.end()) out.push_back(field);
}

}  // namespace

std::vector<std::string> halo_fields(const SweepInfo& sweep) {
  std::vector<std::string> out;
  auto add = [&](const std::string& f) { add_halo_field(out, f); };
  for (const auto& u : sweep.uses)
    if (writes(u.access)) add(u.field);
  for (const char* f : sweep.leaves) add(f);
  return out;
}

namespace {

/// The fields the faces of sections and outlets (sections.h) read in the cell beyond each face,
/// one row away, just before process `p` runs (Backend::run): the outflows before the water
/// update (measure_water_faces); the outflows, the sediment and the flow depth before the
/// transport (measure_sediment_faces); none before any other process.
const std::vector<std::string>& section_face_reads(Process p) {
  static const std::vector<std::string> water{"flux_left", "flux_right", "flux_top", "flux_bottom"};
  static const std::vector<std::string> transport{"flux_left",   "flux_right", "flux_top",
                                                  "flux_bottom", "sediment",   "depth_flow"};
  static const std::vector<std::string> none;
  return p == Process::water ? water : p == Process::transport ? transport : none;
}

}  // namespace

std::vector<std::string> neighbour_read_fields(const Params& params) {
  std::vector<std::string> out;
  auto add = [&](const std::string& f) { add_halo_field(out, f); };
  for (const auto& [p, s] : step_sweeps(params))
    for (const auto& u : s.uses)
      if (reads_neighbours(u.access)) add(u.field);
  if (!params.section.empty() || !params.outlet.empty())
    for (const Process p : {Process::water, Process::transport})
      for (const std::string& f : section_face_reads(p)) add(f);
  return out;
}

std::vector<std::string> halo_fields(const SweepInfo& sweep,
                                     const std::vector<std::string>& needed) {
  std::vector<std::string> out;
  for (const std::string& f : halo_fields(sweep))
    if (std::find(needed.begin(), needed.end(), f) != needed.end()) out.push_back(f);
  return out;
}

int band_halo_rows(const Params& params) {
  return params.flow.scheme == FlowScheme::pipes ? 1 : 2;
}

namespace {

/// The fields a process's own loops exchange after its non-generic sweep k, before the next:
/// those it writes that a later one of them reads at a neighbour and leaves as it is
/// (sweeps_tails: thermal's shares).
std::vector<std::string> loop_exchanged(const std::vector<SweepInfo>& sweeps, std::size_t k) {
  std::vector<std::string> done;
  if (sweeps[k].generic) return done;
  const std::vector<std::string> written = halo_fields(sweeps[k]);
  for (std::size_t j = k + 1; j < sweeps.size(); ++j)
    if (!sweeps[j].generic)
      for (const FieldUse& u : sweeps[j].uses)
        if (reads_neighbours(u.access) && !writes(u.access) &&
            std::find(written.begin(), written.end(), u.field) != written.end())
          done.emplace_back(u.field);
  return done;
}

}  // namespace

std::vector<SweepsTail> sweeps_tails(const Params& params, bool halo, int band_halo) {
  const std::vector<std::string> needed =
      halo ? neighbour_read_fields(params) : std::vector<std::string>();
  std::vector<SweepsTail> tails;
  for (const ProcessInfo& info : process_table()) {
    const auto p = static_cast<std::size_t>(info.id);
    if (tails.size() <= p) tails.resize(p + 1);
    SweepsTail& t = tails[p];
    t.sweeps = info.sweeps(params);
    t.exchange.assign(t.sweeps.size(), {});
    if (!halo) continue;
    for (std::size_t k = 0; k < t.sweeps.size(); ++k) {
      const std::vector<std::string> done = loop_exchanged(t.sweeps, k);
      for (const std::string& f : halo_fields(t.sweeps[k], needed))
        if (std::find(done.begin(), done.end(), f) == done.end()) t.exchange[k].push_back(f);
    }
  }
  if (halo && band_halo > 0) exact_in_band(params, band_halo, tails);
  return tails;
}

namespace {

/// The rows beyond its own cell's that a use reads, in a band of `h` halo rows.
int reach_rows(const FieldUse& u, int h) {
  if (!reads_neighbours(u.access)) return 0;
  return u.rows < 0 ? h : std::min(u.rows, h);
}

/// Whether a step may skip the process (Simulation::step runs the terrain classes every
/// terrain_classes.interval steps only).
bool may_skip(Process p) {
  return p == Process::terrain_class;
}

}  // namespace

void exact_in_band(const Params& params, int h, std::vector<SweepsTail>& tails) {
  // the sweeps in the order the backends run them (run_sweeps_tail): each process's own loops
  // in order, then their exchanges, then its generic sweeps with theirs
  struct At {
    std::size_t p, k;
    bool exchanges_after;  // the exchanges of (p, k) come right after it (else: `flush`)
    bool flush;            // the process's own loops end here: their exchanges follow
  };
  std::vector<At> order;
  for (const Process proc : step_sequence(params)) {
    const auto p = static_cast<std::size_t>(proc);
    const auto& sweeps = tails.at(p).sweeps;
    std::size_t last_own = sweeps.size();
    for (std::size_t k = 0; k < sweeps.size(); ++k)
      if (!sweeps[k].generic) last_own = k;
    for (std::size_t k = 0; k < sweeps.size(); ++k)
      if (!sweeps[k].generic) order.push_back({p, k, false, k == last_own});
    for (std::size_t k = 0; k < sweeps.size(); ++k)
      if (sweeps[k].generic) order.push_back({p, k, true, false});
  }
  // marks[i]: the fields exchanged after order[i]
  std::vector<std::set<std::string>> marks(order.size());
  std::map<std::string, std::vector<std::size_t>> writers;  // of each field, in step order
  for (std::size_t i = 0; i < order.size(); ++i) {
    const SweepInfo& s = tails[order[i].p].sweeps[order[i].k];
    for (const std::string& f : halo_fields(s)) writers[f].push_back(i);
  }
  auto skips = [&](std::size_t i) { return may_skip(static_cast<Process>(order[i].p)); };
  // the faces of sections and outlets read the cell beyond each face, one row away, before the
  // water update and the transport (section_face_reads)
  const bool faces = !params.section.empty() || !params.outlet.empty();

  std::map<std::string, int> start;  // e at the start of a step; h where absent
  auto get = [h](const std::map<std::string, int>& e, const std::string& f) {
    const auto it = e.find(f);
    return grid_input(f) || it == e.end() ? h : it->second;
  };
  for (int round = 0;; ++round) {
    if (round > 64)
      throw Error(ExitCode::internal, "exact_in_band: the halo rows' data flow does not settle");
    std::map<std::string, int> e = start;
    std::size_t marked = 0;
    for (const auto& m : marks) marked += m.size();
    // a read `r` rows away, before order[i], of a field exact on fewer: the last sweep to write
    // it exchanges it (the step before's, where none of this step has yet), and the one before
    // that where the step may skip it, up to one it never skips
    auto need = [&](const std::string& f, int r, std::size_t i) {
      if (grid_input(f) || get(e, f) >= r) return;
      const std::vector<std::size_t>& w = writers.at(f);
      const auto first_after = std::lower_bound(w.begin(), w.end(), i) - w.begin();
      for (std::size_t n = 1; n <= w.size(); ++n) {
        const std::size_t j = w[(first_after + w.size() - n) % w.size()];
        // an own loop's exchange comes after the process's last own loop: not before a later
        // one of them (the loop would have to exchange it itself, as thermal's shares)
        if (j < i && order[j].p == order[i].p && !order[j].exchanges_after &&
            !order[i].exchanges_after)
          throw Error(ExitCode::internal,
                      fmt::format("exact_in_band: sweep '{}' reads '{}' {} rows away, which an "
                                  "earlier loop of its process writes and does not exchange",
                                  tails[order[i].p].sweeps[order[i].k].name, f, r));
        marks[j].insert(f);
        if (!skips(j)) break;
      }
      e[f] = h;
    };
    std::vector<std::size_t> own_loops;  // the process's own sweeps run so far
    for (std::size_t i = 0; i < order.size(); ++i) {
      const auto& sweeps = tails[order[i].p].sweeps;
      const SweepInfo& s = sweeps[order[i].k];
      const auto proc = static_cast<Process>(order[i].p);
      if (faces && order[i].k == 0)
        for (const std::string& f : section_face_reads(proc)) need(f, std::min(1, h), i);
      int m = s.domain == Domain::cells ? h - 1 : h;
      for (const FieldUse& u : s.uses) {
        if (u.access == Access::write) continue;
        const int r = reach_rows(u, h);
        need(u.field, r, i);
        // the ghost cells on a band's halo rows are its ghost columns, which read along their
        // own row (a ghost row, which reads the rows inside, is never a halo row)
        m = std::min(m, get(e, u.field) - (s.domain == Domain::halo ? 0 : r));
      }
      m = std::max(m, 0);
      for (const std::string& f : halo_fields(s))
        // a cells sweep writes every row of its band; the others some cells only, both copies
        // of each alike; a sweep the step may skip leaves what was there, or its own
        e[f] = s.domain == Domain::cells && !skips(i) ? m : std::min(get(e, f), m);
      if (order[i].exchanges_after) {
        for (const std::string& f : marks[i]) e[f] = h;
        continue;
      }
      for (const std::string& f : loop_exchanged(sweeps, order[i].k)) e[f] = h;
      own_loops.push_back(i);
      if (order[i].flush) {
        for (const std::size_t j : own_loops)
          for (const std::string& f : marks[j]) e[f] = h;
        own_loops.clear();
      }
    }
    std::size_t marked_now = 0;
    for (const auto& mk : marks) marked_now += mk.size();
    bool same = marked_now == marked;
    for (auto& [f, v] : e) {
      const int next = std::min(get(start, f), v);
      if (next != get(start, f)) same = false;
      start[f] = next;
    }
    if (same) break;
  }
  for (std::size_t i = 0; i < order.size(); ++i) {
    SweepsTail& t = tails[order[i].p];
    t.unsent.resize(t.sweeps.size());
    auto& exchange = t.exchange[order[i].k];
    auto& unsent = t.unsent[order[i].k];
    unsent.clear();
    for (const std::string& f : marks[i])  // never outside the list: add it, to be safe
      if (std::find(exchange.begin(), exchange.end(), f) == exchange.end()) exchange.push_back(f);
    for (const std::string& f : exchange)
      if (!marks[i].count(f)) unsent.push_back(f);
  }
}

namespace {

/// Whether a sweep of the step (on the cells only, or on any domain) writes `field`.
bool sweeps_write(const Params& params, const std::string& field, bool cells_only) {
  for (const auto& [p, s] : step_sweeps(params))
    if (s.domain == Domain::cells || !cells_only)
      for (const auto& u : s.uses)
        if (field == u.field && writes(u.access)) return true;
  return false;
}

}  // namespace

bool bed_changes(const Params& params) {
  return sweeps_write(params, "bed", true);
}

bool step_writes(const Params& params, const std::string& field) {
  return sweeps_write(params, field, false);
}

bool material_field(FieldId id) {
  return id == FieldId::bed || id == FieldId::bed_residual || id == FieldId::sediment;
}

bool changes_material(Process p, const Params& params) {
  for (const SweepInfo& s : process_info(p).sweeps(params))
    if (s.domain != Domain::halo)
      for (const FieldUse& u : s.uses)
        if (writes(u.access))
          for (const FieldInfo& f : field_table())
            if (material_field(f.id) && std::string(f.name) == u.field) return true;
  return false;
}

std::vector<char> material_changers(const Params& params) {
  std::vector<char> out;
  for (const ProcessInfo& info : process_table()) {
    const auto p = static_cast<std::size_t>(info.id);
    if (out.size() <= p) out.resize(p + 1, 0);
    out[p] = changes_material(info.id, params);
  }
  return out;
}

SweepBytes sweep_bytes(const SweepInfo& sweep, int real_bytes) {
  SweepBytes b;
  if (sweep.domain != Domain::cells) return b;
  for (const auto& u : sweep.uses) {
    const int size = std::string(u.field) == "kind" ? 1 : real_bytes;
    if (u.access != Access::write) {
      b.read += size;
      b.reads += (b.reads.empty() ? "" : " ") + std::string(u.field);
    }
    if (writes(u.access)) {
      b.write += size;
      b.writes += (b.writes.empty() ? "" : " ") + std::string(u.field);
    }
  }
  return b;
}

SweepBytes process_bytes(Process p, const Params& params, int real_bytes) {
  SweepBytes total;
  for (const auto& s : process_info(p).sweeps(params)) {
    const SweepBytes b = sweep_bytes(s, real_bytes);
    total.read += b.read;
    total.write += b.write;
    if (!b.reads.empty()) total.reads += (total.reads.empty() ? "" : " | ") + b.reads;
    if (!b.writes.empty()) total.writes += (total.writes.empty() ? "" : " | ") + b.writes;
  }
  return total;
}

const SweepInfo& stats_sweep(bool material) {
  // CpuBackend::stats and stats.cl (cell_state_ok, stats.h): volumes, maxima, the first bad
  // cell, over the active cells
  static const SweepInfo sweep{"stats",
                               Domain::cells,
                               {{"kind", R},
                                {"bed", R},
                                {"bed_residual", R},
                                {"water_depth", R},
                                {"sediment", R},
                                {"velocity_x", R},
                                {"velocity_y", R}},
                               {"field_stats"}};
  static const SweepInfo water_only{
      "stats",
      Domain::cells,
      {{"kind", R}, {"water_depth", R}, {"velocity_x", R}, {"velocity_y", R}},
      {"field_stats"}};
  return material ? sweep : water_only;
}

std::vector<std::string> opencl_cell_kernels() {
  std::vector<std::string> out;
  auto add = [&](const SweepInfo& sweep) {
    if (sweep.domain != Domain::cells) return;
    for (const char* k : sweep.opencl_kernels)
      if (std::find(out.begin(), out.end(), k) == out.end()) out.emplace_back(k);
  };
  // every process of the table (enabled or not), with each flow and transport scheme and
  // erosion law, a stage hydrograph, and the snow pack without and with temperature grids
  Params p;
  p.rain.rate = 1.0;
  p.evaporation.rate = 1.0;
  p.boundary.stage = {{0.0, 0.0}};
  p.snow.slide_angle = 45.0;
  for (auto flow : {FlowScheme::pipes, FlowScheme::local_inertial, FlowScheme::shallow_water})
    for (auto transport : {TransportScheme::conservative, TransportScheme::semi_lagrangian})
      for (auto law : {ErosionLaw::mei, ErosionLaw::physical}) {
        p.flow.scheme = flow;
        p.transport.scheme = transport;
        p.erosion.law = law;
        for (const char* grids : {"", "grids"}) {
          p.snow.temperature_grids = grids;
          for (const auto& e : process_table())
            for (const auto& sweep : e.sweeps(p)) add(sweep);
        }
      }
  add(stats_sweep());
  return out;
}

std::vector<std::string> opencl_program_order() {
  std::vector<std::string> order{"reduce.cl"};
  for (const auto& e : process_table()) order.emplace_back(e.opencl_source);
  order.emplace_back("edges.cl");
  order.emplace_back("stats.cl");
  return order;
}

}  // namespace erodem
