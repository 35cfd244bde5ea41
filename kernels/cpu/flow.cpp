// CPU loop of the flow process: kernels/common/flow.h over every padded cell (ghosts give
// water too), then the new fluxes become the current ones.
//
// Local inertial: each thread takes a block of rows and walks it top to bottom, keeping the
// few rows of faces it needs in small row buffers: per cell row y it computes the unit
// discharges of the faces south of row y + 1, the discharges of the faces south of row y and
// east of every cell of row y, and splits them into row y's outflows. Every face is
// computed once per thread (the faces between two blocks twice), and every inner loop runs
// over x with values, not calls through pointers, so GCC vectorises it.
//
// Local inertial and pipes write the new outflows over the old ones (no second buffers: 16 B
// per cell). A pipe cell reads only its own old outflows. A local-inertial row y reads its own
// (the faces east of its cells) and, through the unit discharges of the faces south of rows
// j, rows j and j + 1: a thread takes those of row y + 1 before it writes row y, and those it
// needs of rows its neighbouring blocks write (the first three and the last two of its block)
// before any thread writes (a barrier), so every face reads the old outflows, as before.
//
// Shallow water (common/shallow_water.h): the same walk (shallow_water_rows): per row the
// velocities (and for the second order the slopes) of the rows it needs next, the faces south
// of the row and those of the row, each once, then the row's cells from their four faces; the
// second order runs it twice a step (Heun), with the depth after the first stage in between.
#include "common/flow.h"

#include <algorithm>
#include <array>
#include <type_traits>
#include <utility>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "common/shallow_water.h"
#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

