// erodem — the run driver io::RunSession that `erodem run` and the Python Simulation share:
// advance() stops at each limit, pieces give the one-run result bit for bit, an unstable step
// is recorded and named once, abandon() keeps the partial file, and a restart (with the
// stored config as the base) continues the stored run bit for bit.
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "erodem/error.hpp"
#include "erodem/io/results.hpp"
#include "erodem/io/run_session.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/ledger.hpp"
#include "erodem/schema.hpp"
#include "temp_dir.hpp"

namespace fs = std::filesystem;
using erodem::Error;
using erodem::ExitCode;
using erodem::Params;
using erodem::Simulation;
using erodem::io::Limits;
using erodem::io::ResultReader;
using erodem::io::RunSession;
using erodem::io::SessionOptions;
using erodem::io::Stop;

namespace {

/// A 32 x 32 synthetic valley with rain, erosion and thermal collapse, 60 adaptive steps,
/// a snapshot every 20 steps and one gauge: every part of the result file is written.
Params valley(const std::string& output) {
  const char* text = R"([dem]
synthetic = "valley"
size = 32
seed = 11
relief = "30 m"
cell_size = "10 m"
[initial]
water_depth = 0.05
[time]
steps = 60
adaptive = true
dt_max = "2 s"
[rain]
rate = "60 mm/h"
[erosion]
law = "mei"
enabled = true
sediment_capacity = 0.2
[thermal]
enabled = true
talus_angle = 30.0
[boundary]
east = "open"
[output]
every = 20
gauges = [[155.0, 155.0]]
)";
  Params p = erodem::params_from_toml(toml::parse(text), "valley");
  p.output.path = output;
  erodem::validate(p, "valley");
  return p;
}

SessionOptions cpu(bool write = true) {
  SessionOptions o;
  o.backend = "cpu";
  o.command_line = "test_run_session";
  o.write = write;
  return o;
}

/// Whether two ledgers hold the same bits.
bool same_ledger(const erodem::Ledger& a, const erodem::Ledger& b) {
  for (const auto& e : erodem::ledger_entries())
    if (std::memcmp(&(a.*e.member), &(b.*e.member), sizeof(double)) != 0) return false;
  return true;
}

TEST(RunSession, AdvanceStopsAtEachLimitInOrder) {
  erodem::test::TempDir dir;
  RunSession s(valley(dir.file("unused.h5")), cpu(false));
  EXPECT_EQ(s.writer(), nullptr);
  EXPECT_FALSE(s.writing());
  Limits steps;
  steps.max_steps = 5;
  EXPECT_EQ(s.advance(steps), Stop::limit);
  EXPECT_EQ(s.sim().steps_done(), 5);
  Limits until;
  until.until_time = s.sim().time() + 3.0;
  EXPECT_EQ(s.advance(until), Stop::limit);
  EXPECT_GE(s.sim().time(), until.until_time);
  const long after_until = s.sim().steps_done();
  // `interrupted` is asked before every step, first: 3 steps, then it says stop.
  int asked = 0;
  EXPECT_EQ(s.advance({}, [&] { return ++asked > 3; }), Stop::interrupted);
  EXPECT_EQ(s.sim().steps_done(), after_until + 3);
  // A wall time of 0 lets exactly one step run.
  Limits wall;
  wall.wall_seconds = 0.0;
  EXPECT_EQ(s.advance(wall), Stop::wall);
  EXPECT_EQ(s.sim().steps_done(), after_until + 4);
  long seen = 0;
  EXPECT_EQ(s.advance({}, {}, [&](const Simulation&) { ++seen; }), Stop::finished);
  EXPECT_EQ(s.sim().steps_done(), 60);
  EXPECT_EQ(seen, 60 - (after_until + 4));
  // At the end: returns at once; without to_end it steps on.
  EXPECT_EQ(s.advance(), Stop::finished);
  Limits beyond;
  beyond.to_end = false;
  beyond.max_steps = 2;
  EXPECT_EQ(s.advance(beyond), Stop::limit);
  EXPECT_EQ(s.sim().steps_done(), 62);
  std::printf(
      "[run_session] limits: 5 steps, until t + 3 s (%ld steps), 3 then interrupted, "
      "1 under wall 0, to the end (%ld on_step calls), 2 beyond\n",
      after_until - 5, seen);
}

TEST(RunSession, PiecesAndAPreloadedTerrainGiveTheOneRunFile) {
  erodem::test::TempDir dir;
  {
    RunSession one(valley(dir.file("one.h5")), cpu());
    ASSERT_NE(one.writer(), nullptr);
    EXPECT_EQ(one.advance(), Stop::finished);
    one.finish();
    EXPECT_FALSE(one.writing());
    EXPECT_EQ(one.writer()->snapshots(), 4u);  // t = 0 and every 20 steps
  }
  const Params p = valley(dir.file("pieces.h5"));
  const erodem::Terrain terrain = erodem::io::load_terrain(p);
  SessionOptions o = cpu();
  o.terrain = &terrain;
  {
    RunSession pieces(p, o);
    Limits seven;
    seven.max_steps = 7;
    while (pieces.advance(seven) == Stop::limit) {
    }
    pieces.finish();
  }
  ASSERT_TRUE(fs::exists(dir.file("one.h5")) && fs::exists(dir.file("pieces.h5")));
  EXPECT_FALSE(fs::exists(erodem::io::partial_path(dir.file("pieces.h5"))));
  const ResultReader a(dir.file("one.h5")), b(dir.file("pieces.h5"));
  ASSERT_EQ(a.times(), b.times());
  std::size_t values = 0;
  for (std::size_t i = 0; i < a.times().size(); ++i) {
    for (const auto& f : a.fields()) {
      const auto x = a.read_index(f, i), y = b.read_index(f, i);
      ASSERT_EQ(x.size(), y.size());
      EXPECT_EQ(std::memcmp(x.data(), y.data(), x.size() * sizeof(float)), 0) << f << " " << i;
      values += x.size();
    }
    EXPECT_TRUE(same_ledger(a.restart_point(i).ledger, b.restart_point(i).ledger));
  }
  const auto da = a.diagnostics(), db = b.diagnostics();
  ASSERT_EQ(da.size(), db.size());
  EXPECT_EQ(std::memcmp(da.data(), db.data(), da.size() * sizeof(da[0])), 0);
  const auto ga = a.gauges(), gb = b.gauges();
  EXPECT_EQ(ga.water_level, gb.water_level);
  std::printf(
      "[run_session] 60 steps in pieces of 7 on a preloaded terrain: %zu field values at "
      "%zu times, %zu diagnostics rows, %zu gauge rows identical\n",
      values, a.times().size(), da.size(), ga.time.size());
}

