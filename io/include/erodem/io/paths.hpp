// erodem — checks on output paths, shared by every writer and subcommand.
#pragma once

#include <string>

namespace erodem::io {

/// Fails with ExitCode::cant_create unless `path` can be created: its folder exists and is
/// writable, and (without `overwrite`) no file of that name exists yet. Call it before any
/// long work, so nothing is spent on a run whose output cannot be written.
void check_output_path(const std::string& path, bool overwrite);

}  // namespace erodem::io
