// erodem — publishing a result file (results.hpp ResultWriter::publish, paths.hpp): a partial
// name unique to the process, never a file put at the final name by another process replaced
// (with or without --overwrite), the link + unlink way of file systems without renameat2, the
// partial files of ended processes, the holder of a locked file named, and two `erodem run`
// to one output at once without HDF5's file locks.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "cli_runner.hpp"
#include "erodem/error.hpp"
#include "erodem/io/paths.hpp"
#include "erodem/io/results.hpp"
#include "scenarios.hpp"
#include "temp_dir.hpp"

namespace fs = std::filesystem;
using erodem::ExitCode;
using erodem::io::ResultReader;
using erodem::io::ResultWriter;

namespace {

/// `steps` steps of rain on a 16 x 16 bumpy grid, a snapshot after each.
erodem::Simulation rainy(long steps = 3) {
  using namespace erodem;
  Params p = test::quiet_params(FlowScheme::local_inertial, 0.5);
  p.rain.rate = 1e-4;
  p.time.steps = steps;
  p.output.every = 1;
  p.output.fields = {"water_depth"};
  return test::make_simulation(test::bumpy_terrain(16, 10.0), std::move(p),
                               {"cpu", Precision::float32});
}

std::string text_of(const std::string& path) {
  std::ifstream in(path);
  std::string s;
  std::getline(in, s);
  return s;
}

/// The error `f` throws (its code; its message in `msg`); ExitCode::ok when none.
template <class F>
ExitCode error_of(F&& f, std::string& msg) {
  try {
    f();
  } catch (const erodem::Error& e) {
    msg = e.what();
    return e.code();
  }
  return ExitCode::ok;
}

/// A writer to `path` that has written a whole run of rainy(), up to its last snapshot, and
/// is to finish() (publish) it.
std::unique_ptr<ResultWriter> written(const std::string& path, bool overwrite) {
  auto sim = rainy();
  auto w = std::make_unique<ResultWriter>(path, sim, "", overwrite);
  w->snapshot(sim);
  while (!sim.finished()) {
    sim.step();
    w->step_done(sim);
  }
  w->last_snapshot(sim);
  return w;
}

}  // namespace

TEST(Publish, PartialNameIsUniqueToTheProcess) {
  const std::string p = erodem::io::partial_path("out/run.h5");
  EXPECT_EQ(p,
            "out/.run.h5." + erodem::io::host_name() + "-" + std::to_string(getpid()) + ".partial");
  EXPECT_EQ(erodem::io::host_name().find('/'), std::string::npos);
}

