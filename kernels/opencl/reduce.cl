/* erodem OpenCL — what the reductions share: the accumulator type (double where the device
 * has cl_khr_fp64: the host defines ERODEM_HAVE_FP64 then) and the work-group sum the cell
 * kernels use for the ledger's tallies. The host assembles this file first.
 *
 * The tally kernels (water, evaporation: rows 1 .. H - 2 of the raster; edge_tallies: a list
 * of cells) run in work-groups; each group sums its work-items' tallies in a fixed order and
 * writes one partial per group to partials[slot * stride + group], where stride is at least
 * every kernel's group count and the partials no kernel writes stay 0; reduce_tallies
 * (stats.cl) sums the partials of each slot in a fixed order once per step, so no result
 * depends on timing.
 *
 * The kernels' pointer parameters are `restrict`: the host never binds one buffer to two
 * restrict parameters of a kernel (a field a kernel writes while it reads the neighbours is
 * double buffered; the in-place updates touch only their own cell; the pipes, which read their
 * old outflows and write the new ones in place, take both as plain pointers). Without it LLVM
 * reloads the per-row values in every iteration of PoCL's work-item loop, since a store might have
 * changed them (local-inertial face pass at 4096^2: 61 -> 53 ms). Evaporation keeps plain
 * pointers: there `restrict` made PoCL's code slower (6.3 -> 8.4 ms). */
#pragma OPENCL FP_CONTRACT OFF
#ifdef ERODEM_HAVE_FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double acc_t;
typedef double2 acc2_t;
typedef double4 acc4_t;
typedef double8 acc8_t;
typedef long8 acc8_mask_t; /* what comparing two acc8_t gives */
#define convert_acc8 convert_double8
#define convert_acc8_mask convert_long8
#else
typedef float acc_t;
typedef float2 acc2_t;
typedef float4 acc4_t;
typedef float8 acc8_t;
typedef int8 acc8_mask_t;
#define convert_acc8 convert_float8
#define convert_acc8_mask convert_int8
#endif

/* Whether work-item column x lies past the padded row of W cells. Where the host launches
 * whole rows (ERODEM_WHOLE_ROWS, on CPU devices: groups of the local size from column 0, then
 * where that does not divide W a group of the row's last columns, launch_rows) there is no such
 * work-item, and a cell kernel has no per-work-item condition left: every load is
 * unconditional, which PoCL needs to vectorise a kernel with loads of per-row values (under a
 * per-work-item condition it gathers them). Elsewhere the global size is rounded up to whole
 * work-groups and those work-items stop here. */
#ifdef ERODEM_WHOLE_ROWS
#define ERODEM_PAST_ROW(x, W) 0
#else
#define ERODEM_PAST_ROW(x, W) ((x) >= (W))
#endif

/* The opening of a generic kernel without tallies (the arguments every generic kernel takes,
 * process.hpp SweepInfo::generic): its work-item's padded cell (x, y), and a return for a
 * work-item past the row. */
#define ERODEM_UNTALLIED_CELL(x, y)                               \
  const int x = (int)get_global_id(0), y = (int)get_global_id(1); \
  (void)H;                                                        \
  (void)partials;                                                 \
  (void)stride;                                                   \
  if (ERODEM_PAST_ROW(x, W)) return

/* The largest work-group of the cell kernels (the host's local size is at most this, and
 * their local arrays hold this many values): a whole-row divisor on CPU devices; in the rounded
 * launches (GPUs: 128 unless ERODEM_OPENCL_WG says otherwise; 256 and 512 were no faster on an
 * H200) 256, so a kernel's local arrays take a quarter of the memory (the snow kernels' four
 * tally arrays and their lanes: 4.1 KiB instead of 16.1; Oclgrind, counting the two snow
 * kernels together, refused 33 KiB against its 32). */
#ifdef ERODEM_WHOLE_ROWS
#define ERODEM_CELL_GROUP_MAX 1024
#else
#define ERODEM_CELL_GROUP_MAX 256
#endif

