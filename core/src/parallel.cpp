#include "erodem/parallel.hpp"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <limits>

#include "erodem/error.hpp"

#ifdef ERODEM_HAVE_MPI
#include <mpi.h>
#endif

namespace erodem::parallel {

namespace {
#ifdef ERODEM_HAVE_MPI
bool g_started = false;   // init() called MPI_Init
bool g_launched = false;  // init() found this process started by a launcher
// decompose() made this launched process one rank of a decomposed run (`erodem run`): rank()
// and size() are MPI's. Elsewhere (other commands; Python, also where mpi4py initialised MPI)
// they stay 0 and 1, and each process runs its whole grid (docs/mpi.md).
bool g_decomposed = false;

bool running() {
  int on = 0, off = 0;
  MPI_Initialized(&on);
  if (on) MPI_Finalized(&off);
  return on && !off;
}

/// MPI_Comm_rank or MPI_Comm_size of MPI_COMM_WORLD.
int world(int (*query)(MPI_Comm, int*)) {
  int v = 0;
  query(MPI_COMM_WORLD, &v);
  return v;
}

int count_of(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(INT_MAX))
    throw Error(ExitCode::internal, "MPI: a message of more than 2 GiB");
  return static_cast<int>(bytes);
}
#endif
}  // namespace

bool built_with_mpi() {
#ifdef ERODEM_HAVE_MPI
  return true;
#else
  return false;
#endif
}

int launched_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(name); v && std::atoi(v) > 0) return std::atoi(v);
  return 1;
}

void init(int* argc, char*** argv) {
#ifdef ERODEM_HAVE_MPI
  // started by a launcher: OpenMPI's mpirun, or a PMI/PMIx one (MPICH's, Slurm's srun)
  const bool launched =
      std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
  if (!launched) return;
  g_launched = true;
  if (running()) return;
  MPI_Init(argc, argv);
  g_started = true;
#else
  (void)argc;
  (void)argv;
#endif
}

void decompose() {
#ifdef ERODEM_HAVE_MPI
  g_decomposed = g_launched;
#endif
}

void finalize() {
#ifdef ERODEM_HAVE_MPI
  if (g_started && running()) MPI_Finalize();
#endif
}

void abort_all(int code) {
#ifdef ERODEM_HAVE_MPI
  if (size() > 1) MPI_Abort(MPI_COMM_WORLD, code);
#else
  (void)code;
#endif
}

#ifdef ERODEM_HAVE_MPI
int rank() {
  return g_decomposed && running() ? world(MPI_Comm_rank) : 0;
}
int size() {
  return g_decomposed && running() ? world(MPI_Comm_size) : 1;
}
#else
int rank() {
  return 0;
}
int size() {
  return 1;
}
#endif

int local_size() {
  if (launched_size() <= 1) return 1;
  for (const char* name : {"OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"})
    if (const char* v = std::getenv(name); v && std::atoi(v) > 0) return std::atoi(v);
  return 1;
}

int local_rank() {
  if (launched_size() <= 1) return 0;
  for (const char* name : {"OMPI_COMM_WORLD_LOCAL_RANK", "MPI_LOCALRANKID"})
    if (const char* v = std::getenv(name); v && std::atoi(v) >= 0 && *v) return std::atoi(v);
  return 0;
}

Band band(int ny, int r, int n) {
  const long rows = ny;
  return {static_cast<int>(rows * r / n), static_cast<int>(rows * (r + 1) / n)};
}

int owner_of_row(int ny, int row, int n) {
  int r = static_cast<int>(static_cast<long>(row) * n / ny);  // a guess within one of it
  while (r > 0 && band(ny, r, n).row0 > row) --r;
  while (r + 1 < n && band(ny, r, n).row1 <= row) ++r;
  return r;
}

std::vector<double> gather_owned(const std::vector<int>& owner, const std::vector<double>& mine) {
  const int n = size();
  if (n <= 1) return mine;
  const std::vector<double> all = allgather(mine);  // each rank's items, ranks in order
  std::vector<double> out(owner.size());
  std::size_t next = 0;
  for (int r = 0; r < n; ++r)
    for (std::size_t j = 0; j < owner.size(); ++j)
      if (owner[j] == r) out[j] = all.at(next++);
  return out;
}