TEST(Publish, AFileCreatedDuringTheRunIsNeverReplaced) {
  erodem::test::TempDir dir("erodem_publish_");
  const std::string path = dir.file("run.h5");
  const auto w = written(path, false);
  std::ofstream(path) << "another run's file";  // another process published first
  std::string msg;
  EXPECT_EQ(error_of([&] { w->finish(); }, msg), ExitCode::cant_create);
  std::printf("[publish] %s\n", msg.c_str());
  EXPECT_EQ(msg.find('\n'), std::string::npos);
  EXPECT_NE(msg.find(path + ": exists (created by another process during the run)"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("this run's results are in " + w->partial()), std::string::npos) << msg;
  EXPECT_EQ(text_of(path), "another run's file");
  EXPECT_FALSE(fs::exists(dir.file("run.xmf")));  // the other run's sidecar is not touched
  const ResultReader kept(w->partial());          // complete: every snapshot
  EXPECT_EQ(kept.times().size(), 4u);
  EXPECT_EQ(kept.restart_point(kept.restart_times().size() - 1).steps, 3);
}

TEST(Publish, OverwriteReplacesOnlyTheFileSeenAtTheStart) {
  erodem::test::TempDir dir("erodem_publish_");
  const std::string path = dir.file("run.h5");
  // Replaced by another process between the start and the end: refused.
  std::ofstream(path) << "old";
  {
    const auto w = written(path, true);
    std::ofstream(dir.file("other")) << "newer";
    fs::rename(dir.file("other"), path);  // a new file (inode) at the name
    std::string msg;
    EXPECT_EQ(error_of([&] { w->finish(); }, msg), ExitCode::cant_create);
    std::printf("[publish --overwrite] %s\n", msg.c_str());
    EXPECT_NE(msg.find(path +
                       ": replaced by another process during the run; not overwritten; "
                       "this run's results are in " +
                       w->partial()),
              std::string::npos)
        << msg;
    EXPECT_EQ(text_of(path), "newer");
    EXPECT_TRUE(fs::exists(w->partial()));
    fs::remove(w->partial());
  }
  // Created by another process while a run with --overwrite found nothing: refused too.
  fs::remove(path);
  {
    const auto w = written(path, true);
    std::ofstream(path) << "created";
    std::string msg;
    EXPECT_EQ(error_of([&] { w->finish(); }, msg), ExitCode::cant_create);
    EXPECT_NE(msg.find("created by another process during the run"), std::string::npos) << msg;
    EXPECT_EQ(text_of(path), "created");
    fs::remove(w->partial());
  }
  // The file seen at the start, or none left: replaced, published.
  for (const bool removed : {false, true}) {
    const auto w = written(path, true);
    if (removed) fs::remove(path);
    w->finish();
    EXPECT_EQ(ResultReader(path).times().size(), 4u);
    EXPECT_FALSE(fs::exists(w->partial()));
  }
}

TEST(Publish, LinkWayWhereRenameat2IsRefused) {
  erodem::test::TempDir dir("erodem_publish_");
  const std::string a = dir.file("a"), b = dir.file("b");
  std::ofstream(a) << "ours";
  EXPECT_EQ(erodem::io::rename_no_replace(a, b, true), 0);
  EXPECT_FALSE(fs::exists(a));
  EXPECT_EQ(text_of(b), "ours");
  EXPECT_EQ(fs::hard_link_count(b), 1u);
  std::ofstream(a) << "second";
  EXPECT_EQ(erodem::io::rename_no_replace(a, b, true), EEXIST);  // link never replaces
  EXPECT_EQ(text_of(a), "second");
  EXPECT_EQ(text_of(b), "ours");
  EXPECT_EQ(erodem::io::rename_no_replace(a, b, false), EEXIST);  // nor renameat2
  // A result file published that way.
  const std::string path = dir.file("run.h5");
  const auto w = written(path, false);
  w->close();
  w->publish(true);
  EXPECT_FALSE(fs::exists(w->partial()));
  EXPECT_EQ(ResultReader(path).times().size(), 4u);
  std::string msg;
  std::ofstream(w->partial()) << "again";
  EXPECT_EQ(error_of([&] { w->publish(true); }, msg), ExitCode::cant_create);
  EXPECT_NE(msg.find("not overwritten (give --overwrite)"), std::string::npos) << msg;
}

TEST(Publish, PartialFilesOfEndedProcessesOnThisHostAreRemoved) {
  erodem::test::TempDir dir("erodem_publish_");
  const std::string host = erodem::io::host_name();
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_GT(child, 0);
  waitpid(child, nullptr, 0);  // an ended process
  const std::string ended = dir.file(".run.h5." + host + "-" + std::to_string(child) + ".partial");
  const std::string alive =
      dir.file(".run.h5." + host + "-" + std::to_string(getppid()) + ".partial");
  const std::string elsewhere = dir.file(".run.h5.otherhost-" + std::to_string(child) + ".partial");
  const std::string other_output =
      dir.file(".b.h5." + host + "-" + std::to_string(child) + ".partial");
  for (const auto& f : {ended, alive, elsewhere, other_output}) std::ofstream(f) << "x";
  auto sim = rainy();
  const ResultWriter w(dir.file("run.h5"), sim, "", false);
  EXPECT_FALSE(fs::exists(ended));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(elsewhere));
  EXPECT_TRUE(fs::exists(other_output));
  EXPECT_TRUE(fs::exists(w.partial()));
}