/* The tally slots of the partials buffer: ERODEM_TALLY_<NAME> for each tally of ERODEM_TALLIES
 * (core/include/erodem/ledger.hpp), its index there, and ERODEM_TALLY_SLOTS, their number, are
 * defined by the build options (kernels/opencl/runtime.cpp). */
#ifndef ERODEM_TALLY_SLOTS
#error "the host defines the tally slots (ERODEM_TALLY_*) in the build options"
#endif

/* Whether this launch is the tail of whole rows: launch_rows launches a row's last columns on
 * their own at an x offset, every other launch at column 0. */
static inline int row_tail_launch(void) {
  return get_global_offset(0) > 0;
}

/* The partial of this work-group in a tally slot of `stride` partials: its linear index among
 * the launch's groups; for the tail of whole rows (the row's last columns, launched on their
 * own at an x offset: launch_rows) the slot's top, stride - 1 - its row in the launch. The
 * host's stride counts a group per row for the tail (groups_x_), so the two never meet; and
 * a band's own rows, launched last with at least as many rows as a halo launch, write over
 * every partial of the halo rows (launch_interior). */
static inline int cell_group_index(int stride) {
#ifdef ERODEM_WHOLE_ROWS
  if (row_tail_launch()) return stride - 1 - (int)get_group_id(1);
#endif
  return (int)get_group_id(0) + (int)get_group_id(1) * (int)get_num_groups(0);
}

/* A function that the compiler must not inline: the work a group does once, after a barrier,
 * under `if (get_local_id(0) == 0)`. PoCL runs the code after a barrier in a loop over the
 * group's work-items; with a call there, LLVM peels the first iteration and drops the loop,
 * but with the work inlined (it holds loops of its own) the loop stays and tests every local
 * id: 683 iterations per group, about 12 % of the water kernel at 4096^2 and a third of
 * evaporation (8.3 -> 5.4 ms). Only where the compiler is clang (PoCL, most others); a
 * compiler without the attribute inlines as it likes. The functions are not `static`: with
 * `static` PoCL 3.1 computed wrong statistics (every AgreementStats case failed). */
#if defined(__clang__)
#define ERODEM_GROUP_ONCE __attribute__((noinline))
#else
#define ERODEM_GROUP_ONCE
#endif

/* The eight lanes of a running sum added pairwise: ((0 + 1) + (2 + 3)) + ((4 + 5) + (6 + 7)). */
static inline acc_t acc8_total(acc8_t a) {
  return ((a.s0 + a.s1) + (a.s2 + a.s3)) + ((a.s4 + a.s5) + (a.s6 + a.s7));
}

/* The sum in acc_t of the n per-cell tallies s[0 .. n) (n the local size): eight running
 * sums, lane j over the indices j mod 8 below the last multiple of 8, as one 8-vector, added
 * pairwise (acc8_total), then the rest in order; a fixed order. (One running sum makes every
 * add wait for the one before: on CPU devices that chain, not the memory traffic, would set
 * the speed of the tally kernels.) */
ERODEM_GROUP_ONCE acc_t cell_tallies_sum(__local const real* s, int n) {
  const int blocks = n / 8;
  acc_t sum = 0;
  if (blocks > 0) {
    acc8_t a = convert_acc8(vload8(0, s));
    for (int k = 1; k < blocks; ++k) a += convert_acc8(vload8(k, s));
    sum = acc8_total(a);
  }
  for (int k = 8 * blocks; k < n; ++k) sum += (acc_t)s[k];
  return sum;
}

/* Lane j (< 8) of cell_tallies_sum over s[0 .. 8 blocks): s[j] + s[j + 8] + ... in order. */
static inline acc_t cell_tallies_lane(__local const real* s, int blocks, int j) {
  acc_t a = (acc_t)s[j];
  for (int k = 1; k < blocks; ++k) a += (acc_t)s[8 * k + j];
  return a;
}

/* cell_tallies_sum from its eight lanes (lanes[0 .. 8), cell_tallies_lane) and the rest of s
 * after the last multiple of 8: the same adds in the same order, so the same bits. */
