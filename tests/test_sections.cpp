// erodem tests — cross-sections and outlets (core/include/erodem/sections.hpp): the faces a
// polyline or an edge is rasterised into, the discharge and sediment flux measured through
// them from the water update's and the transport's own face fluxes, on every target, and the
// [[section]] / [[outlet]] schema with its errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "erodem/error.hpp"
#include "erodem/schema.hpp"
#include "erodem/sections.hpp"
#include "target_test.hpp"

namespace erodem::test {
namespace {

namespace vr = validation;

/// The channel of ManningPlane shortened to 60 x 3 cells of 10 m (slope 1e-3, Manning n 0.03,
/// 0.5 m^2/s fed at the west over the 30 m width: 15 m^3/s; the east edge open), with the
/// adaptive step:
/// a section across the middle (x = 300 m, drawn northwards, so eastward flow is positive)
/// and an outlet on the east edge.
struct Channel {
  ManningPlane plane;
  Channel() { plane.n = 60; }
  double inflow() const { return plane.q * 3 * plane.dx; }  // m^3/s
  Params params(FlowScheme scheme = FlowScheme::local_inertial) const {
    Params p = plane.params(2.0);
    p.flow.scheme = scheme;
    p.time.adaptive = true;
    p.time.dt_max = 5.0;
    p.section.push_back(SectionSpec{"middle", {{300.0, 0.0}, {300.0, 30.0}}});
    p.outlet.push_back(OutletSpec{"east", "east", {0.0, 0.0}});
    return p;
  }
  /// The water (m^3) on the cells west of the section (columns 0 .. 29).
  static double upstream_water(const Simulation& sim) {
    const auto d = sim.field(FieldId::water_depth);
    const Grid& g = sim.grid();
    double v = 0;
    for (int r = 0; r < g.ny; ++r)
      for (int c = 0; c < 30; ++c) v += d[static_cast<std::size_t>(r) * g.nx + c] * g.area[r];
    return v;
  }
};

class Sections : public TargetTest {};

TEST_P(Sections, SectionDischargeEqualsTheInflowAtSteadyState) {
  // At steady state the discharge through any cross-section of the channel is the inflow,
  // Q = 15 m^3/s. Bound: 1e-3 relative, the unsteadiness left after 4000 s (the kinematic
  // wave crosses the 600 m in about 800 s; ManningPlane's normal depth is met to 1e-4), far
  // above float32 rounding. And the section around the upstream half measures exactly what
  // left it: inflow volume - volume through the section = the change of the water upstream
  // (walls at the north, south and west), to rounding: 1e-10 of the inflow (float64), 2e-5
  // (float32: the depths' rounding over the steps). An idle solver carries nothing through
  // the section (discharge 0) and fails the first bound.
  const Channel ch;
  auto sim = make_simulation(ch.plane.terrain(), ch.params(), target());
  ASSERT_EQ(sim.section_layout().names.size(), 2u);
  ASSERT_EQ(sim.section_layout().faces.size(), 3u + 3u);  // the middle's 3 faces, the edge's 3
  const double before = Channel::upstream_water(sim);
  while (sim.time() < 4000.0) sim.step();
  const SectionState& mid = sim.sections()[0];
  const double q_err = std::abs(mid.discharge / ch.inflow() - 1.0);
  const double v_in = sim.ledger().inflow;
  const double budget = v_in - mid.volume - (Channel::upstream_water(sim) - before);
  const double b = bound(1e-10, 2e-5);
  std::printf(
      "[section steady] %s: discharge %.7g m^3/s vs inflow %.7g (|Q/Q_in - 1| %.2e, bound "
      "1e-3); inflow %.6g m^3 - through %.6g - upstream change = %.3e (%.2e of the inflow, bound "
      "%.0e); peak %.5g m^3/s at t = %.5g s\n",
      target().label().c_str(), mid.discharge, ch.inflow(), q_err, v_in, mid.volume, budget,
      std::abs(budget) / v_in, b, mid.peak_discharge, mid.peak_time);
  vr::expect_below(figure("section_steady_channel", "local_inertial",
                          "|section discharge / inflow - 1| at steady state", ch.plane.dx,
                          "the inflow (continuity)"),
                   q_err, 1e-3);
  vr::expect_below(figure("section_steady_channel", "local_inertial",
                          "|inflow - through the section - upstream change| / inflow", ch.plane.dx,
                          "the upstream water budget"),
                   std::abs(budget) / v_in, b);
}

TEST_P(Sections, OutletEqualsTheLedgersBoundaryOutflowAndSedimentOut) {
  // The east edge is the only open one, so the outlet on it measures what the ledger books as
  // boundary_out and sediment_out: the same face fluxes, summed per face in double instead of
  // per row, so equal to rounding: 1e-12 (float64), 1e-5 (float32) of the volume. Each scheme
  // (the pipes, local inertial, shallow water) and the physical erosion law with a laden
  // inflow (solid 1e-3 of the water). An idle solver lets nothing out: the outlet's volume must
  // also be over half the inflow's (the channel starts at half its normal depth), and its
  // sediment positive.
  const Channel ch;
  for (const FlowScheme scheme :
       {FlowScheme::local_inertial, FlowScheme::pipes, FlowScheme::shallow_water}) {
    Params p = ch.params(scheme);
    p.erosion.enabled = true;
    p.erosion.law = ErosionLaw::physical;
    p.inflow[0].sediment_concentration = 1e-3;
    auto sim = make_simulation(ch.plane.terrain(), p, target());
    while (sim.time() < 1500.0) sim.step();
    const SectionState& east = sim.sections()[1];
    const Ledger& L = sim.ledger();
    const double water = std::abs(east.volume / L.boundary_out - 1.0);
    const double sediment = std::abs(east.sediment_volume / L.sediment_out - 1.0);
    const double b = bound(1e-12, 1e-5);
    const char* name = scheme == FlowScheme::pipes           ? "pipes"
                       : scheme == FlowScheme::shallow_water ? "shallow_water"
                                                             : "local_inertial";
    std::printf(
        "[outlet = ledger] %s %s: water %.9g m^3 vs boundary_out %.9g (%.2e, bound %.0e); "
        "sediment %.6e vs sediment_out %.6e (%.2e); inflow %.6g m^3\n",
        target().label().c_str(), name, east.volume, L.boundary_out, water, b, east.sediment_volume,
        L.sediment_out, sediment, L.inflow);
    EXPECT_LT(water, b) << name;
    EXPECT_LT(sediment, b) << name;
    EXPECT_GT(east.volume, 0.5 * L.inflow) << name;
    EXPECT_GT(east.sediment_volume, 0.0) << name;
  }
}

ERODEM_INSTANTIATE_TARGETS(Sections);

TEST(SectionsAgreement, OpenClMeasuresTheCpusBits) {
  // The same functions of sections.h on the same float32 fluxes, summed in double in the same
  // order on the host: the OpenCL backend's sections equal the CPU reference's bit for bit
  // (the fields themselves agree bit for bit, test_agreement.cpp), here with erosion on and a
  // laden inflow, 300 steps.
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const Channel ch;
  Params p = ch.params();
  p.erosion.enabled = true;
  p.erosion.law = ErosionLaw::physical;
  p.inflow[0].sediment_concentration = 1e-3;
  auto cpu = make_simulation(ch.plane.terrain(), p, Target{"cpu", Precision::float32});
  auto ocl = make_simulation(ch.plane.terrain(), p, Target{"opencl", Precision::float32});
  long differ = 0;
  for (int k = 0; k < 300; ++k) {
    cpu.step();
    ocl.step();
    for (std::size_t s = 0; s < cpu.sections().size(); ++s)
      differ += cpu.sections()[s].discharge != ocl.sections()[s].discharge ||
                cpu.sections()[s].sediment_flux != ocl.sections()[s].sediment_flux;
  }
  std::printf("[sections agreement] %ld of %d values differ; outlet %.9g m^3 (cpu) %.9g (opencl)\n",
              differ, 300 * 2 * 2, cpu.sections()[1].volume, ocl.sections()[1].volume);
  EXPECT_EQ(differ, 0);
  EXPECT_GT(cpu.sections()[1].sediment_volume, 0.0);
}

// ---- the faces ----------------------------------------------------------------------------

Terrain grid_terrain(int nx, int ny) {
  return flat_terrain(nx, ny, 10.0);  // origin (0, ny * 10), 10 m cells
}

TEST(SectionLayout, AClosedLineGivesTheFacesAroundTheCellsInside) {
  // A square drawn clockwise (east along its north side, then south, west, north) around the
  // 2 x 2 cells (cols 2-3, rows 2-3) of a 6 x 6 grid: the inside is on the right of the line,
  // so inflow counts positive and outflow negative; the 8 faces between the 4 cells and their
  // 8 neighbours, each once.
  Params p;
  p.section.push_back(SectionSpec{"box", {{20, 40}, {40, 40}, {40, 20}, {20, 20}, {20, 40}}});
  const Terrain t = grid_terrain(6, 6);
  // (20, 40) .. (40, 20): x 20..40 is cols 2-3; y 40..20 is rows 2-3 (y = 60 - 10 row)
  const SectionLayout l = layout_sections(t, p);
  ASSERT_EQ(l.faces.size(), 8u);
  double out_east = 0, out_south = 0;
  for (std::size_t j = 0; j < l.faces.size(); ++j) {
    const Face& f = l.faces[j];
    const bool inside_a = f.col >= 2 && f.col <= 3 && f.row >= 2 && f.row <= 3;
    // a face's positive way (east/south) leads out of the box when the cell west/north of it
    // is inside: outflow, -1
    EXPECT_EQ(l.sign[j], inside_a ? -1.0 : 1.0) << f.col << "," << f.row << "," << f.axis;
    (f.axis == 0 ? out_east : out_south) += 1;
  }
  EXPECT_EQ(out_east, 4);
  EXPECT_EQ(out_south, 4);
}

TEST(SectionLayout, OutletsOnEdgesAndPoints) {
  Params p;
  p.outlet.push_back(OutletSpec{"w", "west", {0, 0}});
  p.outlet.push_back(OutletSpec{"n", "north", {0, 0}});
  p.outlet.push_back(OutletSpec{"corner", "", {5, 55}});  // the north-west cell
  const SectionLayout l = layout_sections(grid_terrain(4, 6), p);
  ASSERT_EQ(l.faces.size(), 6u + 4u + 2u);
  EXPECT_EQ(l.faces[0].col, -1);
  EXPECT_EQ(l.sign[0], -1.0);
  EXPECT_EQ(l.faces[6].row, -1);
  EXPECT_EQ(l.faces[6].axis, 1);
  EXPECT_EQ(l.section[10], 2);
  EXPECT_EQ(l.section[11], 2);
}

std::string layout_error(const Params& p, int nx = 6, int ny = 6) {
  try {
    layout_sections(grid_terrain(nx, ny), p);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::config);
    return e.what();
  }
  return "";
}

TEST(SectionLayout, ErrorsNameTheKey) {
  Params p;
  p.section.push_back(SectionSpec{"out", {{20, 40}, {200, 40}}});
  EXPECT_NE(layout_error(p).find("section[0].line[1]"), std::string::npos) << layout_error(p);
  p.section = {SectionSpec{"tiny", {{21, 41}, {22, 42}}}};
  EXPECT_NE(layout_error(p).find("crosses no face"), std::string::npos) << layout_error(p);
  p.section.clear();
  p.outlet = {OutletSpec{"inner", "", {25, 25}}};
  EXPECT_NE(layout_error(p).find("outlet[0].point"), std::string::npos) << layout_error(p);
  p.outlet = {OutletSpec{"far", "", {-5, 25}}};
  EXPECT_NE(layout_error(p).find("outside the grid"), std::string::npos) << layout_error(p);
}

// ---- the schema -------------------------------------------------------------------------

std::string config_error_of(const std::string& text) {
  try {
    validate(params_from_toml(toml::parse("[dem]\npath = \"x.tif\"\n" + text), "test.toml"),
             "test.toml");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::config) << e.what();
    return e.what();
  }
  return "";
}