std::vector<unsigned char> allgather_bytes(const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
#ifdef ERODEM_HAVE_MPI
  const int n = size();
  if (n > 1) {
    // every rank's count, then the bytes in rounds of at most INT_MAX in all (MPI's counts and
    // displacements are ints; a whole grid's bytes may be more: docs/mpi.md)
    const auto mine = static_cast<unsigned long long>(bytes);
    std::vector<unsigned long long> counts(static_cast<std::size_t>(n));
    MPI_Allgather(&mine, 1, MPI_UNSIGNED_LONG_LONG, counts.data(), 1, MPI_UNSIGNED_LONG_LONG,
                  MPI_COMM_WORLD);
    std::vector<std::size_t> offsets(static_cast<std::size_t>(n));
    std::size_t total = 0, largest = 0;
    for (std::size_t r = 0; r < counts.size(); ++r) {
      offsets[r] = total;
      total += counts[r];
      largest = std::max<std::size_t>(largest, counts[r]);
    }
    std::vector<unsigned char> out(total);
    // (ERODEM_MPI_GATHER_BYTES lowers a rank's bytes per round: tests/mpi.sh runs many rounds)
    std::size_t chunk = static_cast<std::size_t>(INT_MAX) / static_cast<std::size_t>(n);
    if (const char* v = std::getenv("ERODEM_MPI_GATHER_BYTES"); v && std::atol(v) > 0)
      chunk = std::min(chunk, static_cast<std::size_t>(std::atol(v)));
    std::vector<int> round_counts(static_cast<std::size_t>(n)), round_offsets(counts.size());
    std::vector<unsigned char> round;
    for (std::size_t done = 0; done == 0 || done < largest; done += chunk) {
      int at = 0;
      for (std::size_t r = 0; r < counts.size(); ++r) {
        round_counts[r] =
            static_cast<int>(counts[r] > done ? std::min<std::size_t>(counts[r] - done, chunk) : 0);
        round_offsets[r] = at;
        at += round_counts[r];
      }
      const int own = round_counts[static_cast<std::size_t>(rank())];
      if (largest <= chunk) {  // one round, straight into the result
        MPI_Allgatherv(p, own, MPI_BYTE, out.data(), round_counts.data(), round_offsets.data(),
                       MPI_BYTE, MPI_COMM_WORLD);
        break;
      }
      round.resize(static_cast<std::size_t>(at));
      MPI_Allgatherv(p + std::min(done, bytes), own, MPI_BYTE, round.data(), round_counts.data(),
                     round_offsets.data(), MPI_BYTE, MPI_COMM_WORLD);
      for (std::size_t r = 0; r < counts.size(); ++r)
        std::copy_n(round.begin() + round_offsets[r], round_counts[r],
                    out.begin() + static_cast<std::ptrdiff_t>(offsets[r] + done));
    }
    return out;
  }
#endif
  return std::vector<unsigned char>(p, p + bytes);
}

bool any(bool yes) {
#ifdef ERODEM_HAVE_MPI
  if (size() > 1) {
    int v = yes ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
    return v != 0;
  }
#endif
  return yes;
}

std::vector<unsigned char> any_each(std::vector<unsigned char> flags) {
#ifdef ERODEM_HAVE_MPI
  if (size() > 1) {
    constexpr std::size_t kRound = std::numeric_limits<int>::max();  // MPI's counts are ints
    for (std::size_t k = 0; k < flags.size(); k += kRound)
      MPI_Allreduce(MPI_IN_PLACE, flags.data() + k,
                    static_cast<int>(std::min(kRound, flags.size() - k)), MPI_UNSIGNED_CHAR,
                    MPI_BOR, MPI_COMM_WORLD);
  }
#endif
  return flags;
}

std::vector<double> sums_in_rank_order(std::size_t n,
                                       const std::function<void(std::vector<double>&)>& add) {
  std::vector<double> sums(n, 0.0);
#ifdef ERODEM_HAVE_MPI
  const int ranks = size(), r = rank();
  if (ranks > 1) {
    const int count = count_of(n * sizeof(double));
    if (r > 0) MPI_Recv(sums.data(), count, MPI_BYTE, r - 1, 3, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    add(sums);
    if (r + 1 < ranks) MPI_Send(sums.data(), count, MPI_BYTE, r + 1, 3, MPI_COMM_WORLD);
    MPI_Bcast(sums.data(), count, MPI_BYTE, ranks - 1, MPI_COMM_WORLD);
    return sums;
  }
#endif
  add(sums);
  return sums;
}

double max_over_ranks(double mine) {
#ifdef ERODEM_HAVE_MPI
  if (size() > 1) {
    double top = mine;
    MPI_Allreduce(&mine, &top, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return top;
  }
#endif
  return mine;
}

std::string root_string(const std::string& text) {
  const bool root = rank() == 0;
  const std::vector<unsigned char> all =
      allgather_bytes(root ? text.data() : nullptr, root ? text.size() : 0);
  return std::string(all.begin(), all.end());
}

void exchange(const void* send_up, void* recv_up, const void* send_down, void* recv_down,
              std::size_t bytes) {
#ifdef ERODEM_HAVE_MPI
  const int n = size(), r = rank();
  if (n > 1) {
    const int count = count_of(bytes);
    // Both directions at once (non-blocking): the receives posted first, then the sends, and
    // one wait for all four, so an exchange costs one message latency, not one per direction
    // (MPI_Sendrecv northwards, then southwards, before 2026-11-28). Tag 1: rows going north
    // (my first rows to the rank above, its halo below); tag 2: rows going south.
    MPI_Request requests[4];
    int k = 0;
    if (r > 0) {
      MPI_Irecv(recv_up, count, MPI_BYTE, r - 1, 2, MPI_COMM_WORLD, &requests[k++]);
      MPI_Isend(send_up, count, MPI_BYTE, r - 1, 1, MPI_COMM_WORLD, &requests[k++]);
    }
    if (r + 1 < n) {
      MPI_Irecv(recv_down, count, MPI_BYTE, r + 1, 1, MPI_COMM_WORLD, &requests[k++]);
      MPI_Isend(send_down, count, MPI_BYTE, r + 1, 2, MPI_COMM_WORLD, &requests[k++]);
    }
    MPI_Waitall(k, requests, MPI_STATUSES_IGNORE);
    return;
  }
#endif
  (void)send_up;
  (void)recv_up;
  (void)send_down;
  (void)recv_down;
  (void)bytes;
}

}  // namespace erodem::parallel
