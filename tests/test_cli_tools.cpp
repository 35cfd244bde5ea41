// erodem — the tool subcommands end to end: devices, compare, bench.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "erodem/backends.hpp"
#include "erodem/grid.hpp"
#include "erodem/io/raster.hpp"

namespace fs = std::filesystem;

namespace {

using erodem::test::CliResult;
using erodem::test::run_cli;

bool contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

class CliTools : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("erodem_cli_tools_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Writes `stem`_<field>.tif for each field, as `erodem run` names its outputs, on an
  /// nx x ny grid of 10 m cells; values base + field index + scale * cell index.
  void write_run(const std::string& stem, int nx, int ny, double base, double scale,
                 const std::vector<std::string>& fields = {"bed", "water_depth"}) const {
    const erodem::Grid g = erodem::Grid::uniform(nx, ny, 10.0);
    for (std::size_t f = 0; f < fields.size(); ++f) {
      std::vector<float> v(g.cells());
      for (std::size_t i = 0; i < v.size(); ++i)
        v[i] = static_cast<float>(base + static_cast<double>(f) + scale * static_cast<double>(i));
      erodem::io::write_geotiff((dir_ / (stem + "_" + fields[f] + ".tif")).string(), g, v,
                                fields[f]);
    }
  }
  fs::path dir_;
};

TEST(AutoBackend, TheCpuReferenceRatherThanPoclAGpuWhenThereIsOne) {
  // A 200 x 5 channel ran 28 times slower on PoCL than on the CPU reference (issue 19), and the
  // CPU reference was as fast or faster at every size measured up to 2048^2: auto takes a GPU,
  // else the CPU reference, and says why; ERODEM_OPENCL_DEVICE still selects PoCL.
  erodem::ClDeviceInfo pocl;
  pocl.platform = "Portable Computing Language";
  pocl.device = "pthread-skylake";
  pocl.type = "CPU";
  erodem::ClDeviceInfo gpu = pocl;
  gpu.platform = "NVIDIA CUDA";
  gpu.device = "H100";
  gpu.type = "GPU";
  const auto cpu_only = erodem::auto_backend_choice({pocl}, "");
  const auto with_gpu = erodem::auto_backend_choice({pocl, gpu}, "");
  const auto selected = erodem::auto_backend_choice({pocl}, "portable:");
  std::printf("[auto] PoCL only: %s (%s); PoCL and a GPU: %s device %d; selected: %s\n",
              cpu_only.backend.c_str(), cpu_only.reason.c_str(), with_gpu.backend.c_str(),
              with_gpu.device, selected.backend.c_str());
  EXPECT_EQ(cpu_only.backend, "cpu");
  EXPECT_TRUE(contains(cpu_only.reason, "PoCL")) << cpu_only.reason;
  EXPECT_EQ(with_gpu.backend, "opencl");
  EXPECT_EQ(with_gpu.device, 1);
  EXPECT_EQ(selected.backend, "opencl");
}

TEST_F(CliTools, DevicesListsTheCpuReferenceAndWhatAutoPicks) {
  const auto r = run_cli("devices", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "CPU reference")) << r.output;
  EXPECT_TRUE(contains(r.output, "auto picks")) << r.output;
  // The CPU reference's instruction-set level, as its device() names it.
  const auto isa = erodem::cpu_isa_info();
  EXPECT_TRUE(contains(r.output, isa.level + " (built: " + isa.built)) << r.output;
  const auto devices = erodem::list_opencl_devices();
  if (erodem::opencl_available()) {
    ASSERT_FALSE(devices.empty());
    EXPECT_TRUE(contains(r.output, devices.front().device)) << r.output;
    EXPECT_TRUE(contains(r.output, "compute units")) << r.output;
  }
  const auto j = run_cli("devices --json", dir_);
  ASSERT_EQ(j.code, 0) << j.output;
  ASSERT_FALSE(j.output.empty());
  EXPECT_EQ(j.output.front(), '{') << j.output;
  EXPECT_TRUE(contains(j.output, "\"cpu_reference\"")) << j.output;
  EXPECT_TRUE(contains(j.output, "\"isa\": \"" + isa.level + "\"")) << j.output;
  EXPECT_TRUE(contains(j.output, "\"opencl_devices\"")) << j.output;
  EXPECT_TRUE(contains(j.output, "\"auto\": {\"backend\": ")) << j.output;
  if (erodem::opencl_available()) {
    EXPECT_TRUE(contains(j.output, "\"max_work_group_size\"")) << j.output;
    EXPECT_TRUE(contains(j.output, "\"device\": \"" + devices.front().device + "\"")) << j.output;
  }
}