namespace {

/// The scalar parameters of the local-inertial faces.
template <class Real>
struct InertialParams {
  Real dt, gravity, theta, dry_depth;
  bool periodic_x = false;  // boundary.periodic_x: the faces across the seam (face_x_row)
  int manning_pitch = 0;    // values per row of the Manning n array (param_index, compat.h)
};

/// The kinds a row loop reads at column x: a row of ints (RowKinds<false>), or the constant
/// ERODEM_CELL_ACTIVE (RowKinds<true>) for a run of columns whose cells the loop knows to be
/// active (CpuBackend::rows_active). The same values, so the same bits; with the constant the
/// compiler drops the kinds' loads and the masks they feed (performance.md "Rows of active
/// cells").
template <bool kActive>
struct RowKinds;
template <>
struct RowKinds<false> {
  const int* __restrict k;
  int operator[](int x) const { return k[x]; }
};
template <>
struct RowKinds<true> {
  explicit RowKinds(const int*) {}  // the row it stands for, unread
  int operator[](int) const { return ERODEM_CELL_ACTIVE; }
};

/// Runs loop(constant, x0, x1) over the columns lo .. hi - 1 of a row in at most three runs:
/// with `constant` std::true_type over a0 .. a1 - 1 (clamped to lo .. hi), whose cells read only
/// kinds that are ERODEM_CELL_ACTIVE when `active` (so the loop may take them as constants:
/// RowKinds<true>), and std::false_type (the kinds read) over the rest, or over all of it when
/// not `active`. Each loop's caller says which columns and rows make it `active`.
template <class Loop>
void runs_of_active_kinds(bool active, int lo, int a0, int a1, int hi, const Loop& loop) {
  if (!active) {
    loop(std::false_type{}, lo, hi);
    return;
  }
  a0 = std::clamp(a0, lo, hi);
  a1 = std::clamp(a1, a0, hi);
  loop(std::false_type{}, lo, a0);
  loop(std::true_type{}, a0, a1);
  loop(std::false_type{}, a1, hi);
}

/// Unit discharges (m^2/s) of the faces south of padded row j (0 <= j <= H - 2), all x.
template <class Real>
void unit_discharge_y_row(int j, int W, const Real* __restrict f_top,
                          const Real* __restrict f_bottom, const Real* __restrict dx,
                          Real* __restrict q) {
  const Real width = cell::face_y_width(dx, j);
  const Real* __restrict fb = f_bottom + static_cast<std::ptrdiff_t>(j) * W;
  const Real* __restrict ft = f_top + static_cast<std::ptrdiff_t>(j + 1) * W;
  for (int x = 0; x < W; ++x) q[x] = cell::face_unit_discharge(fb[x], ft[x], width);
}

/// Discharges (m^3/s) of the faces south of padded row j (0 <= j <= H - 2), columns x0 .. x1 - 1,
/// from the unit discharges of the faces south of rows j - 1, j and j + 1 (q_up, q, q_down; q_up
/// or q_down unused where that row of faces does not exist); the kinds of rows j - 1 .. j + 2
/// (RowKinds).
template <class Kinds, class Real>
void face_y_row(int j, int W, int H, int x0, int x1, Kinds k_up, Kinds k_a, Kinds k_b, Kinds k_down,
                const Real* __restrict bed, const Real* __restrict depth,
                const Real* __restrict manning, const Real* __restrict dx,
                const Real* __restrict dy, const Real* __restrict q_up, const Real* __restrict q,
                const Real* __restrict q_down, const InertialParams<Real>& p,
                Real* __restrict out) {
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(j) * W;
  const int has_up = j >= 1, has_down = j + 2 <= H - 1;
  // Beyond the raster: walls (k_up, k_down are rows of walls there) and q stands in.
  const Real* __restrict qu = has_up ? q_up : q;
  const Real* __restrict qd = has_down ? q_down : q;
  const Real* __restrict b_a = bed + row, * __restrict b_b = bed + row + W;
  const Real* __restrict d_a = depth + row, * __restrict d_b = depth + row + W;
  const std::ptrdiff_t n_row = static_cast<std::ptrdiff_t>(j) * p.manning_pitch;
  const Real* __restrict n_a = manning + n_row, * __restrict n_b =
                                                    manning + n_row + p.manning_pitch;
  const Real width = cell::face_y_width(dx, j), dist = cell::centre_distance_y(dy, j);
  const Real dt = p.dt, g = p.gravity, theta = p.theta, dry = p.dry_depth;
  ERODEM_IVDEP
  for (int x = x0; x < x1; ++x)
    out[x] =
        cell::local_inertial_face(cell::face_open(k_a[x], k_b[x]), k_up[x] != ERODEM_CELL_WALL,
                                  k_down[x] != ERODEM_CELL_WALL, q[x], qu[x], qd[x], d_a[x], d_b[x],
                                  b_a[x], b_b[x], n_a[x], n_b[x], width, dist, dt, g, theta, dry);
}

/// Discharges (m^3/s) of the faces east of the cells x = 0 .. W - 2 of padded row y; `q` is
/// scratch for their unit discharges. out[W - 1] = 0 (no face).
template <class Real>
void face_x_row(int y, int W, const int* __restrict k, bool active, const Real* __restrict bed,
                const Real* __restrict depth, const Real* __restrict manning,
                const Real* __restrict dx, const Real* __restrict dy, const Real* __restrict f_left,
                const Real* __restrict f_right, const InertialParams<Real>& p, Real* __restrict q,
                Real* __restrict out) {
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
  const Real* __restrict fl = f_left + row, * __restrict fr = f_right + row;
  const Real* __restrict b = bed + row, * __restrict d = depth + row;
  const Real* __restrict n = manning + static_cast<std::ptrdiff_t>(y) * p.manning_pitch;
  const Real width = dy[y], dist = dx[y];
  const Real dt = p.dt, g = p.gravity, theta = p.theta, dry = p.dry_depth;
  for (int x = 0; x < W - 1; ++x) q[x] = cell::face_unit_discharge(fr[x], fl[x + 1], width);
  // Face x lies between cells x and x + 1; its up/down neighbours are faces x - 1, x + 1,
  // used when cells x - 1 and x + 2 are no walls (outside the row: walls).
  auto face = [&](int x, int up_open, int down_open, Real q_up, Real q_down) {
    return cell::local_inertial_face(cell::face_open(k[x], k[x + 1]), up_open, down_open, q[x],
                                     q_up, q_down, d[x], d[x + 1], b[x], b[x + 1], n[x], n[x + 1],
                                     width, dist, dt, g, theta, dry);
  };
  // W >= 3: the padded raster has at least one DEM column.
  out[0] = face(0, 0, k[2] != ERODEM_CELL_WALL, q[0], q[1]);
  // the faces between cells 1 .. W - 2; where those cells are active, faces 2 .. W - 4 read the
  // kinds of active cells only
  runs_of_active_kinds(active, 1, 2, W - 3, W - 2, [&](auto constant, int x0, int x1) {
    const RowKinds<decltype(constant)::value> kinds{k};
    ERODEM_IVDEP
    for (int x = x0; x < x1; ++x)
      out[x] = cell::local_inertial_face(
          cell::face_open(kinds[x], kinds[x + 1]), kinds[x - 1] != ERODEM_CELL_WALL,
          kinds[x + 2] != ERODEM_CELL_WALL, q[x], q[x - 1], q[x + 1], d[x], d[x + 1], b[x],
          b[x + 1], n[x], n[x + 1], width, dist, dt, g, theta, dry);
  });
  out[W - 2] = face(W - 2, k[W - 3] != ERODEM_CELL_WALL, 0, q[W - 3], q[W - 2]);
  out[W - 1] = Real(0);
  if (p.periodic_x) {
    // The seam: the face east of the last DEM column is the face west of the first (ghost
    // columns 0 and W - 1 repeat columns W - 2 and 1), computed once with its true neighbours
    // on both sides, the face before it (q[W - 3]) and the face after it, between columns 1
    // and 2 (q[1]), so both cells beside it see the same discharge.
    out[W - 2] =
        face(W - 2, k[W - 3] != ERODEM_CELL_WALL, k[2] != ERODEM_CELL_WALL, q[W - 3], q[1]);
    out[0] = out[W - 2];
  }
}

/// Splits the faces around the cells of padded row y into their outflows (m^3/s). face_x:
/// the row's east faces; face_top, face_bottom: the faces north and south of the row (all
/// 0 where the row of faces does not exist); k_top, k_bottom: the kinds of the rows above
/// and below (walls beyond the raster).
template <class Real>
void split_row(int y, int W, const int* __restrict k, const int* __restrict k_top,
               const int* __restrict k_bottom, bool active, const Real* __restrict depth,
               const Real* __restrict area, const Real* __restrict face_x,
               const Real* __restrict face_top, const Real* __restrict face_bottom, Real dt,
               Real* __restrict out_left, Real* __restrict out_right, Real* __restrict out_top,
               Real* __restrict out_bottom) {
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
  const Real* __restrict d = depth + row;
  Real* __restrict ol = out_left + row, * __restrict orr = out_right + row, * __restrict ot = out_top + row, * __restrict ob = out_bottom + row;
  const Real a = area[y];
  auto cell_at = [&](int x, int k_left, int k_right, Real q_left, Real q_right) {
    cell::local_inertial_split<Real>(k[x], k_left, k_right, k_top[x], k_bottom[x], q_left, q_right,
                                     face_top[x], face_bottom[x], d[x], a, dt, ol + x, orr + x,
                                     ot + x, ob + x);
  };
  cell_at(0, ERODEM_CELL_WALL, k[1], Real(0), face_x[0]);
  // cells 1 .. W - 2, the kinds of the row and the rows above and below; where the cells
  // 1 .. W - 2 of all three rows are active, cells 2 .. W - 3 read those of active cells only
  runs_of_active_kinds(active, 1, 2, W - 2, W - 1, [&](auto constant, int x0, int x1) {
    using Kinds = RowKinds<decltype(constant)::value>;
    const Kinds kinds{k}, kinds_top{k_top}, kinds_bottom{k_bottom};
    ERODEM_IVDEP
    for (int x = x0; x < x1; ++x) {
      Real l, r, t, bt;
      cell::local_inertial_split<Real>(kinds[x], kinds[x - 1], kinds[x + 1], kinds_top[x],
                                       kinds_bottom[x], face_x[x - 1], face_x[x], face_top[x],
                                       face_bottom[x], d[x], a, dt, &l, &r, &t, &bt);
      ol[x] = l;
      orr[x] = r;
      ot[x] = t;
      ob[x] = bt;
    }
  });
  cell_at(W - 1, k[W - 2], ERODEM_CELL_WALL, face_x[W - 2], Real(0));
}

/// One row of shallow-water faces (cell::SwFace), member by member, so the loops that fill
/// and read it vectorise.
template <class Real>
struct SwFaceRow {
  std::vector<Real> mass, mom_a, mom_b, mom_t, h_a, h_b, z, mom_low, z_mean;
  std::vector<int> step;
  explicit SwFaceRow(std::size_t n)
      : mass(n),
        mom_a(n),
        mom_b(n),
        mom_t(n),
        h_a(n),
        h_b(n),
        z(n),
        mom_low(n),
        z_mean(n),
        step(n) {}
};

/// Pointers into a SwFaceRow (restrict: the loops store through them).
template <class Real>
struct SwFaceRef {
  Real* __restrict mass, * __restrict mom_a, * __restrict mom_b, * __restrict mom_t, * __restrict h_a, * __restrict h_b, * __restrict z, * __restrict mom_low, * __restrict z_mean;
  int* __restrict step;
  explicit SwFaceRef(SwFaceRow<Real>& r)
      : mass(r.mass.data()),
        mom_a(r.mom_a.data()),
        mom_b(r.mom_b.data()),
        mom_t(r.mom_t.data()),
        h_a(r.h_a.data()),
        h_b(r.h_b.data()),
        z(r.z.data()),
        mom_low(r.mom_low.data()),
        z_mean(r.z_mean.data()),
        step(r.step.data()) {}
  void store(int x, const cell::SwFace<Real>& f) const {
    mass[x] = f.mass;
    mom_a[x] = f.mom_a;
    mom_b[x] = f.mom_b;
    mom_t[x] = f.mom_t;
    h_a[x] = f.h_a;
    h_b[x] = f.h_b;
    z[x] = f.z;
    mom_low[x] = f.mom_low;
    z_mean[x] = f.z_mean;
    step[x] = f.step;
  }
  cell::SwFace<Real> load(int x) const {
    cell::SwFace<Real> f;
    f.mass = mass[x];
    f.mom_a = mom_a[x];
    f.mom_b = mom_b[x];
    f.mom_t = mom_t[x];
    f.h_a = h_a[x];
    f.h_b = h_b[x];
    f.z = z[x];
    f.mom_low = mom_low[x];
    f.z_mean = z_mean[x];
    f.step = step[x];
    return f;
  }
};

/// Slopes of one row in one direction (cell::SwSlopes), member by member.
template <class Real>
struct SwSlopeRow {
  std::vector<Real> eta, h, u, t;
  std::vector<int> on;
  explicit SwSlopeRow(std::size_t n) : eta(n), h(n), u(n), t(n), on(n) {}
};

/// Pointers into a SwSlopeRow (restrict: the loops store through them).
template <class Real>
struct SwSlopeRef {
  Real* __restrict eta = nullptr, * __restrict h = nullptr, * __restrict u = nullptr, * __restrict t = nullptr;
  int* __restrict on = nullptr;
  SwSlopeRef() = default;
  explicit SwSlopeRef(SwSlopeRow<Real>& r)
      : eta(r.eta.data()), h(r.h.data()), u(r.u.data()), t(r.t.data()), on(r.on.data()) {}
  void store(int x, const cell::SwSlopes<Real>& s) const {
    eta[x] = s.eta;
    h[x] = s.h;
    u[x] = s.u;
    t[x] = s.t;
    on[x] = s.on;
  }
  cell::SwSlopes<Real> load(int x) const {
    cell::SwSlopes<Real> s;
    s.eta = eta[x];
    s.h = h[x];
    s.u = u[x];
    s.t = t[x];
    s.on = on[x];
    return s;
  }
};

/// A padded row as the shallow-water faces read it: kinds (as int; walls for the rows beyond
/// the raster, which stand on the nearest row's state, as shallow_water_cell clamps), depth,
/// bed and velocities (cell::sw_velocity); for the second order its slopes along x and y (none
/// for the rows beyond the raster).
template <class Real>
struct SwRow {
  const int* kind;
  const Real *depth, *bed, *u, *v;
  SwSlopeRef<Real> slope_x, slope_y;
  cell::SwCellState<Real> state(int x) const {
    cell::SwCellState<Real> c;
    c.h = depth[x];
    c.z = bed[x];
    c.u = u[x];
    c.v = v[x];
    c.k = kind[x];
    return c;
  }
};

/// The faces south of row `a` (north of row `b`), all x, into `out`; second order (Muscl) from
/// the rows' y-slopes.
template <bool Muscl, class Real>
void sw_faces_y(int W, const SwRow<Real>& a, const SwRow<Real>& b, Real g, Real eps,
                const SwFaceRef<Real>& out) {
  if constexpr (Muscl) {
    ERODEM_IVDEP
    for (int x = 0; x < W; ++x)
      out.store(x, cell::sw_face_y2(a.state(x), a.slope_y.load(x), b.state(x), b.slope_y.load(x), g,
                                    eps));
  } else {
    const int* __restrict ka = a.kind, * __restrict kb = b.kind;
    const Real* __restrict ha = a.depth, * __restrict za = a.bed, * __restrict ua = a.u, * __restrict va = a.v;
    const Real* __restrict hb = b.depth, * __restrict zb = b.bed, * __restrict ub = b.u, * __restrict vb = b.v;
    ERODEM_IVDEP
    for (int x = 0; x < W; ++x)
      out.store(x, cell::sw_face(ka[x], kb[x], ha[x], za[x], -va[x], ua[x], hb[x], zb[x], -vb[x],
                                 ub[x], g, eps));
  }
}

/// The faces of row r: face x (0 <= x <= W) west of cell x, faces 0 and W against the cell
/// itself as a wall (as shallow_water_cell clamps), into `out`; second order from the row's
/// x-slopes (none at the two walls: those faces are the first order's).
template <bool Muscl, class Real>
void sw_faces_x(int W, const SwRow<Real>& r, Real g, Real eps, const SwFaceRef<Real>& out) {
  const int* __restrict k = r.kind;
  const Real* __restrict h = r.depth, * __restrict z = r.bed, * __restrict u = r.u, * __restrict v = r.v;
  out.store(0, cell::sw_face(ERODEM_CELL_WALL, k[0], h[0], z[0], u[0], v[0], h[0], z[0], u[0], v[0],
                             g, eps));
  if constexpr (Muscl) {
    ERODEM_IVDEP
    for (int x = 1; x < W; ++x)
      out.store(x, cell::sw_face_x2(r.state(x - 1), r.slope_x.load(x - 1), r.state(x),
                                    r.slope_x.load(x), g, eps));
  } else {
    ERODEM_IVDEP
    for (int x = 1; x < W; ++x)
      out.store(x, cell::sw_face(k[x - 1], k[x], h[x - 1], z[x - 1], u[x - 1], v[x - 1], h[x], z[x],
                                 u[x], v[x], g, eps));
  }
  out.store(W, cell::sw_face(k[W - 1], ERODEM_CELL_WALL, h[W - 1], z[W - 1], u[W - 1], v[W - 1],
                             h[W - 1], z[W - 1], u[W - 1], v[W - 1], g, eps));
}

/// What a stage of the shallow-water step reads and writes (cell::shallow_water_muscl_cell's
/// arguments): the stage's depth and unit discharges, the outflows and unit discharges it
/// writes (whether it averages them with what those arrays hold, Heun's second stage, is
/// shallow_water_rows' Combine).
template <class Real>
struct SwStage {
  int W, H;
  const cell::erodem_kind_t* kind;
  const Real *bed, *depth, *q_x, *q_y, *manning, *dx, *dy, *area;
  Real dt;
  cell_params::FlowParams<Real> params;
  Real *out_left, *out_right, *out_top, *out_bottom, *q_x_new, *q_y_new;
};

/// One stage over the padded rows [y0, y1) (a thread's block), walked top to bottom: per row y
/// the state of the rows it needs next (velocities, slopes), the faces south of row y and those
/// of row y, then row y's cells from their four faces (cell::shallow_water_cell_update), each
/// face computed once (the faces between two blocks twice) with the arguments the OpenCL cell
/// gives it (cell::shallow_water_cell, shallow_water_muscl_cell), so the two agree bit for bit.
/// Combine: the second stage of Heun's method (cell::shallow_water_stage_store), a constant so
/// the other stages do not read the arrays they write.
template <bool Muscl, bool Combine, class Real>
void shallow_water_rows(const SwStage<Real>& st, int y0, int y1) {
  const int W = st.W, H = st.H;
  const Real g = st.params.gravity, eps = st.params.dry_depth;
  const std::size_t w = static_cast<std::size_t>(W);
  constexpr int kSlots = 5;  // rows y - 2 .. y + 2 at most
  // rings: kinds, velocities and slopes of rows j (slot j mod 5), faces south of rows j (slot
  // j mod 2); walls for the kinds of the rows beyond the raster, and no slopes
  std::vector<int> kinds(kSlots * w), walls(w, ERODEM_CELL_WALL);
  std::vector<Real> us(kSlots * w), vs(kSlots * w);
  std::vector<SwSlopeRow<Real>> slope_x_rows, slope_y_rows;
  std::vector<SwSlopeRef<Real>> slope_x, slope_y;
  for (int k = 0; k < (Muscl ? kSlots : 0); ++k) {
    slope_x_rows.emplace_back(w);
    slope_y_rows.emplace_back(w);
  }
  for (int k = 0; k < (Muscl ? kSlots : 0); ++k) {
    slope_x.emplace_back(slope_x_rows[static_cast<std::size_t>(k)]);
    slope_y.emplace_back(slope_y_rows[static_cast<std::size_t>(k)]);
  }
  SwSlopeRow<Real> flat_row(Muscl ? w : 0);  // zeros: no slopes
  const SwSlopeRef<Real> flat(flat_row);
  SwFaceRow<Real> fy0(w), fy1(w), fx(w + 1);
  const SwFaceRef<Real> face_y[2] = {SwFaceRef<Real>(fy0), SwFaceRef<Real>(fy1)};
  const SwFaceRef<Real> face_x(fx);
  const Real *d = st.depth, *b = st.bed;
  auto slot_of = [&](int j) { return static_cast<std::size_t>(j % kSlots); };
  auto row_of = [&](int j) {  // -1 <= j <= H
    const int c = j < 0 ? 0 : (j >= H ? H - 1 : j);
    const std::size_t slot = slot_of(c) * w, row = static_cast<std::size_t>(c) * w;
    SwRow<Real> r{c == j ? kinds.data() + slot : walls.data(),
                  d + row,
                  b + row,
                  us.data() + slot,
                  vs.data() + slot,
                  {},
                  {}};
    if constexpr (Muscl) {
      r.slope_x = slope_x[slot_of(c)];
      r.slope_y = c == j && j >= 1 && j <= H - 2 ? slope_y[slot_of(c)] : flat;
    }
    return r;
  };
  auto load_row = [&](int j) {  // 0 <= j < H: kinds, velocities, x-slopes
    const int n = W;  // locals: the loop bounds and constants must not be read through the closure
    const Real e = eps;
    const std::size_t slot = slot_of(j) * w, row = static_cast<std::size_t>(j) * w;
    int* __restrict k = kinds.data() + slot;
    Real* __restrict u = us.data() + slot, * __restrict v = vs.data() + slot;
    const cell::erodem_kind_t* __restrict src = st.kind + row;
    const Real* __restrict h = d + row, * __restrict qxr = st.q_x + row, * __restrict qyr = st.q_y + row;
    for (int x = 0; x < n; ++x) k[x] = src[x];  // (bytes and floats in one loop: scalar)
    for (int x = 0; x < n; ++x) {
      u[x] = cell::sw_velocity(qxr[x], h[x], e);
      v[x] = cell::sw_velocity(qyr[x], h[x], e);
    }
    if constexpr (Muscl) {
      const SwRow<Real> r = row_of(j);
      const SwSlopeRef<Real> s = slope_x[slot_of(j)];
      s.store(0, {});
      ERODEM_IVDEP
      for (int x = 1; x < n - 1; ++x)
        s.store(x, cell::sw_slopes_x(r.state(x - 1), r.state(x), r.state(x + 1), e));
      s.store(n - 1, {});
      if (st.params.periodic_x) {
        // the ghost columns' slopes: those of the DEM columns they repeat (the seam's faces
        // are then the faces inside, shallow_water_muscl_cell's wrap)
        s.store(0, s.load(n - 2));
        s.store(n - 1, s.load(1));
      }
    }
  };
  auto slopes_y = [&](int j) {  // 1 <= j <= H - 2, rows j - 1 .. j + 1 loaded
    const int n = W;
    const Real e = eps;
    const SwRow<Real> m = row_of(j - 1), c = row_of(j), p = row_of(j + 1);
    const SwSlopeRef<Real> s = slope_y[slot_of(j)];
    ERODEM_IVDEP
    for (int x = 0; x < n; ++x)
      s.store(x, cell::sw_slopes_y(m.state(x), c.state(x), p.state(x), e));
  };
  auto faces_south_of = [&](int j) {  // -1 <= j <= H - 1
    sw_faces_y<Muscl>(W, row_of(j), row_of(j + 1), g, eps, face_y[(j + 2) % 2]);
  };
  // rows y0 - 2 (second order) .. y0 + 1 loaded and the slopes of y0 - 1 and y0 known before
  // the faces north of row y0
  for (int j = y0 - (Muscl ? 2 : 1); j <= y0 + (Muscl ? 1 : 0); ++j)
    if (j >= 0 && j < H) load_row(j);
  if constexpr (Muscl)
    for (int j = y0 - 1; j <= y0; ++j)
      if (j >= 1 && j <= H - 2) slopes_y(j);
  faces_south_of(y0 - 1);
  for (int y = y0; y < y1; ++y) {
    const int next = y + (Muscl ? 2 : 1);
    if (next < H) load_row(next);
    if constexpr (Muscl)
      if (y + 1 <= H - 2) slopes_y(y + 1);
    faces_south_of(y);
    sw_faces_x<Muscl>(W, row_of(y), g, eps, face_x);
    const SwFaceRef<Real>&north = face_y[(y + 1) % 2], &south = face_y[(y + 2) % 2];
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
    const int* __restrict k = row_of(y).kind;
    const Real* __restrict h = d + row, * __restrict qxr = st.q_x + row, * __restrict qyr = st.q_y + row, * __restrict n = st.manning + static_cast<std::ptrdiff_t>(y) * st.params.manning_pitch;
    Real* __restrict o_l = st.out_left + row, * __restrict o_r = st.out_right + row, * __restrict o_t = st.out_top + row, * __restrict o_b = st.out_bottom + row, * __restrict qx_out = st.q_x_new + row, * __restrict qy_out = st.q_y_new + row;
    // face lengths: x-faces the row's dy; y-faces the mean dx of their two rows (the rows
    // beyond the raster: the nearest face's, as shallow_water_cell clamps)
    const Real l_x = st.dy[y];
    const Real l_n = cell::face_y_width(st.dx, cell::sw_north_face_row(y));
    const Real l_s = cell::face_y_width(st.dx, cell::sw_south_face_row(y, H));
    const Real a = st.area[y], step = st.dt;
    const cell_params::FlowParams<Real> fp = st.params;
    ERODEM_IVDEP
    for (int x = 0; x < W; ++x) {
      const cell::SwCell<Real> c = cell::shallow_water_cell_update(
          k[x], h[x], qxr[x], qyr[x], n[x], l_x, l_n, l_s, a, step, fp, face_x.load(x + 1),
          face_x.load(x), south.load(x), north.load(x));
      cell::shallow_water_stage_store(x, Combine, c, o_l, o_r, o_t, o_b, qx_out, qy_out);
    }
  }
}

}  // namespace

