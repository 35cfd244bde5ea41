// erodem — error type carrying a documented process exit code.
#pragma once

#include <stdexcept>
#include <string>

namespace erodem {

/// Exit codes of the `erodem` command line (see docs/cli.md and INTERFACES.md).
enum class ExitCode : int {
  ok = 0,
  check_failed = 1,  ///< a comparison or check failed
  usage = 2,         ///< bad command-line usage
  data = 65,         ///< bad input data (EX_DATAERR)
  no_input = 66,     ///< input file missing (EX_NOINPUT)
  internal = 70,     ///< internal error (EX_SOFTWARE)
  cant_create = 73,  ///< cannot create output (EX_CANTCREAT)
  io = 74,           ///< I/O error (EX_IOERR)
  unstable = 75,     ///< simulation went unstable: NaN, negative depth, CFL violated
  config = 78,       ///< bad configuration (EX_CONFIG)
};

/// An error that the command line reports as one line and maps to an exit code.
class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const noexcept { return code_; }

 private:
  ExitCode code_;
};

/// A configuration error naming the parameter (`key`) and what was expected.
inline Error config_error(const std::string& key, const std::string& what) {
  return Error(ExitCode::config, "config: '" + key + "': " + what);
}

}  // namespace erodem