TEST(OpenClCopyBandwidth, CopiesOnTheDeviceTheBackendChooses) {
  // `erodem bench` sets a GPU's kernels against this figure. It must come from the device the
  // backend runs on, move what it says (two buffers no larger than a quarter of the device's
  // memory) and be a rate: a probe that timed nothing (0) or an empty event (inf) fails.
  if (!erodem::opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const std::size_t want = std::size_t{64} << 20;
  const auto bw = erodem::opencl_copy_bandwidth(want, 5);
  const auto devices = erodem::list_opencl_devices();
  bool gpu = false;
  for (const auto& d : devices) gpu = gpu || d.gpu();
  std::printf("[opencl copy] %s / %s (%s): %.1f GB/s (%.1f to %.1f), %zu bytes per buffer\n",
              bw.device.platform.c_str(), bw.device.device.c_str(), bw.device.type.c_str(), bw.gbs,
              bw.gbs_low, bw.gbs_high, bw.bytes);
  EXPECT_EQ(bw.device.type, gpu ? "GPU" : devices.front().type);
  EXPECT_EQ(bw.repetitions, 5);
  EXPECT_LE(bw.bytes, want);
  EXPECT_LE(bw.bytes, bw.device.global_memory / 4);
  EXPECT_EQ(bw.bytes % 4096, 0u);
  // Above 0.1 GB/s (64 MiB in 1.3 s: no device of the last twenty years is that slow) and
  // below 100 TB/s (no memory is that fast: a timer that read zero would give inf).
  EXPECT_TRUE(bw.gbs_low > 0.1 && bw.gbs_low <= bw.gbs && bw.gbs <= bw.gbs_high &&
              bw.gbs_high < 1e5)
      << bw.gbs_low << " " << bw.gbs << " " << bw.gbs_high;
}

TEST_F(CliTools, CompareIdenticalOutputsPasses) {
  write_run("a", 16, 12, 100.0, 0.01);
  write_run("b", 16, 12, 100.0, 0.01);
  const auto r = run_cli("compare a.h5 b.h5 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"field\": \"bed\"")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"field\": \"water_depth\"")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"rel_l2\": 0,")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"cells\": 192")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"ok\": true}")) << r.output;
  // The table form, and single GeoTIFFs.
  const auto t = run_cli("compare a.h5 b.h5", dir_);
  EXPECT_EQ(t.code, 0) << t.output;
  EXPECT_TRUE(contains(t.output, "within tolerance")) << t.output;
  EXPECT_EQ(run_cli("compare a_bed.tif b_bed.tif", dir_).code, 0);
}

TEST_F(CliTools, CompareDifferentOutputsFailsAboveTolerance) {
  write_run("a", 16, 12, 100.0, 0.01);
  write_run("b", 16, 12, 100.0, 0.02);  // differs most at the last cell (15, 11)
  const auto r = run_cli("compare a.h5 b.h5 --tol 1e-5", dir_);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "FAIL")) << r.output;
  EXPECT_TRUE(contains(r.output, "(15,11)")) << r.output;
  const auto j = run_cli("compare a.h5 b.h5 --json --fields bed", dir_);
  EXPECT_EQ(j.code, 1) << j.output;
  EXPECT_TRUE(contains(j.output, "\"max_abs_at\": [15, 11]")) << j.output;
  EXPECT_FALSE(contains(j.output, "water_depth")) << j.output;
  const auto loose = run_cli("compare a.h5 b.h5 --tol 0.5", dir_);
  EXPECT_EQ(loose.code, 0) << loose.output;
}

TEST_F(CliTools, CompareMismatchedGridsExit65AndMissingInputs66) {
  write_run("a", 16, 12, 100.0, 0.01);
  write_run("small", 12, 12, 100.0, 0.01);
  const auto r = run_cli("compare a.h5 small.h5", dir_);
  EXPECT_EQ(r.code, 65) << r.output;
  EXPECT_TRUE(contains(r.output, "mismatch")) << r.output;
  EXPECT_EQ(run_cli("compare a.h5 nothing.h5", dir_).code, 66);
  EXPECT_EQ(run_cli("compare a_bed.tif nothing.tif", dir_).code, 66);
  // A field that one output lacks.
  write_run("c", 16, 12, 100.0, 0.01, {"bed"});
  const auto lacking = run_cli("compare a.h5 c.h5", dir_);
  EXPECT_EQ(lacking.code, 66) << lacking.output;
  EXPECT_TRUE(contains(lacking.output, "water_depth")) << lacking.output;
  EXPECT_EQ(run_cli("compare a.h5 c.h5 --fields bed", dir_).code, 0);
}