template <class Real>
void CpuBackend<Real>::run_flow(Real dt) {
  const cell_params::FlowParams<Real> f = cell_.flow;
  const Kind* kind = kind_.data();
  const Real *b = bed_.data(), *d = depth_.data();
  // The outflows in place for every scheme: no scheme reads the previous step's outflows of a
  // cell other than its own (local inertial, pipes: flow_blocks), and the shallow-water scheme
  // reads none of them (the second order's second stage reads its own cell's first-stage
  // outflows and averages into them).
  Real *ol = flux_[0].data(), *orr = flux_[1].data(), *ot = flux_[2].data(), *ob = flux_[3].data();
  const Real *dx = dx_.data(), *dy = dy_.data(), *area = area_.data();
  const int W = W_, H = H_;
  if (params_.flow.scheme == FlowScheme::shallow_water) {
    // Every padded cell: its four faces, its outflows (in place) and (active) its new unit
    // discharges into the second buffers. First order: one stage, the buffers swapped. Second
    // order (Heun): the first stage into the outflows and the second buffers, the depth it
    // leaves, and the second stage from that depth and those unit discharges, averaged into the
    // outflows of the first and the unit discharges at the start of the step (which stay the
    // current ones).
    Field &qx = *fields_.get(FieldId::momentum_x), &qy = *fields_.get(FieldId::momentum_y);
    Field &qx_next = *fields_.twin(FieldId::momentum_x),
          &qy_next = *fields_.twin(FieldId::momentum_y);
    SwStage<Real> st{W,  H, kind, b,   d,  qx.data(), qy.data(),      manning_.data(), dx, dy, area,
                     dt, f, ol,   orr, ot, ob,        qx_next.data(), qy_next.data()};
    if (params_.flow.order == 2) {
      for_row_blocks(H, [&](int y0, int y1) { shallow_water_rows<true, false>(st, y0, y1); });
      // the halo of the first stage before the depth and the second stage read it
      exchange_fields({ol, orr, ot, ob, qx_next.data(), qy_next.data()});
      stage_depth_.resize(depth_.size());
      Real* h1 = stage_depth_.data();
      for_rows(0, H, [=](int y) {
        for (int x = 0; x < W; ++x)
          cell::shallow_water_stage_depth_cell(x, y, W, H, kind, d, ol, orr, ot, ob, area, dt, h1);
      });
      exchange_fields({h1});
      SwStage<Real> st2 = st;
      st2.depth = h1;
      st2.q_x = qx_next.data();
      st2.q_y = qy_next.data();
      st2.q_x_new = qx.data();
      st2.q_y_new = qy.data();
      for_row_blocks(H, [&](int y0, int y1) { shallow_water_rows<true, true>(st2, y0, y1); });
    } else {
      for_row_blocks(H, [&](int y0, int y1) { shallow_water_rows<false, false>(st, y0, y1); });
      std::swap(qx, qx_next);
      std::swap(qy, qy_next);
    }
    return;
  }
  flow_blocks(dt, [](int, int, int) {});  // in place
}

