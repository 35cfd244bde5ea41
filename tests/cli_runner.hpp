// erodem tests — running the `erodem` binary and capturing its exit code and output.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace erodem::test {

struct CliResult {
  int code = -1;
  std::string output;  // stdout and stderr together
};

/// Runs `erodem ARGS` (ERODEM_CLI_PATH) in folder `cwd` (default: the current one).
inline CliResult run_cli(const std::string& args, const std::filesystem::path& cwd = {}) {
  const std::string cd = cwd.empty() ? std::string() : "cd '" + cwd.string() + "' && ";
  const std::string cmd = cd + "'" ERODEM_CLI_PATH "' " + args + " 2>&1";
  CliResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace erodem::test
