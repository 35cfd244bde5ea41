// erodem — the MPI domain decomposition's communication (docs/mpi.md): which band of rows a
// rank holds, the halo exchange between neighbouring ranks, and the gathers that let every
// rank combine per-row partial results in global row order (so reductions give the bits of a
// run on one process). Built with MPI where ERODEM_MPI is on; MPI is initialised only when
// the process was started by mpirun (init), so a plain `erodem run` and `import erodem`
// never touch it. Without MPI (or outside mpirun) rank() is 0 and size() 1, and every
// function here is the identity.
#pragma once

#include <cstddef>
#include <cstring>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

namespace erodem::parallel {

/// Whether this build has MPI (ERODEM_MPI).
bool built_with_mpi();
/// The number of processes the launcher (mpirun, srun) started, from its environment
/// (OMPI_COMM_WORLD_SIZE, PMI_SIZE); 1 without one. Known with or without MPI built in.
int launched_size();
/// Initialises MPI when this process was started by mpirun (OpenMPI's or a PMI launcher's
/// environment); nothing otherwise. Only `erodem`'s main calls it.
void init(int* argc, char*** argv);
/// Makes this process, if init() found it started by a launcher, a rank of a decomposed run:
/// rank() and size() are MPI's from here on. Only `erodem run` calls it. Other commands, and
/// Python (also where mpi4py initialised MPI), run the whole grid in every process, each as
/// one process of an ensemble.
void decompose();
/// Finalises MPI where init started it.
void finalize();
/// Ends every rank with exit status `code` (MPI_Abort) in a decomposed run of more than one
/// rank (decompose()): one rank's error must not leave the others waiting in a collective.
/// Returns otherwise (each process of an ensemble ends on its own).
void abort_all(int code);
/// This process's rank and the number of ranks of the decomposed run (0 and 1 without MPI
/// running, or where init() did not make this process a rank).
int rank();
int size();
/// The processes the launcher started on this machine (its OMPI_COMM_WORLD_LOCAL_SIZE or
/// MPI_LOCALNRANKS; 1 where neither says or without a launcher), to share its cores among
/// them: the ranks of a decomposed run, or the members of an ensemble (Python under mpirun).
int local_size();
/// This process's index among them (the launcher's OMPI_COMM_WORLD_LOCAL_RANK or
/// MPI_LOCALRANKID; 0 where neither says or without a launcher), e.g. to give each its own
/// GPU.
int local_rank();

/// The DEM rows [row0, row1) rank `r` of `n` holds (bands as equal as the rows allow, in rank
/// order from the north).
struct Band {
  int row0 = 0, row1 = 0;
};
Band band(int ny, int r, int n);
/// The rank of `n` whose band holds DEM row `row` (0 <= row < ny).
int owner_of_row(int ny, int row, int n);

/// Every rank's `bytes` bytes at `data`, concatenated in rank order (each rank may give a
/// different count). Collective.
std::vector<unsigned char> allgather_bytes(const void* data, std::size_t bytes);

/// Every rank's `mine`, concatenated in rank order. Collective.
template <class T>
std::vector<T> allgather(const std::vector<T>& mine) {
  static_assert(std::is_trivially_copyable_v<T>);
  if constexpr (std::is_same_v<T, unsigned char>) {  // no second copy (a whole grid's bytes)
    return allgather_bytes(mine.data(), mine.size());
  } else {
    const std::vector<unsigned char> raw = allgather_bytes(mine.data(), mine.size() * sizeof(T));
    std::vector<T> out(raw.size() / sizeof(T));
    if (!raw.empty()) std::memcpy(out.data(), raw.data(), raw.size());
    return out;
  }
}

/// Whether `yes` holds on any rank (a decision every rank must take alike: to stop, to store
/// again). Collective (in one process: `yes`).
bool any(bool yes);

/// Each of `flags` (0 or 1) set where it is set on any rank (every rank gives as many).
/// Collective (in one process: `flags`).
std::vector<unsigned char> any_each(std::vector<unsigned char> flags);

/// Running sums carried through the ranks in rank order: rank 0 calls `add` on `n` zeros,
/// each other rank on the previous rank's result, and every rank returns the last rank's.
/// With `add` adding this rank's own rows' terms to each sum it is given, one after another,
/// each result has the bits of one process adding every term in global order (sums split into
/// per-rank partials would not). Collective; the ranks wait for each other in turn (for sums
/// made once, at setup). In one process: `add` on `n` zeros.
std::vector<double> sums_in_rank_order(std::size_t n,
                                       const std::function<void(std::vector<double>&)>& add);

/// The largest of every rank's `mine`. Collective (in one process: `mine`).
double max_over_ranks(double mine);

/// Rank 0's `text` on every rank (what each rank's own may differ in: a time, a process id).
/// Collective (in one process: `text`).
std::string root_string(const std::string& text);

/// Items each owned by one rank (`owner[j]`, of this run's ranks), with `mine` this rank's
/// values of its items in item order: every item's value in item order, from its owner.
/// Collective (in one process: `mine`).
std::vector<double> gather_owned(const std::vector<int>& owner, const std::vector<double>& mine);

/// The halo exchange of a band (non-blocking, both directions at once): sends `bytes` at
/// `send_up` to rank - 1 and at `send_down` to rank + 1, receiving into `recv_down` from
/// rank + 1 and into `recv_up` from rank - 1 (none beyond the first and last rank; null
/// buffers where there is none). Collective among neighbours.
void exchange(const void* send_up, void* recv_up, const void* send_down, void* recv_down,
              std::size_t bytes);

}  // namespace erodem::parallel