template <class Real>
template <class AfterRow>
void CpuBackend<Real>::flow_blocks(Real dt, const AfterRow& after_row) {
  const cell_params::FlowParams<Real> f = cell_.flow;
  const Real g = f.gravity;
  const Kind* kind = kind_.data();
  const Real *b = bed_.data(), *d = depth_.data();
  // in place: the old outflows are read through fl .. fb, the new written through ol .. ob
  Real *ol = flux_[0].data(), *orr = flux_[1].data(), *ot = flux_[2].data(), *ob = flux_[3].data();
  const Real *fl = ol, *fr = orr, *ft = ot, *fb = ob;
  const Real *dx = dx_.data(), *dy = dy_.data(), *area = area_.data();
  const int W = W_, H = H_;
  if (params_.flow.scheme == FlowScheme::pipes) {
    const Real area_pipe = f.pipe_area;
    const Real length = f.pipe_length;
    // Rows 1 .. H - 2 without clamping (the loop vectorises), the first and last row clamped.
    for_row_blocks(H, [&](int y0, int y1) {
      // Locals, not closure members: stores to Real arrays could alias those.
      const Real step = dt, gravity = g, a_pipe = area_pipe, l_pipe = length;
      for (int y = y0; y < y1; ++y) {
        if (y >= 1 && y <= H - 2) {
          Real lx, lt, lb;
          cell::pipe_lengths(y, y - 1, y + 1, dx, dy, l_pipe, &lx, &lt, &lb);
          const Real cell_area = area[y];
          // Where rows y - 1 .. y + 1 are active, columns 2 .. W - 3 and their four neighbours
          // are: the same outflows with the kinds as constants (performance.md "Rows of active
          // cells"); the two columns at each end as any interior cell.
          runs_of_active_kinds(
              all_active_around(y), 0, 2, W - 2, W, [&](auto constant, int x0, int x1) {
                ERODEM_IVDEP
                for (int x = x0; x < x1; ++x)
                  if constexpr (decltype(constant)::value)
                    cell::flow_pipes_cell_all_active(x, y, W, b, d, lx, lt, lb, cell_area, fl, fr,
                                                     ft, fb, ol, orr, ot, ob, step, gravity,
                                                     a_pipe);
                  else
                    cell::flow_pipes_cell_interior(x, y, W, kind, b, d, lx, lt, lb, cell_area, fl,
                                                   fr, ft, fb, ol, orr, ot, ob, step, gravity,
                                                   a_pipe);
              });
        } else {
          for (int x = 0; x < W; ++x)
            cell::flow_pipes_cell(x, y, W, H, kind, b, d, dx, dy, area, fl, fr, ft, fb, ol, orr, ot,
                                  ob, step, gravity, a_pipe, l_pipe);
        }
        after_row(y, y0, y1);
      }
    });
    return;
  }
  const InertialParams<Real> p{dt, g, f.theta, f.dry_depth, periodic_, f.manning_pitch};
  const Real* manning = manning_.data();
  // for_row_blocks' blocks, with a barrier all threads meet (flow_blocks' comment above)
#pragma omp parallel num_threads(threads_)
  {
    const std::pair<int, int> block = thread_row_block(H);
    const int y0 = block.first, y1 = block.second;  // (lambdas below capture them)
    const std::size_t w = static_cast<std::size_t>(W);
    // Rings of rows: cell kinds as int (slot j mod 6; walls beyond the raster), unit
    // discharges of the faces south of rows j (slot j mod 3) and discharges of the faces
    // south of rows j (slot j mod 2; zeros stand in beyond the raster). Kinds as int keep
    // every loop in 32-bit lanes, which GCC vectorises along with the floats.
    std::vector<int> kind_ring(6 * w);
    int kind_tag[6] = {-9, -9, -9, -9, -9, -9};
    std::vector<Real> q_ring(3 * w), face_ring(2 * w), q_x(w), face_x(w), zeros(w, Real(0));
    auto kind_row = [&](int j) {
      const int slot = (j + 6) % 6;
      int* r = kind_ring.data() + static_cast<std::size_t>(slot) * w;
      if (kind_tag[slot] != j) {
        kind_tag[slot] = j;
        if (j < 0 || j >= H) {
          for (int x = 0; x < W; ++x) r[x] = ERODEM_CELL_WALL;
        } else {
          const Kind* __restrict src = kind + static_cast<std::size_t>(j) * w;
          for (int x = 0; x < W; ++x) r[x] = src[x];
        }
      }
      return static_cast<const int*>(r);
    };
    auto q_row = [&](int j) { return q_ring.data() + static_cast<std::size_t>(j % 3) * w; };
    auto face_row = [&](int j) { return face_ring.data() + static_cast<std::size_t>(j % 2) * w; };
    auto unit_q = [&](int j) {
      if (j >= 0 && j <= H - 2) unit_discharge_y_row(j, W, ft, fb, dx, q_row(j));
    };
    // The unit discharges of the faces south of rows y1 - 1 and y1, which read rows of the
    // next block (slot j - y1 + 1), taken before the barrier with those of the block's first
    // rows (which read the previous block's rows) into the ring.
    std::vector<Real> q_tail(2 * w);
    const auto tail_row = [&](int j) {
      return q_tail.data() + static_cast<std::size_t>(j - y1 + 1) * w;
    };
    const auto in_tail = [&](int j) { return j >= std::max(y0 + 1, y1 - 1) && j <= y1; };
    if (y0 < y1) {
      unit_q(y0 - 2);
      unit_q(y0 - 1);
      unit_q(y0);
      for (int j = std::max(y0 + 1, y1 - 1); j <= y1; ++j)
        if (j >= 0 && j <= H - 2) unit_discharge_y_row(j, W, ft, fb, dx, tail_row(j));
    }
#pragma omp barrier
    if (y0 < y1) {
      auto faces_y = [&](int j) {
        if (j < 0 || j > H - 2) return;
        const int *up = kind_row(j - 1), *a = kind_row(j), *b_row = kind_row(j + 1),
                  *down = kind_row(j + 2);
        const Real *qu = j >= 1 ? q_row(j - 1) : q_row(j), *qj = q_row(j),
                   *qd = j + 1 <= H - 2 ? q_row(j + 1) : q_row(j);
        // where columns 1 .. W - 2 of rows j - 1 .. j + 2 are active, its faces there read the
        // kinds of active cells only
        runs_of_active_kinds(
            rows_active(j - 1, j + 2), 0, 1, W - 1, W, [&](auto constant, int x0, int x1) {
              using Kinds = RowKinds<decltype(constant)::value>;
              face_y_row(j, W, H, x0, x1, Kinds{up}, Kinds{a}, Kinds{b_row}, Kinds{down}, b, d,
                         manning, dx, dy, qu, qj, qd, p, face_row(j));
            });
      };
      faces_y(y0 - 1);
      for (int y = y0; y < y1; ++y) {
        if (in_tail(y + 1)) {
          if (y + 1 <= H - 2) std::copy(tail_row(y + 1), tail_row(y + 1) + w, q_row(y + 1));
        } else {
          unit_q(y + 1);
        }
        faces_y(y);
        face_x_row(y, W, kind_row(y), rows_active(y, y), b, d, manning, dx, dy, fl, fr, p,
                   q_x.data(), face_x.data());
        const Real* top = y >= 1 ? face_row(y - 1) : zeros.data();
        const Real* bottom = y <= H - 2 ? face_row(y) : zeros.data();
        split_row(y, W, kind_row(y), kind_row(y - 1), kind_row(y + 1), all_active_around(y), d,
                  area, face_x.data(), top, bottom, dt, ol, orr, ot, ob);
        after_row(y, y0, y1);
      }
    }
  }
}