TEST(Publish, ALockedFileNamesTheProcessHoldingIt) {
  erodem::test::TempDir dir("erodem_publish_");
  const std::string path = dir.file("run.h5");
  written(path, false)->finish();
  EXPECT_EQ(erodem::io::lock_holder(path), "");
  const int fd = ::open(path.c_str(), O_RDWR);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // as HDF5 holds a file it writes
  const std::string holder = erodem::io::lock_holder(path);
  std::printf("[lock] held by %s\n", holder.c_str());
  EXPECT_EQ(holder.rfind("process " + std::to_string(getpid()) + " (", 0), 0u) << holder;
  EXPECT_NE(holder.find("erodem_tests"), std::string::npos) << holder;
  const char* locking = std::getenv("HDF5_USE_FILE_LOCKING");
  if (locking == nullptr || std::string(locking) != "FALSE") {
    std::string msg;
    EXPECT_NE(error_of([&] { ResultReader r(path); }, msg), ExitCode::ok);
    std::printf("[lock] %s\n", msg.c_str());
    EXPECT_NE(msg.find(path + ": cannot open"), std::string::npos) << msg;
    EXPECT_NE(msg.find("another process has it open (HDF5 file lock, held by process " +
                       std::to_string(getpid())),
              std::string::npos)
        << msg;
  }
  ::close(fd);
  EXPECT_EQ(erodem::io::lock_holder(path), "");
}

TEST(Publish, TwoRunsToOneOutputWithoutFileLocks) {
  erodem::test::TempDir dir("erodem_publish_");
  ASSERT_EQ(
      erodem::test::run_cli("generate --kind hill --size 48 --relief 30 hill.tif", dir.path).code,
      0);
  std::ofstream(dir.file("c.toml")) << R"([dem]
path = "hill.tif"
[rain]
rate = "100 mm/h"
[time]
steps = 150
dt = 0.5
[output]
every = 10
path = "out.h5"
)";
  // Both started together; without file locks (NFS, Lustre) nothing but the publication
  // keeps them apart.
  const std::string one = "HDF5_USE_FILE_LOCKING=FALSE '" ERODEM_CLI_PATH "' run c.toml";
  const std::string cmd = "cd '" + dir.path.string() + "' && { (" + one +
                          " > a.log 2>&1; echo $? > a.rc) & (" + one +
                          " > b.log 2>&1; echo $? > b.rc) & wait; }";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const int a = std::stoi(text_of(dir.file("a.rc"))), b = std::stoi(text_of(dir.file("b.rc")));
  std::printf("[two runs] exit %d and %d\n", a, b);
  ASSERT_TRUE((a == 0 && b == 73) || (a == 73 && b == 0)) << a << " " << b;
  std::ifstream log(dir.file(a == 73 ? "a.log" : "b.log"));
  std::string line, last;
  while (std::getline(log, line))
    if (line.rfind("erodem:", 0) == 0) last = line;
  std::printf("[two runs] %s\n", last.c_str());
  EXPECT_NE(last.find("out.h5"), std::string::npos) << last;
  // One valid file; the other run's results, if it got as far, where it says.
  const ResultReader r(dir.file("out.h5"));
  EXPECT_EQ(r.times().size(), 16u);
  EXPECT_EQ(r.diagnostics().size(), 150u);
  const auto at = last.find("this run's results are in ");
  if (at != std::string::npos) {
    const std::string kept = last.substr(at + std::string("this run's results are in ").size());
    EXPECT_EQ(ResultReader((dir.path / kept).string()).times().size(), 16u) << kept;
  } else {  // it started after the first had published: refused at the start
    EXPECT_NE(last.find("exists; not overwritten"), std::string::npos) << last;
  }
}
