// erodem command line — one function per subcommand; each returns the process exit code
// or throws erodem::Error (mapped to its exit code by main).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "erodem/io/paths.hpp"

namespace erodem::cli {

/// Registers a subcommand on `app` and returns the action to run when it is chosen.
using Action = std::function<int()>;
Action add_run(CLI::App& app);
Action add_generate(CLI::App& app);
Action add_bench(CLI::App& app);
Action add_devices(CLI::App& app);
Action add_compare(CLI::App& app);
Action add_info(CLI::App& app);
Action add_export(CLI::App& app);
Action add_view(CLI::App& app);

/// Whether `path` starts with the HDF5 signature (a result file, not a DEM).
bool is_hdf5_file(const std::string& path);
/// `erodem info` of a result file (info_result.cpp): text, or JSON with `json`.
int info_result(const std::string& path, bool json);

/// Whether stderr is a terminal (progress bar) or a log (periodic lines).
bool stderr_is_terminal();

/// Output paths are checked by io::check_output_path (erodem/io/paths.hpp).
using io::check_output_path;

}  // namespace erodem::cli
