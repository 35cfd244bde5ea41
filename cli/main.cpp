// erodem — command-line front end. Subcommands and exit codes: docs/cli.md.
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>

#include "commands.hpp"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/io/results.hpp"
#include "erodem/parallel.hpp"

namespace erodem::cli {

bool stderr_is_terminal() {
  return isatty(fileno(stderr)) != 0;
}

}  // namespace erodem::cli

int main(int argc, char** argv) {
  using namespace erodem;
  // Declared first, destroyed last: every OpenCL object is released before main returns, not
  // in static destruction after the OpenCL implementation may have torn itself down.
  const OpenClRuntimes opencl_runtimes;
  // MPI, where mpirun started this process (docs/mpi.md): initialised here, finalised when
  // main returns; in `erodem run`, which decomposes the grid (parallel::decompose), an error on
  // one rank ends them all (parallel::abort_all) with its exit code.
  struct MpiSession {
    MpiSession(int* c, char*** v) { parallel::init(c, v); }
    ~MpiSession() { parallel::finalize(); }
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
  } mpi(&argc, &argv);
  io::skip_hdf5_exit_cleanup();  // one error line, not HDF5's page (corrupt result files)
  CLI::App app{"erodem — hydrology and hydraulic erosion on real terrain"};
  app.require_subcommand(1);
  // the version, and how an MPI run writes its result (docs/mpi.md)
  app.set_version_flag("--version", std::string("erodem ") + ERODEM_VERSION +
                                        (!parallel::built_with_mpi()      ? ""
                                         : io::built_with_parallel_hdf5() ? " (MPI, parallel HDF5)"
                                                                          : " (MPI, serial HDF5)"));
  std::map<CLI::App*, cli::Action> actions;
  auto add = [&](cli::Action (*f)(CLI::App&)) {
    const auto before = app.get_subcommands({}).size();
    cli::Action a = f(app);
    actions[app.get_subcommands({})[before]] = std::move(a);
  };
  add(cli::add_run);
  add(cli::add_generate);
  add(cli::add_bench);
  add(cli::add_devices);
  add(cli::add_compare);
  add(cli::add_info);
  add(cli::add_export);
  add(cli::add_view);
  spdlog::set_default_logger(spdlog::stderr_logger_mt("erodem"));
  spdlog::set_pattern("[%H:%M:%S] %v");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // one line, as every other error: what the parser refused and where the help is
    std::string help = "erodem --help";
    for (const CLI::App* sub : app.get_subcommands())
      help = "erodem " + sub->get_name() + " --help";
    std::fprintf(stderr, "erodem: %s (see '%s')\n", e.what(), help.c_str());
    return static_cast<int>(ExitCode::usage);
  }
  try {
    for (auto& [sub, action] : actions)
      if (sub->parsed()) return action();
    return static_cast<int>(ExitCode::usage);
  } catch (const Error& e) {
    std::fprintf(stderr, "erodem: %s\n", e.what());
    parallel::abort_all(static_cast<int>(e.code()));
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "erodem: internal error: %s\n", e.what());
    parallel::abort_all(static_cast<int>(ExitCode::internal));
    return static_cast<int>(ExitCode::internal);
  }
}
