#include "erodem/io/paths.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "erodem/error.hpp"

namespace erodem::io {

void check_output_path(const std::string& path, bool overwrite) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(ExitCode::cant_create,
                path + ": cannot create output: '" + dir.string() +
                    (fs::exists(dir, ec) ? "' is not a folder" : "' (folder) does not exist"));
  if (access(dir.c_str(), W_OK) != 0)
    throw Error(ExitCode::cant_create, path + ": cannot create output: folder '" + dir.string() +
                                           "' is not writable (" + std::strerror(errno) + ")");
  if (fs::is_directory(p, ec))
    throw Error(ExitCode::cant_create, path + ": cannot create output: it is a folder");
  if (!overwrite && fs::exists(p, ec))
    throw Error(ExitCode::cant_create,
                path + ": exists; not overwritten (give --overwrite to replace it)");
}

}  // namespace erodem::io