TEST(SectionSchema, ReadsDumpsAndRejects) {
  const Params p = params_from_toml(
      toml::parse("[[section]]\nname = \"bridge\"\nline = [[0, 1], [2, 3], [4, 5]]\n"
                  "[[outlet]]\nname = \"sea\"\nedge = \"east\"\n"
                  "[[outlet]]\nname = \"culvert\"\npoint = [7, 8]\n"),
      "test.toml");
  ASSERT_EQ(p.section.size(), 1u);
  EXPECT_EQ(p.section[0].name, "bridge");
  EXPECT_EQ(p.section[0].vertices.size(), 3u);
  ASSERT_EQ(p.outlet.size(), 2u);
  EXPECT_EQ(p.outlet[0].edge, "east");
  EXPECT_EQ(p.outlet[1].point[1], 8.0);
  const Params back = params_from_toml(toml::parse(dump_toml(p)), "dump");
  EXPECT_TRUE(params_equal(p, back)) << dump_toml(p);

  const std::string one = config_error_of("[[section]]\nname = \"a\"\nline = [[0, 1]]\n");
  EXPECT_NE(one.find("section[0].line"), std::string::npos) << one;
  EXPECT_NE(one.find("two or more"), std::string::npos) << one;
  const std::string dup = config_error_of(
      "[[section]]\nname = \"a\"\nline = [[0, 1], [2, 3]]\n[[outlet]]\nname = \"a\"\nedge = "
      "\"west\"\n");
  EXPECT_NE(dup.find("outlet[0].name"), std::string::npos) << dup;
  EXPECT_NE(dup.find("duplicate"), std::string::npos) << dup;
  const std::string edge = config_error_of("[[outlet]]\nname = \"a\"\nedge = \"up\"\n");
  EXPECT_NE(edge.find("outlet[0].edge"), std::string::npos) << edge;
  const std::string both =
      config_error_of("[[outlet]]\nname = \"a\"\nedge = \"west\"\npoint = [1, 2]\n");
  EXPECT_NE(both.find("not both"), std::string::npos) << both;
  const std::string key = config_error_of("[[section]]\nname = \"a\"\npoints = [[0, 1], [2, 3]]\n");
  EXPECT_NE(key.find("section[0].points"), std::string::npos) << key;
  const std::string name =
      config_error_of("[[section]]\nname = \"a,b\"\nline = [[0, 1], [2, 3]]\n");
  EXPECT_NE(name.find("section[0].name"), std::string::npos) << name;
  const std::string none = config_error_of("[[section]]\nline = [[0, 1], [2, 3]]\n");
  EXPECT_NE(none.find("section[0].name"), std::string::npos) << none;
}

}  // namespace
}  // namespace erodem::test