static inline acc_t cell_tallies_total(__local const acc_t* lanes, __local const real* s, int n) {
  const int blocks = n / 8;
  acc_t sum = 0;
  if (blocks > 0)
    sum = ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) +
          ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
  for (int k = 8 * blocks; k < n; ++k) sum += (acc_t)s[k];
  return sum;
}

/* The tally sums of a work-group. Every work-item must call them, once per kernel (erosion's
 * second kernel twice, the calls one after another), with `s`, `s_a`, `s_b` holding at least
 * the local size and `lanes` ERODEM_TALLY_LANES values (__local acc_t, one array per kernel).
 * The per-cell tallies are stored as `real` (they are real numbers; the sum widens them
 * exactly): PoCL vectorises a kernel whose local stores are float and not one whose stores are
 * double. Both ways add in the fixed order of cell_tallies_sum, so both give the same bits:
 *  - whole rows (CPU devices): one work-item adds them all (more barriers would cost more
 *    than the adds); `lanes` is not used;
 *  - rounded launches (GPUs): the eight lanes in eight work-items side by side (sixteen for
 *    two sums), then one work-item adds the lanes. The one work-item's walk left the group's
 *    others waiting: on an H200 the tally kernels ran at 31-36 % of the copy bandwidth, the
 *    kernels without tallies at up to 54 % (2026-11-27). */
#define ERODEM_TALLY_LANES 16

static inline void cell_group_sum(__local real* s, __local acc_t* lanes, real v,
                                  __global acc_t* out) {
  const int l = (int)get_local_id(0) + (int)get_local_id(1) * (int)get_local_size(0);
  s[l] = v;
  barrier(CLK_LOCAL_MEM_FENCE);
#ifdef ERODEM_WHOLE_ROWS
  (void)lanes;
  /* the ids again, not l: on PoCL a value computed before a barrier and used after it is
   * kept per work-item (see field_stats in stats.cl) */
  if (get_local_id(0) == 0 && get_local_id(1) == 0)
    *out = cell_tallies_sum(s, (int)(get_local_size(0) * get_local_size(1)));
#else
  const int n = (int)(get_local_size(0) * get_local_size(1));
  if (l < 8 && n >= 8) lanes[l] = cell_tallies_lane(s, n / 8, l);
  barrier(CLK_LOCAL_MEM_FENCE);
  if (l == 0) *out = cell_tallies_total(lanes, s, n);
#endif
}

/* Two sums at once, a into *out_a and b into *out_b, each as cell_group_sum; instead of two
 * cell_group_sum (one barrier for both). Two arrays rather than two halves of one: PoCL did
 * not vectorise the erosion kernel with stores at an offset of the local size (AMD EPYC
 * without AVX-512, PoCL 3.1). */
static inline void cell_group_sum2(__local real* s_a, __local real* s_b, __local acc_t* lanes,
                                   real a, real b, __global acc_t* out_a, __global acc_t* out_b) {
  const int l = (int)get_local_id(0) + (int)get_local_id(1) * (int)get_local_size(0);
  s_a[l] = a;
  s_b[l] = b;
  barrier(CLK_LOCAL_MEM_FENCE);
#ifdef ERODEM_WHOLE_ROWS
  (void)lanes;
  if (get_local_id(0) == 0 && get_local_id(1) == 0) {
    const int n = (int)(get_local_size(0) * get_local_size(1));
    *out_a = cell_tallies_sum(s_a, n);
    *out_b = cell_tallies_sum(s_b, n);
  }
#else
  const int n = (int)(get_local_size(0) * get_local_size(1));
  if (l < 16 && n >= 16) lanes[l] = cell_tallies_lane(l < 8 ? s_a : s_b, n / 8, l % 8);
  barrier(CLK_LOCAL_MEM_FENCE);
  if (l == 0) {
    if (n >= 16) {
      *out_a = cell_tallies_total(lanes, s_a, n);
      *out_b = cell_tallies_total(lanes + 8, s_b, n);
    } else { /* groups of fewer than 16 work-items: one work-item adds both */
      *out_a = cell_tallies_sum(s_a, n);
      *out_b = cell_tallies_sum(s_b, n);
    }
  }
#endif
}