TEST_F(CliTools, CompareResultFilesAtMatchingTimes) {
  ASSERT_EQ(run_cli("generate --kind hill --size 24 --relief 20 hill.tif", dir_).code, 0);
  std::ofstream(dir_ / "c.toml") << R"([dem]
path = "hill.tif"
[time]
steps = 20
dt = 0.5
[rain]
rate = "100 mm/h"
[output]
path = "out.h5"
every = 10
fields = ["bed", "water_depth"]
)";
  ASSERT_EQ(run_cli("run c.toml --backend cpu --output a.h5", dir_).code, 0);
  ASSERT_EQ(run_cli("run c.toml --backend cpu --output b.h5", dir_).code, 0);
  ASSERT_EQ(
      run_cli("run c.toml --backend cpu --output wet.h5 --set 'rain.rate=200 mm/h'", dir_).code, 0);
  const auto same = run_cli("compare a.h5 b.h5 --json", dir_);
  EXPECT_EQ(same.code, 0) << same.output;
  EXPECT_TRUE(contains(same.output, "\"times\": [0, 5, 10]")) << same.output;
  EXPECT_TRUE(contains(same.output, "\"rel_l2\": 0,")) << same.output;
  const auto wet = run_cli("compare wet.h5 a.h5 --fields water_depth", dir_);
  EXPECT_EQ(wet.code, 1) << wet.output;
  EXPECT_EQ(run_cli("compare wet.h5 a.h5 --fields water_depth --tol 10", dir_).code, 0);
}

TEST_F(CliTools, BenchReportsRatesAndBandwidth) {
  const auto r =
      run_cli("bench --size 64 --steps 2 --threads 1 --stream-floats 1048576 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.front(), '{') << r.output;
  for (const char* key : {"\"cell_steps_per_second\"", "\"bandwidth\"", "\"copy_gbs\"",
                          "\"triad_gbs\"", "\"copy_gbs_1_thread\"", "\"bytes_per_cell\"", "\"gbs\"",
                          "\"fraction_of_copy\"", "\"fraction_of_triad\"", "\"process\": \"flow\"",
                          "\"process\": \"stats\"", "\"process\": \"full_step\""})
    EXPECT_TRUE(contains(r.output, key)) << key << "\n" << r.output;
  // One probe round before each of the 3 repetitions of the one run, and one at the end; the
  // median copy bandwidth lies between the lowest and the highest round.
  EXPECT_TRUE(contains(r.output, "\"rounds\": 4,")) << r.output;
  const auto number_after = [&r](const std::string& key) {
    const auto at = r.output.find("\"" + key + "\": ");
    return at == std::string::npos ? std::nan("") : std::stod(r.output.substr(at + key.size() + 4));
  };
  const double low = number_after("copy_gbs_lowest_round"), copy = number_after("copy_gbs"),
               high = number_after("copy_gbs_highest_round");
  std::printf("bench probe: copy %.1f GB/s, rounds %.1f to %.1f\n", copy, low, high);
  EXPECT_TRUE(low > 0 && low <= copy && copy <= high) << low << " " << copy << " " << high;
  // The byte model of the benchmark scenario (local inertial, conservative transport), from
  // the process table (tests/test_process_table.cpp has every process's figure).
  EXPECT_TRUE(contains(r.output, "\"process\": \"flow\", \"seconds_per_step\"")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"bytes_per_cell\": 45,")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"bytes_per_cell\": 245,")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"flow_scheme\": \"local_inertial\"")) << r.output;
}

