// erodem — checks on output paths, shared by every writer and subcommand.
#pragma once

#include <sys/types.h>

#include <ctime>
#include <string>

namespace erodem::io {

/// Fails with ExitCode::cant_create unless `path` can be created: its folder exists and is
/// writable, and (without `overwrite`) no file of that name exists yet. Call it before any
/// long work, so nothing is spent on a run whose output cannot be written.
void check_output_path(const std::string& path, bool overwrite);

/// Under MPI with more than one rank, for a file every rank opens (parallel HDF5): fails on
/// every rank with ExitCode::cant_create, naming the folder and the ranks, unless each rank
/// sees a file rank 0 creates in the folder of `path` (a file of a name no other run uses,
/// removed again). A folder on a disk of each node's own (/tmp, a node-local scratch) would
/// otherwise give each node a result file of its own. Collective; nothing in one process.
void check_output_folder_shared(const std::string& path);

/// What tells one file at a path from another that replaced it: device, inode, modification
/// time and size (stat(2)); `exists` is false when nothing is at the path.
struct FileIdentity {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  timespec mtime{};
  off_t size = 0;
  bool operator==(const FileIdentity& o) const;
  bool operator!=(const FileIdentity& o) const { return !(*this == o); }
};
FileIdentity file_identity(const std::string& path);

/// Renames `from` to `to` unless something exists at `to`, which is then left as it is:
/// renameat2(RENAME_NOREPLACE), or where the file system refuses that (EINVAL, ENOSYS: NFS)
/// link(2) then unlink(2), link failing with EEXIST as well. `force_link` takes the second
/// way (for the tests). Returns 0, or the errno of the failure: EEXIST when `to` exists.
int rename_no_replace(const std::string& from, const std::string& to, bool force_link = false);

/// Who holds a lock on the file at `path` (/proc/locks: flock, POSIX and OFD locks):
/// "process 1234 (erodem run a.toml)", "another process" when a lock is held but not by a
/// process this one can name, "" when there is no lock (or no /proc).
std::string lock_holder(const std::string& path);

/// This host's name, as it goes into temporary file names (characters other than letters,
/// digits, '.', '_' and '-' become '_').
std::string host_name();

}  // namespace erodem::io