template <class Real>
void CpuBackend<Real>::run_flow_water(Real dt, StepTally& tally, bool evaporation) {
  // The inflows by row, in list order within a row: each cell receives its rain and then its
  // inflows in the order run_sources adds them.
  const StepInputs& in = step_inputs_;
  point_rows_.clear();
  for (std::size_t k = 0; k < in.points.size(); ++k)
    point_rows_.emplace_back(static_cast<int>(padded(in.points[k].cell) / W_), k);
  std::stable_sort(point_rows_.begin(), point_rows_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  const Real rate = static_cast<Real>(in.rain_rate);
  const std::array<const Real*, 4> out{flux_[0].data(), flux_[1].data(), flux_[2].data(),
                                       flux_[3].data()};  // the flow's, in place
  const int H = H_;
  // evaporation on the water update's output (depth_next_ until the swap), row by row
  GenericRows evaporate;
  if (evaporation) {
    const auto sweeps = process_info(Process::evaporation).sweeps(params_);
    evaporate = generic_rows(sweeps.at(0), Process::evaporation, dt, depth_next_.data());
  }
  const bool stats = evaporation && stats_in_pass_, material_known = this->material_known();
  if (stats) pass_stats_rows_.resize(static_cast<std::size_t>(H - 2));
  const Real* depth_new = depth_next_.data();
  const auto water_evaporation_stats = [&](int y) {
    water_row(y, dt, out);
    if (!evaporation) return;
    evaporate.row(y);
    if (stats)
      pass_stats_rows_[static_cast<std::size_t>(y - 1)] = stats_row(y, depth_new, material_known);
  };
  // A block's flow reads the depths of the row above it and the row below it (the faces
  // between blocks): the sources of a block's first and last rows wait until every block's
  // flow is done, and so does the water update of the rows beside those. Within a block,
  // row y - 1 gets its sources once row y's outflows are stored (the flow reads a row's depth
  // last for the row below it), and row y - 2 its water update (it reads the depths and
  // outflows of the rows beside it).
  const auto sources_now = [](int s, int y0, int y1) { return s > y0 && s < y1 - 1; };
  const auto water_now = [](int w, int y0, int y1) { return w > y0 + 1 && w < y1 - 2; };
  const auto real_row = [H](int y) { return y >= 1 && y <= H - 2; };
  std::vector<std::pair<int, int>> blocks(static_cast<std::size_t>(threads_) + 1, {0, 0});
  flow_blocks(dt, [&](int y, int y0, int y1) {
    if (y == y0) {
#ifdef _OPENMP
      blocks[static_cast<std::size_t>(omp_get_thread_num())] = {y0, y1};
#else
      blocks[0] = {y0, y1};
#endif
    }
    if (real_row(y - 1) && sources_now(y - 1, y0, y1)) sources_row(y - 1, dt, rate);
    if (real_row(y - 2) && water_now(y - 2, y0, y1)) water_evaporation_stats(y - 2);
  });
  // the rows left: the sources of each block's first and last rows, then the water update of
  // the rows their depths reach
  std::vector<int> source_rows, water_rows;
  for (const auto& [y0, y1] : blocks)
    for (int y = y0; y < y1; ++y) {
      if (real_row(y) && !sources_now(y, y0, y1)) source_rows.push_back(y);
      if (real_row(y) && !water_now(y, y0, y1)) water_rows.push_back(y);
    }
  const int ns = static_cast<int>(source_rows.size()), nw = static_cast<int>(water_rows.size());
#pragma omp parallel num_threads(threads_)
  {
#pragma omp for schedule(static)
    for (int k = 0; k < ns; ++k) sources_row(source_rows[static_cast<std::size_t>(k)], dt, rate);
#pragma omp for schedule(static)
    for (int k = 0; k < nw; ++k) water_evaporation_stats(water_rows[static_cast<std::size_t>(k)]);
  }
  measure_water_faces();  // the outflows the water update applied, as run(water) measures them
  book_water_rows(dt, tally);
  if (evaporation) evaporate.book(tally);
  // depth_next_ keeps the depth the water update started from (run_water)
  std::swap(depth_, depth_next_);
  pass_stats_ = stats;
  if (stats) material_known_ = true;  // every row's volumes summed or kept
}

template void CpuBackend<float>::run_flow(float);
template void CpuBackend<double>::run_flow(double);
template void CpuBackend<float>::run_flow_water(float, StepTally&, bool);
template void CpuBackend<double>::run_flow_water(double, StepTally&, bool);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