TEST_F(CliTools, BenchSetsAGpuAgainstItsOwnMemory) {
  // An OpenCL run on a GPU is set against the GPU memory's copy bandwidth (the host's says
  // nothing of it) and has no triad figure; a run on PoCL, whose device is the host, stays set
  // against the host's probe.
  if (!erodem::opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const auto r =
      run_cli("bench --size 64 --steps 2 --backends opencl --stream-floats 1048576 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  bool gpu = false;
  for (const auto& d : erodem::list_opencl_devices()) gpu = gpu || d.gpu();
  std::printf("[bench on %s] device_bandwidth %s\n", gpu ? "a GPU" : "PoCL",
              contains(r.output, "\"device_bandwidth\"") ? "reported" : "not reported");
  EXPECT_EQ(contains(r.output, "\"device_bandwidth\""), gpu) << r.output;
  // a row of the byte model (not the per-step 'stats' rows with no bytes) without a triad
  const std::regex modelled_without_triad(
      "\"bytes_per_cell\": [1-9][0-9]*, \"gbs\": [^,]*, \"fraction_of_copy\": [0-9.e+-]+, "
      "\"fraction_of_triad\": null");
  EXPECT_EQ(std::regex_search(r.output, modelled_without_triad), gpu) << r.output;
}

TEST_F(CliTools, BenchGivesTheDeviceTimePerKernelWhenProfiling) {
  // ERODEM_OPENCL_PROFILE=1 puts a profiling event on every launch and read and books them per
  // kernel name. The bench runs 3 warm-up steps and, in each of its 3 repetitions, --steps steps
  // process by process and 3 x --steps full steps: 27 steps at --steps 2, so every kernel of
  // the step ran at least 27 times, each for a time above 0. Without the variable: no list.
  // The water update and erosion run as one kernel (water_erosion) in the fused steps (the
  // warm-up, full_step and full_fused: 3 + 3 x 2 x 2 = 15) and as their own kernels in the
  // others (process by process and full_unfused: 3 x 2 x 2 = 12): 27 of each either way.
  if (!erodem::opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const std::string args =
      "bench --size 64 --steps 2 --backends opencl --stream-floats 1048576 --json";
  const auto plain = run_cli(args, dir_);
  ASSERT_EQ(plain.code, 0) << plain.output;
  EXPECT_TRUE(contains(plain.output, "\"kernel_times\": []")) << plain.output;
  setenv("ERODEM_OPENCL_PROFILE", "1", 1);
  const auto r = run_cli(args, dir_);
  unsetenv("ERODEM_OPENCL_PROFILE");
  ASSERT_EQ(r.code, 0) << r.output;
  std::map<std::string, long> calls_of;
  for (const char* k :
       {"flow_local_inertial_split_interior", "sources_rain", "water_update", "erosion",
        "water_erosion", "thermal_share", "field_stats", "stats_rows", "read"}) {
    std::smatch m;
    const std::regex entry(std::string("\"kernel\": \"") + k +
                           "\", \"calls\": ([0-9]+), \"seconds\": ([0-9.e+-]+)");
    ASSERT_TRUE(std::regex_search(r.output, m, entry)) << k << "\n" << r.output;
    const long calls = std::stol(m[1].str());
    const double seconds = std::stod(m[2].str());
    std::printf("[kernel times] %-36s %5ld calls, %.3f ms\n", k, calls, 1e3 * seconds);
    calls_of[k] = calls;
    EXPECT_GT(seconds, 0.0) << k;
  }
  for (const auto& [k, calls] : calls_of) {
    if (k == "water_update" || k == "erosion")
      EXPECT_GE(calls + calls_of["water_erosion"], 27) << k << " and water_erosion";
    else if (k == "water_erosion")
      EXPECT_GE(calls, 15) << k;
    else
      EXPECT_GE(calls, 27) << k;
  }
}

TEST_F(CliTools, BenchRunsTheSchemesSetAndRejectsBadSettings) {
  // --set reaches the bench scenario through the config schema: pipes move 41 B/cell, the
  // semi-Lagrangian transport 17, so the full step 245 - 45 + 41 - 29 + 17 = 229.
  const auto r = run_cli(
      "bench --size 32 --steps 1 --threads 1 --stream-floats 1048576 --json --set "
      "flow.scheme=pipes --set transport.scheme=semi_lagrangian",
      dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"flow_scheme\": \"pipes\"")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"transport_scheme\": \"semi_lagrangian\"")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"bytes_per_cell\": 41,")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"bytes_per_cell\": 229,")) << r.output;
  const auto bad = run_cli("bench --size 32 --steps 1 --set flow.scheme=foo", dir_);
  std::printf("[bench --set flow.scheme=foo] exit %d: %s", bad.code, bad.output.c_str());
  EXPECT_EQ(bad.code, 78) << bad.output;
  EXPECT_TRUE(contains(bad.output, "flow.scheme")) << bad.output;
}

}  // namespace
