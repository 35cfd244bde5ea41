#include "erodem/io/paths.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "erodem/error.hpp"
#include "erodem/parallel.hpp"

namespace erodem::io {

namespace {
/// The folder an output path names a file in ("." for a bare file name).
std::filesystem::path output_folder(const std::filesystem::path& p) {
  return p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
}
}  // namespace

void check_output_path(const std::string& path, bool overwrite) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path dir = output_folder(p);
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

void check_output_folder_shared(const std::string& path) {
  namespace fs = std::filesystem;
  const int ranks = parallel::size();
  if (ranks <= 1) return;
  const fs::path dir = output_folder(path);
  // Rank 0 creates the probe (O_EXCL: a name of this host, process and moment) holding its
  // own name, and hands the name to every rank (where it could not: a NUL and the reason).
  std::string probe;
  if (parallel::rank() == 0) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::steady_clock::now().time_since_epoch())
                        .count();
    const std::string name = ".erodem-shared-folder-probe-" + host_name() + "-" +
                             std::to_string(::getpid()) + "-" + std::to_string(ns);
    probe = (dir / name).string();
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    const bool written =
        fd >= 0 && ::write(fd, probe.data(), probe.size()) == static_cast<ssize_t>(probe.size());
    if (fd >= 0) ::close(fd);
    if (!written) {
      const int error = errno;
      if (fd >= 0) ::unlink(probe.c_str());
      probe = std::string(1, '\0') + std::strerror(error);  // a reason, not a name
    }
  }
  probe = parallel::root_string(probe);
  if (!probe.empty() && probe[0] == '\0')  // on every rank alike
    throw Error(ExitCode::cant_create, path + ": cannot create output: MPI rank 0 could not " +
                                           "create a file in folder '" + dir.string() + "' (" +
                                           probe.substr(1) + ")");
  // Each rank reads it back (open, not stat: NFS's close-to-open consistency).
  std::ifstream in(probe, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const unsigned char seen = static_cast<unsigned char>(in.is_open() && text == probe);
  const std::vector<unsigned char> all = parallel::allgather(std::vector<unsigned char>{seen});
  if (parallel::rank() == 0) ::unlink(probe.c_str());
  std::string missing;
  int count = 0;
  for (int r = 0; r < ranks && r < static_cast<int>(all.size()); ++r)
    if (!all[static_cast<std::size_t>(r)]) {
      missing += (count++ ? ", " : "") + std::to_string(r);
    }
  if (count)
    throw Error(ExitCode::cant_create,
                path + ": cannot create output: folder '" + dir.string() +
                    "' is not one folder shared by every MPI rank (rank" +
                    (count > 1 ? "s " : " ") + missing + " of " + std::to_string(ranks) +
                    " cannot see a file rank 0 created there); the ranks write one result file "
                    "together, so the output must be on a file system every rank sees "
                    "(docs/mpi.md)");
}

bool FileIdentity::operator==(const FileIdentity& o) const {
  if (!exists || !o.exists) return exists == o.exists;
  return device == o.device && inode == o.inode && mtime.tv_sec == o.mtime.tv_sec &&
         mtime.tv_nsec == o.mtime.tv_nsec && size == o.size;
}

FileIdentity file_identity(const std::string& path) {
  struct stat st {};
  FileIdentity id;
  if (::stat(path.c_str(), &st) != 0) return id;
  id.exists = true;
  id.device = st.st_dev;
  id.inode = st.st_ino;
  id.mtime = st.st_mtim;
  id.size = st.st_size;
  return id;
}

int rename_no_replace(const std::string& from, const std::string& to, bool force_link) {
  if (!force_link) {
    if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return 0;
    if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP) return errno;
  }
  // The file system cannot rename without replacing: a hard link is never made over an
  // existing file either.
  if (::link(from.c_str(), to.c_str()) != 0) return errno;
  ::unlink(from.c_str());  // published; a leftover second name would be harmless
  return 0;
}

std::string lock_holder(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return "";
  std::ifstream locks("/proc/locks");
  std::string line;
  bool locked = false;
  while (std::getline(locks, line)) {
    // "1: FLOCK  ADVISORY  WRITE 1234 fe:00:5669940 0 EOF"; waiters ("1: -> FLOCK ...") skipped
    if (line.find("->") != std::string::npos) continue;
    std::istringstream in(line);
    std::string number, kind, mode, access, pid, where;
    if (!(in >> number >> kind >> mode >> access >> pid >> where)) continue;
    unsigned dev_major = 0, dev_minor = 0;
    unsigned long long inode = 0;
    if (std::sscanf(where.c_str(), "%x:%x:%llu", &dev_major, &dev_minor, &inode) != 3) continue;
    if (inode != st.st_ino || dev_major != major(st.st_dev) || dev_minor != minor(st.st_dev))
      continue;
    locked = true;
    if (pid.empty() || pid[0] == '-') continue;  // an OFD lock names no process
    std::ifstream cmd("/proc/" + pid + "/cmdline", std::ios::binary);
    std::string args((std::istreambuf_iterator<char>(cmd)), std::istreambuf_iterator<char>());
    while (!args.empty() && args.back() == '\0') args.pop_back();
    std::replace(args.begin(), args.end(), '\0', ' ');
    return "process " + pid + (args.empty() ? "" : " (" + args + ")");
  }
  return locked ? "another process" : "";
}

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0 || buf[0] == '\0') return "localhost";
  std::string name(buf);
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '_';
  return name;
}

}  // namespace erodem::io
