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

#include "commands.hpp"
#include "erodem/error.hpp"

namespace erodem::cli {

bool stderr_is_terminal() {
  return isatty(fileno(stderr)) != 0;
}

void check_output_path(const std::string& path, bool overwrite) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(ExitCode::cant_create,
                path + ": cannot create output: folder '" + dir.string() + "' does not exist");
  if (access(dir.c_str(), W_OK) != 0)
    throw Error(ExitCode::cant_create, path + ": cannot create output: folder '" + dir.string() +
                                           "' is not writable (" + std::strerror(errno) + ")");
  if (!overwrite && fs::exists(p, ec))
    throw Error(ExitCode::cant_create,
                path + ": exists; not overwritten (give --overwrite to replace it)");
}

}  // namespace erodem::cli

int main(int argc, char** argv) {
  using namespace erodem;
  CLI::App app{"erodem — hydrology and hydraulic erosion on real terrain"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("erodem ") + ERODEM_VERSION);
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
  spdlog::set_default_logger(spdlog::stderr_logger_mt("erodem"));
  spdlog::set_pattern("[%H:%M:%S] %v");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::usage);
  }
  try {
    for (auto& [sub, action] : actions)
      if (sub->parsed()) return action();
    return static_cast<int>(ExitCode::usage);
  } catch (const Error& e) {
    std::fprintf(stderr, "erodem: %s\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "erodem: internal error: %s\n", e.what());
    return static_cast<int>(ExitCode::internal);
  }
}
