// erodem — the process table (core/include/erodem/process.hpp): the step sequence, the tallies,
// the check of the sweeps' fields, the byte model, the bed-change set, the state and output
// fields, all derived from it, against what the code did when each was written by hand
// (2026-11-25).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/ledger.hpp"
#include "erodem/process.hpp"

namespace erodem::test {
namespace {

std::vector<std::string> names(const std::vector<Process>& seq) {
  std::vector<std::string> out;
  for (Process p : seq) out.emplace_back(process_name(p));
  return out;
}

TEST(ProcessTable, SequenceFollowsTheSwitches) {
  // Simulation::sequence() as it was written by hand: boundary, flow, sources (after the
  // flow, model.md section 2), water; erosion and transport when erosion is on; thermal when
  // it is on; evaporation always (it updates the wetness).
  Params p;
  using V = std::vector<std::string>;
  EXPECT_EQ(names(step_sequence(p)), (V{"boundary", "flow", "sources", "water", "evaporation"}));
  p.erosion.enabled = true;
  EXPECT_EQ(names(step_sequence(p)),
            (V{"boundary", "flow", "sources", "water", "erosion", "transport", "evaporation"}));
  p.thermal.enabled = true;
  EXPECT_EQ(names(step_sequence(p)), (V{"boundary", "flow", "sources", "water", "erosion",
                                        "transport", "thermal", "evaporation"}));
  p.erosion.enabled = false;
  EXPECT_EQ(names(step_sequence(p)),
            (V{"boundary", "flow", "sources", "water", "thermal", "evaporation"}));
}

TEST(ProcessTable, EveryTallyIsALedgerEntryBookedByOneProcess) {
  std::size_t booked = 0;
  for (const auto& t : tally_table()) {
    // a ledger entry of the same name and member (the HDF5 restart/ledger_<name>, Python keys)
    const auto& entries = ledger_entries();
    const auto e = std::find_if(entries.begin(), entries.end(), [&](const LedgerEntry& l) {
      return std::string(l.name) == t.name;
    });
    ASSERT_NE(e, entries.end()) << t.name;
    EXPECT_TRUE(e->member == t.ledger) << t.name;
    int by = 0;
    for (const auto& p : process_table())
      by += static_cast<int>(std::count_if(p.tallies.begin(), p.tallies.end(), [&](const char* n) {
        return std::string(n) == t.name;
      }));
    EXPECT_EQ(by, 1) << t.name << " is booked by " << by << " processes";
    booked += by;
  }
  std::size_t listed = 0;
  for (const auto& p : process_table()) listed += p.tallies.size();
  EXPECT_EQ(booked, listed) << "a process lists a tally that tally_table() lacks";
  std::printf("[process table] %zu tallies, each booked by one process\n", tally_table().size());
}

TEST(ProcessTable, CheckRejectsAReadOfAFieldNothingProvides) {
  Params p;
  p.erosion.enabled = p.thermal.enabled = true;
  for (auto transport : {TransportScheme::conservative, TransportScheme::semi_lagrangian})
    for (auto flow : {FlowScheme::pipes, FlowScheme::local_inertial}) {
      p.transport.scheme = transport;
      p.flow.scheme = flow;
      EXPECT_NO_THROW(check_sweeps(step_sweeps(p)));
    }
  // Thermal collapse with its two sweeps swapped: the apply sweep reads the share before any
  // sweep writes it.
  auto sweeps = step_sweeps(p);
  const auto share = std::find_if(sweeps.begin(), sweeps.end(), [](const auto& s) {
    return std::string(s.second.name) == "thermal_share";
  });
  ASSERT_NE(share, sweeps.end());
  std::iter_swap(share, share + 1);
  try {
    check_sweeps(sweeps);
    ADD_FAILURE() << "thermal_apply before thermal_share was accepted";
  } catch (const Error& e) {
    std::printf("[process table] %s\n", e.what());
    EXPECT_EQ(e.code(), ExitCode::internal);
    EXPECT_NE(std::string(e.what()).find("'thermal_apply'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'thermal_share'"), std::string::npos) << e.what();
  }
  // Conservative transport without the water update before it: nothing leaves "depth_flow".
  p.transport.scheme = TransportScheme::conservative;
  std::vector<std::pair<Process, SweepInfo>> no_water;
  for (auto& s : step_sweeps(p))
    if (s.first != Process::water) no_water.push_back(s);
  EXPECT_THROW(check_sweeps(no_water), Error);
}

// The byte model, per process, of the bench scenario's schemes and rates. Where it differs from
// the model written by hand in cmd_bench.cpp (2026-11-23; full local-inertial step 213 B/cell),
// the code had changed under that model: the water update reads the bed since the velocities
// are taken over the faces' flow depths (+4), erosion and slope collapse read and write the
// bed residual since the bed pair (+8, +8), and so do the statistics (+4): 237 B/cell with Mei's
// erosion law; the physical law reads Manning n and updates the soil (+12).
TEST(ProcessTable, ByteModelFromTheSweeps) {
  Params p;
  p.erosion.enabled = p.thermal.enabled = true;
  p.erosion.law = ErosionLaw::mei;
  p.rain.rate = 1e-6;
  p.evaporation.rate = 1e-7;
  auto bytes = [&](Process pr) { return process_bytes(pr, p, 4).total(); };
  EXPECT_EQ(bytes(Process::boundary), 0);
  EXPECT_EQ(bytes(Process::sources), 13);    // kind depth rain_factor | depth
  EXPECT_EQ(bytes(Process::flow), 45);       // kind bed depth manning flux*4 | flux*4
  EXPECT_EQ(bytes(Process::water), 37);      // kind bed depth flux*4 | depth velocity_x, _y
  EXPECT_EQ(bytes(Process::erosion), 41);    // kind bed bed_residual sediment depth u v hardness
  EXPECT_EQ(bytes(Process::transport), 29);  // kind sediment depth_flow flux*4 | sediment
  // kind bed wetness | share; kind bed residual wetness share | ... (the wet talus angle)
  EXPECT_EQ(bytes(Process::thermal), 38);
  EXPECT_EQ(bytes(Process::evaporation), 17);  // kind depth wetness | depth wetness
  EXPECT_EQ(sweep_bytes(stats_sweep(), 4).total(), 25);
  // kept material volumes (changes_material): kind depth velocity_x velocity_y
  EXPECT_EQ(sweep_bytes(stats_sweep(false), 4).total(), 13);
  for (const Process pr : step_sequence(p)) {
    const bool changes = pr == Process::erosion || pr == Process::transport ||
                         pr == Process::thermal;  // the boundary's fill: the ghosts only
    EXPECT_EQ(changes_material(pr, p), changes) << process_info(pr).name;
  }
  EXPECT_TRUE(material_field(FieldId::bed) && material_field(FieldId::bed_residual) &&
              material_field(FieldId::sediment));
  EXPECT_FALSE(material_field(FieldId::water_depth) || material_field(FieldId::rain_factor) ||
               material_field(FieldId::hardness));
  {  // an inflow's sediment (the sources write it at the inflow cells) and a stage hydrograph
    Params q = p;
    q.inflow.push_back(InflowSpec{});
    EXPECT_TRUE(changes_material(Process::sources, q));
    EXPECT_FALSE(changes_material(Process::boundary, q));
    q.boundary.stage = {{0.0, 1.0}};
    EXPECT_TRUE(changes_material(Process::boundary, q));
  }
  int full = sweep_bytes(stats_sweep(), 4).total();
  for (Process pr : step_sequence(p)) full += bytes(pr);
  EXPECT_EQ(full, 245);
  std::printf(
      "[process table] full local-inertial step %d B/cell (hand model of 2026-11-23: 213)\n", full);
  // kind bed bed_residual sediment soil depth u v manning hardness | bed residual sediment soil
  p.erosion.law = ErosionLaw::physical;
  EXPECT_EQ(bytes(Process::erosion), 41 + 12);
  p.flow.scheme = FlowScheme::pipes;
  p.transport.scheme = TransportScheme::semi_lagrangian;
  EXPECT_EQ(bytes(Process::flow), 41);
  EXPECT_EQ(bytes(Process::transport), 17);
  // shallow water: kind bed depth q_x q_y manning | flux*4 q_x q_y; the water update and the
  // velocity from q (kind depth q_x q_y | velocity_x, _y)
  p.flow.scheme = FlowScheme::shallow_water;
  EXPECT_EQ(bytes(Process::flow), 1 + 20 + 24);
  EXPECT_EQ(bytes(Process::water), 37 + 1 + 12 + 8);
  p.evaporation.rate = 0;
  EXPECT_EQ(bytes(Process::evaporation), 13);  // the depth is only read
  p.rain.rate = 0;
  EXPECT_EQ(bytes(Process::sources), 0);
  // float64: every field but the kind twice as wide
  p.flow.scheme = FlowScheme::local_inertial;
  EXPECT_EQ(process_bytes(Process::flow, p, 8).total(), 1 + 7 * 8 + 4 * 8);
  const SweepBytes f = process_bytes(Process::flow, p, 4);
  EXPECT_EQ(f.reads, "kind bed water_depth manning_n flux_left flux_right flux_top flux_bottom");
  EXPECT_EQ(f.writes, "flux_left flux_right flux_top flux_bottom");
  // the snow pack: kind bed rain_factor snow liquid depth | snow liquid depth; with temperature
  // grids the air_temperature field in place of the bed, the same bytes
  p.snow.enabled = true;
  EXPECT_EQ(bytes(Process::snow), 1 + 5 * 4 + 3 * 4);
  EXPECT_EQ(process_bytes(Process::snow, p, 4).reads,
            "kind bed rain_factor snow snow_liquid water_depth");
  p.snow.temperature_grids = "t2m.nc";
  EXPECT_EQ(bytes(Process::snow), 1 + 5 * 4 + 3 * 4);
  EXPECT_EQ(process_bytes(Process::snow, p, 4).reads,
            "kind air_temperature rain_factor snow snow_liquid water_depth");
}

TEST(ProcessTable, BedChangesWithErosionOrThermal) {
  Params p;
  EXPECT_FALSE(bed_changes(p));
  p.erosion.enabled = true;
  EXPECT_TRUE(bed_changes(p));
  p.erosion.enabled = false;
  p.thermal.enabled = true;
  EXPECT_TRUE(bed_changes(p));
}

TEST(ProcessTable, StateAndOutputFieldsAreTheListsOfBefore) {
  // state_fields() and output.fields' choices as written by hand before the table
  // (simulation.cpp and schema.cpp of 2026-11-25) with the snow pack and the shallow-water
  // scheme's unit discharges added, the bed shear stress as an output, the soil of the
  // physical erosion law, infiltration's store, the snow pack's liquid water and the terrain
  // classes, as sets: the order is the table's now.
  std::set<std::string> state, output(output_field_names().begin(), output_field_names().end());
  for (FieldId id : state_fields()) state.insert(field_info(id).name);
  EXPECT_EQ(state, (std::set<std::string>{"bed", "initial_bed", "water_depth", "sediment",
                                          "velocity_x", "velocity_y", "flux_left", "flux_right",
                                          "flux_top", "flux_bottom", "wetness", "bed_residual",
                                          "snow", "snow_liquid", "momentum_x", "momentum_y",
                                          "soil_thickness", "infiltrated", "terrain_class"}));
  EXPECT_EQ(output,
            (std::set<std::string>{
                "bed",        "water_depth",  "sediment",       "velocity_x",  "velocity_y",
                "erosion",    "wetness",      "hardness",       "flux_left",   "flux_right",
                "flux_top",   "flux_bottom",  "snow",           "snow_liquid", "momentum_x",
                "momentum_y", "shear_stress", "soil_thickness", "infiltrated", "terrain_class"}));
  // a field restored from files that lack it starts at 0: the bed residual and the snow pack,
  // added later
  for (const auto& f : field_table())
    EXPECT_EQ(f.restart_zero_if_absent,
              f.id == FieldId::bed_residual || f.id == FieldId::snow ||
                  f.id == FieldId::snow_liquid || f.id == FieldId::momentum_x ||
                  f.id == FieldId::momentum_y || f.id == FieldId::soil_thickness ||
                  f.id == FieldId::infiltrated || f.id == FieldId::terrain_class)
        << f.name;
}

TEST(ProcessTable, OpenClKernelsAndProgramOrder) {
  // the cell kernels whose work-group the OpenCL backend queried from its own list (before
  // 2026-11-26), the snow pack's (with snow.temperature_grids: snow_gridded), the shallow-water
  // second order's and first-order interior's (with its velocities), infiltration's, the stage
  // hydrograph's and the terrain classes' (added through the table), as a set; the program in step
  // order (the terrain classes first) (flow before sources since they run after it; before, the
  // files were listed in the enum's order)
  const auto k = opencl_cell_kernels();
  EXPECT_EQ(std::set<std::string>(k.begin(), k.end()),
            (std::set<std::string>{"sources_rain",
                                   "flow_pipes",
                                   "flow_pipes_interior",
                                   "flow_local_inertial_faces",
                                   "flow_local_inertial_faces_x_interior",
                                   "flow_local_inertial_faces_y_interior",
                                   "flow_local_inertial_split",
                                   "flow_local_inertial_split_interior",
                                   "water_update",
                                   "erosion",
                                   "erosion_physical",
                                   "transport_conservative",
                                   "transport_semi_lagrangian",
                                   "thermal_share",
                                   "thermal_apply",
                                   "evaporation",
                                   "snow",
                                   "snow_gridded",
                                   "snow_slide_share",
                                   "snow_slide",
                                   "infiltration",
                                   "boundary_level",
                                   "terrain_class",
                                   "flow_shallow_water",
                                   "flow_shallow_water_velocities",
                                   "flow_shallow_water_interior",
                                   "flow_shallow_water_muscl",
                                   "flow_shallow_water_muscl_interior",
                                   "flow_shallow_water_stage_depth",
                                   "shallow_water_velocity",
                                   "field_stats",
                                   "edge_tallies"}));
  EXPECT_EQ(k.size(), 32u) << "a kernel listed twice";
  EXPECT_EQ(opencl_program_order(),
            (std::vector<std::string>{"reduce.cl", "terrain_class.cl", "boundary.cl", "flow.cl",
                                      "sources.cl", "water.cl", "erosion.cl", "transport.cl",
                                      "thermal.cl", "evaporation.cl", "snow.cl", "infiltration.cl",
                                      "edges.cl", "stats.cl"}));
}

}  // namespace
}  // namespace erodem::test