TEST(RunSession, AnUnstableStepIsRecordedAndNamed) {
  erodem::test::TempDir dir;
  Params p = valley(dir.file("out.h5"));
  p.time.adaptive = false;
  p.time.dt = 60.0;  // far beyond the CFL bound of 10 m cells
  p.initial.water_depth.value = 2.0;
  RunSession s(p, cpu());
  try {
    s.advance();
    FAIL() << "no unstable step";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::unstable);
    const std::string m = e.what();
    std::printf("[run_session] %s\n", m.c_str());
    EXPECT_NE(m.find("the results up to step 1 (t = 60 s) are in "), std::string::npos) << m;
    EXPECT_NE(m.find(erodem::io::partial_path(dir.file("out.h5")) + "; "), std::string::npos) << m;
    EXPECT_NE(m.find("out.h5 was not created"), std::string::npos) << m;
  }
  s.close_output();
  EXPECT_FALSE(fs::exists(dir.file("out.h5")));
  const ResultReader r(erodem::io::partial_path(dir.file("out.h5")));
  EXPECT_EQ(r.times().size(), 2u);  // t = 0 and the failing step
  EXPECT_EQ(r.diagnostics().size(), 1u);
}

TEST(RunSession, AbandonKeepsThePartialFileWithOneSnapshotOfTheStep) {
  erodem::test::TempDir dir;
  for (const long stop_at : {13L, 20L}) {  // 20: the step has its snapshot already
    const std::string name = "stop" + std::to_string(stop_at) + ".h5";
    RunSession s(valley(dir.file(name)), cpu());
    EXPECT_EQ(s.advance({}, [&] { return s.sim().steps_done() == stop_at; }), Stop::interrupted);
    s.abandon();
    s.abandon();  // closed: no-op
    EXPECT_FALSE(s.writing());
    EXPECT_NE(s.partial_note().find("up to step " + std::to_string(stop_at)), std::string::npos);
    EXPECT_FALSE(fs::exists(dir.file(name)));
    const ResultReader r(erodem::io::partial_path(dir.file(name)));
    EXPECT_EQ(r.times().size(), 2u) << stop_at;  // t = 0 and the step reached, once
    EXPECT_EQ(r.restart_point(r.times().size() - 1).steps, stop_at);
    EXPECT_EQ(r.diagnostics().size(), static_cast<std::size_t>(stop_at));
  }
}

TEST(RunSession, RestartContinuesTheStoredRunBitForBit) {
  erodem::test::TempDir dir;
  std::vector<double> bed;
  erodem::Ledger ledger;
  {
    RunSession full(valley(dir.file("full.h5")), cpu());
    full.advance();
    full.finish();
    bed = full.sim().field(erodem::FieldId::bed);
    ledger = full.sim().ledger();
  }
  const ResultReader stored(dir.file("full.h5"));
  const double t = stored.times()[1];
  // From the stored config (its config_toml), restarted at step 20.
  const std::string arg = dir.file("full.h5") + ":" + std::to_string(t);
  SessionOptions o = cpu();
  o.restart = arg;
  Params p = erodem::io::stored_params(arg);
  p.output.path = dir.file("rest.h5");
  RunSession rest(p, o);
  EXPECT_TRUE(rest.warnings().empty());
  EXPECT_EQ(rest.first_step(), 20);
  EXPECT_EQ(rest.restart_from().rfind(dir.file("full.h5") + ":", 0), 0u) << rest.restart_from();
  rest.advance();
  rest.finish();
  EXPECT_TRUE(same_ledger(rest.sim().ledger(), ledger));
  EXPECT_EQ(rest.sim().field(erodem::FieldId::bed), bed);
  const ResultReader r(dir.file("rest.h5"));
  EXPECT_EQ(r.attribute("restart_from"), rest.restart_from());
  EXPECT_EQ(r.diagnostics().size(), 40u);
  // A changed key is allowed and named; the errors name the label and the file.
  Params changed = p;
  changed.erosion.dissolving_rate *= 2;
  changed.output.path = dir.file("changed.h5");
  RunSession c(changed, o);
  ASSERT_EQ(c.warnings().size(), 1u);
  EXPECT_NE(c.warnings()[0].find("erosion.dissolving_rate"), std::string::npos);
  SessionOptions bad = cpu(false);
  bad.restart = dir.file("full.h5") + ":0.5";
  bad.restart_label = "restart";
  try {
    RunSession s(p, bad);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::usage);
    EXPECT_EQ(
        std::string(e.what()).rfind("restart " + dir.file("full.h5") + ":0.5: no snapshot", 0), 0u)
        << e.what();
  }
}

}  // namespace
