/* erodem OpenCL — what the reductions share: the accumulator type (double where the device
 * has cl_khr_fp64: the host defines ERODEM_HAVE_FP64 then) and the work-group sum the cell
 * kernels use for the ledger's tallies. The host assembles this file first.
 *
 * The cell kernels run in work-groups of (Lx, Ly) work-items over a global size of
 * (Lx * groups_x, Ly * groups_y): each group sums its work-items' tallies in local-id order and
 * writes one partial per group to partials[slot * groups + group]; reduce_tallies (stats.cl) sums
 * the partials of each slot in a fixed order once per step, so no result depends on timing. */
#pragma OPENCL FP_CONTRACT OFF
#ifdef ERODEM_HAVE_FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double acc_t;
#else
typedef float acc_t;
#endif

/* The largest work-group of the cell kernels (the host's local size is at most this). */
#define ERODEM_CELL_GROUP_MAX 1024

/* The tally slots of the partials buffer. */
#define ERODEM_TALLY_EXCHANGE 0   /* water: net discharge out through ghost faces (m^3/s) */
#define ERODEM_TALLY_CLIPPED 1    /* water: volume added to lift rounding-level negatives */
#define ERODEM_TALLY_SEDIMENT 2   /* conservative transport: sediment carried out */
#define ERODEM_TALLY_EVAPORATED 3 /* evaporation: volume lost */
#define ERODEM_TALLY_SLOTS 4

/* Linear index of this work-group among the cell kernel's groups. */
static inline int cell_group_index(void) {
  return (int)get_group_id(0) + (int)get_group_id(1) * (int)get_num_groups(0);
}

/* Sums v over the work-group into *out, in local-id order (one work-item adds them: on CPU
 * devices the barrier costs more than the adds). Every work-item must call it; `s` holds
 * at least the local size. */
static inline void cell_group_sum(__local acc_t* s, acc_t v, __global acc_t* out) {
  const int l = (int)get_local_id(0) + (int)get_local_id(1) * (int)get_local_size(0);
  barrier(CLK_LOCAL_MEM_FENCE); /* s may still be read by an earlier call */
  s[l] = v;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (l == 0) {
    const int n = (int)(get_local_size(0) * get_local_size(1));
    acc_t a = 0;
    for (int k = 0; k < n; ++k) a += s[k];
    *out = a;
  }
}
