// CPU loop of the flow process: kernels/common/flow.h over every padded cell (ghosts give
// water too), then the new fluxes become the current ones.
//
// Local inertial: each thread takes a block of rows and walks it top to bottom, keeping the
// few rows of faces it needs in small row buffers: per cell row y it computes the unit
// discharges of the faces south of row y + 1, the discharges of the faces south of row y and
// east of every cell of row y, and splits them into row y's outflows. Every face is
// computed once per thread (the faces between two blocks twice), and every inner loop runs
// over x with values, not calls through pointers, so GCC vectorises it.
#include "common/flow.h"

#include <vector>

#include "common/shallow_water.h"
#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

namespace {

/// The scalar parameters of the local-inertial faces.
template <class Real>
struct InertialParams {
  Real dt, gravity, theta, dry_depth;
};

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

/// Discharges (m^3/s) of the faces south of padded row j (0 <= j <= H - 2), all x, from the
/// unit discharges of the faces south of rows j - 1, j and j + 1 (q_up, q, q_down; q_up or
/// q_down unused where that row of faces does not exist).
template <class Real>
void face_y_row(int j, int W, int H, const int* __restrict k_up, const int* __restrict k_a,
                const int* __restrict k_b, const int* __restrict k_down, const Real* __restrict bed,
                const Real* __restrict depth, const Real* __restrict manning,
                const Real* __restrict dx, const Real* __restrict dy, const Real* __restrict q_up,
                const Real* __restrict q, const Real* __restrict q_down,
                const InertialParams<Real>& p, Real* __restrict out) {
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(j) * W;
  const int has_up = j >= 1, has_down = j + 2 <= H - 1;
  // Beyond the raster: walls (k_up, k_down are rows of walls there) and q stands in.
  const Real* __restrict qu = has_up ? q_up : q;
  const Real* __restrict qd = has_down ? q_down : q;
  const Real* __restrict b_a = bed + row, * __restrict b_b = bed + row + W;
  const Real* __restrict d_a = depth + row, * __restrict d_b = depth + row + W;
  const Real* __restrict n_a = manning + row, * __restrict n_b = manning + row + W;
  const Real width = cell::face_y_width(dx, j), dist = cell::centre_distance_y(dy, j);
  const Real dt = p.dt, g = p.gravity, theta = p.theta, dry = p.dry_depth;
  ERODEM_IVDEP
  for (int x = 0; x < W; ++x)
    out[x] =
        cell::local_inertial_face(cell::face_open(k_a[x], k_b[x]), k_up[x] != ERODEM_CELL_WALL,
                                  k_down[x] != ERODEM_CELL_WALL, q[x], qu[x], qd[x], d_a[x], d_b[x],
                                  b_a[x], b_b[x], n_a[x], n_b[x], width, dist, dt, g, theta, dry);
}

/// Discharges (m^3/s) of the faces east of the cells x = 0 .. W - 2 of padded row y; `q` is
/// scratch for their unit discharges. out[W - 1] = 0 (no face).
template <class Real>
void face_x_row(int y, int W, const int* __restrict k, const Real* __restrict bed,
                const Real* __restrict depth, const Real* __restrict manning,
                const Real* __restrict dx, const Real* __restrict dy, const Real* __restrict f_left,
                const Real* __restrict f_right, const InertialParams<Real>& p, Real* __restrict q,
                Real* __restrict out) {
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
  const Real* __restrict fl = f_left + row, * __restrict fr = f_right + row;
  const Real* __restrict b = bed + row, * __restrict d = depth + row, * __restrict n = manning + row;
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
  ERODEM_IVDEP
  for (int x = 1; x < W - 2; ++x)
    out[x] =
        face(x, k[x - 1] != ERODEM_CELL_WALL, k[x + 2] != ERODEM_CELL_WALL, q[x - 1], q[x + 1]);
  out[W - 2] = face(W - 2, k[W - 3] != ERODEM_CELL_WALL, 0, q[W - 3], q[W - 2]);
  out[W - 1] = Real(0);
}

/// Splits the faces around the cells of padded row y into their outflows (m^3/s). face_x:
/// the row's east faces; face_top, face_bottom: the faces north and south of the row (all
/// 0 where the row of faces does not exist); k_top, k_bottom: the kinds of the rows above
/// and below (walls beyond the raster).
template <class Real>
void split_row(int y, int W, const int* __restrict k, const int* __restrict k_top,
               const int* __restrict k_bottom, const Real* __restrict depth,
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
  ERODEM_IVDEP
  for (int x = 1; x < W - 1; ++x) {
    Real l, r, t, bt;
    cell::local_inertial_split<Real>(k[x], k[x - 1], k[x + 1], k_top[x], k_bottom[x], face_x[x - 1],
                                     face_x[x], face_top[x], face_bottom[x], d[x], a, dt, &l, &r,
                                     &t, &bt);
    ol[x] = l;
    orr[x] = r;
    ot[x] = t;
    ob[x] = bt;
  }
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

/// A padded row as the shallow-water faces read it: kinds (as int; walls for the rows beyond
/// the raster, which stand on the nearest row's state, as shallow_water_cell clamps), depth,
/// bed and velocities (cell::sw_velocity).
template <class Real>
struct SwRow {
  const int* kind;
  const Real *depth, *bed, *u, *v;
};

/// The faces south of row `a` (north of row `b`), all x, into `out`.
template <class Real>
void sw_faces_y(int W, const SwRow<Real>& a, const SwRow<Real>& b, Real g, Real eps,
                const SwFaceRef<Real>& out) {
  const int* __restrict ka = a.kind, * __restrict kb = b.kind;
  const Real* __restrict ha = a.depth, * __restrict za = a.bed, * __restrict ua = a.u, * __restrict va = a.v;
  const Real* __restrict hb = b.depth, * __restrict zb = b.bed, * __restrict ub = b.u, * __restrict vb = b.v;
  ERODEM_IVDEP
  for (int x = 0; x < W; ++x)
    out.store(x, cell::sw_face(ka[x], kb[x], ha[x], za[x], -va[x], ua[x], hb[x], zb[x], -vb[x],
                               ub[x], g, eps));
}

/// The faces of row r: face x (0 <= x <= W) west of cell x, faces 0 and W against the cell
/// itself as a wall (as shallow_water_cell clamps), into `out`.
template <class Real>
void sw_faces_x(int W, const SwRow<Real>& r, Real g, Real eps, const SwFaceRef<Real>& out) {
  const int* __restrict k = r.kind;
  const Real* __restrict h = r.depth, * __restrict z = r.bed, * __restrict u = r.u, * __restrict v = r.v;
  out.store(0, cell::sw_face(ERODEM_CELL_WALL, k[0], h[0], z[0], u[0], v[0], h[0], z[0], u[0], v[0],
                             g, eps));
  ERODEM_IVDEP
  for (int x = 1; x < W; ++x)
    out.store(x, cell::sw_face(k[x - 1], k[x], h[x - 1], z[x - 1], u[x - 1], v[x - 1], h[x], z[x],
                               u[x], v[x], g, eps));
  out.store(W, cell::sw_face(k[W - 1], ERODEM_CELL_WALL, h[W - 1], z[W - 1], u[W - 1], v[W - 1],
                             h[W - 1], z[W - 1], u[W - 1], v[W - 1], g, eps));
}

}  // namespace

template <class Real>
void CpuBackend<Real>::run_flow(Real dt) {
  const cell_params::FlowParams<Real> f = cell_.flow;
  const Real g = f.gravity;
  const Kind* kind = kind_.data();
  const Real *b = bed_.data(), *d = depth_.data();
  const Real *fl = flux_[0].data(), *fr = flux_[1].data(), *ft = flux_[2].data(),
             *fb = flux_[3].data();
  Real *ol = flux_next_[0].data(), *orr = flux_next_[1].data(), *ot = flux_next_[2].data(),
       *ob = flux_next_[3].data();
  const Real *dx = dx_.data(), *dy = dy_.data(), *area = area_.data();
  const int W = W_, H = H_;
  if (params_.flow.scheme == FlowScheme::shallow_water) {
    // Every padded cell: its four faces, its outflows and (active) its new unit discharges
    // into the second buffers, swapped below.
    Field &qx = *fields_.get(FieldId::momentum_x), &qy = *fields_.get(FieldId::momentum_y);
    Field &qx_next = *fields_.twin(FieldId::momentum_x),
          &qy_next = *fields_.twin(FieldId::momentum_y);
    const Real *q_x = qx.data(), *q_y = qy.data(), *manning = manning_.data();
    Real *q_x_new = qx_next.data(), *q_y_new = qy_next.data();
    // Each thread a block of rows, walked top to bottom: per row y the velocities of row
    // y + 1, the faces south of row y and those of row y, then row y's cells from their four
    // faces (cell::shallow_water_cell_update), each face computed once (the faces between two
    // blocks twice) with the arguments shallow_water_cell gives it: the same bits as the
    // OpenCL kernel, which computes every face from both sides.
    const Real eps = f.dry_depth;
    for_row_blocks(H, [&](int y0, int y1) {
      const std::size_t w = static_cast<std::size_t>(W);
      // rings: kinds and velocities of rows j (slot j mod 3), faces south of rows j (slot j
      // mod 2); walls for the kinds of the rows beyond the raster
      std::vector<int> kinds(3 * w), walls(w, ERODEM_CELL_WALL);
      std::vector<Real> us(3 * w), vs(3 * w);
      SwFaceRow<Real> fy0(w), fy1(w), fx(w + 1);
      const SwFaceRef<Real> face_y[2] = {SwFaceRef<Real>(fy0), SwFaceRef<Real>(fy1)};
      const SwFaceRef<Real> face_x(fx);
      auto load_row = [&](int j) {  // 0 <= j < H
        const std::size_t slot = static_cast<std::size_t>(j % 3) * w;
        const std::size_t row = static_cast<std::size_t>(j) * w;
        int* __restrict k = kinds.data() + slot;
        Real* __restrict u = us.data() + slot, * __restrict v = vs.data() + slot;
        const Kind* __restrict src = kind + row;
        const Real* __restrict h = d + row, * __restrict qxr = q_x + row, * __restrict qyr = q_y + row;
        for (int x = 0; x < W; ++x) {
          k[x] = src[x];
          u[x] = cell::sw_velocity(qxr[x], h[x], eps);
          v[x] = cell::sw_velocity(qyr[x], h[x], eps);
        }
      };
      auto row_of = [&](int j) {  // -1 <= j <= H
        const int c = j < 0 ? 0 : (j >= H ? H - 1 : j);
        const std::size_t slot = static_cast<std::size_t>(c % 3) * w;
        const std::size_t row = static_cast<std::size_t>(c) * w;
        return SwRow<Real>{c == j ? kinds.data() + slot : walls.data(), d + row, b + row,
                           us.data() + slot, vs.data() + slot};
      };
      auto faces_south_of = [&](int j) {  // -1 <= j <= H - 1
        sw_faces_y(W, row_of(j), row_of(j + 1), g, eps, face_y[(j + 2) % 2]);
      };
      if (y0 >= 1) load_row(y0 - 1);
      load_row(y0);
      faces_south_of(y0 - 1);
      for (int y = y0; y < y1; ++y) {
        if (y + 1 < H) load_row(y + 1);
        faces_south_of(y);
        sw_faces_x(W, row_of(y), g, eps, face_x);
        const SwFaceRef<Real>&north = face_y[(y + 1) % 2], &south = face_y[(y + 2) % 2];
        const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
        const int* __restrict k = row_of(y).kind;
        const Real* __restrict h = d + row, * __restrict qxr = q_x + row, * __restrict qyr = q_y + row, * __restrict n = manning + row;
        Real* __restrict o_l = ol + row, * __restrict o_r = orr + row, * __restrict o_t = ot + row, * __restrict o_b = ob + row, * __restrict qx_out = q_x_new + row, * __restrict qy_out = q_y_new + row;
        // face lengths: x-faces the row's dy; y-faces the mean dx of their two rows (the
        // rows beyond the raster: the nearest face's, as shallow_water_cell clamps)
        const Real l_x = dy[y];
        const Real l_n = cell::face_y_width(dx, y >= 1 ? y - 1 : y);
        const Real l_s = cell::face_y_width(dx, y + 1 < H ? y : (y >= 1 ? y - 1 : y));
        const Real a = area[y], step = dt;
        const cell_params::FlowParams<Real> fp = f;
        ERODEM_IVDEP
        for (int x = 0; x < W; ++x) {
          const cell::SwCell<Real> c = cell::shallow_water_cell_update(
              k[x], h[x], qxr[x], qyr[x], n[x], l_x, l_n, l_s, a, step, fp, face_x.load(x + 1),
              face_x.load(x), south.load(x), north.load(x));
          o_l[x] = c.left;
          o_r[x] = c.right;
          o_t[x] = c.top;
          o_b[x] = c.bottom;
          qx_out[x] = c.q_x;
          qy_out[x] = c.q_y;
        }
      }
    });
    std::swap(qx, qx_next);
    std::swap(qy, qy_next);
    std::swap(flux_, flux_next_);
    return;
  }
  if (params_.flow.scheme == FlowScheme::pipes) {
    const Real area_pipe = f.pipe_area;
    const Real length = f.pipe_length;
    // Rows 1 .. H - 2 without clamping (the loop vectorises), the first and last row clamped.
    for_rows(0, H, [=](int y) {
      // Locals, not closure members: stores to Real arrays could alias those.
      const Real step = dt, gravity = g, a_pipe = area_pipe, l_pipe = length;
      if (y >= 1 && y <= H - 2) {
        Real lx, lt, lb;
        cell::pipe_lengths(y, y - 1, y + 1, dx, dy, l_pipe, &lx, &lt, &lb);
        const Real cell_area = area[y];
        ERODEM_IVDEP
        for (int x = 0; x < W; ++x)
          cell::flow_pipes_cell_interior(x, y, W, kind, b, d, lx, lt, lb, cell_area, fl, fr, ft, fb,
                                         ol, orr, ot, ob, step, gravity, a_pipe);
      } else {
        for (int x = 0; x < W; ++x)
          cell::flow_pipes_cell(x, y, W, H, kind, b, d, dx, dy, area, fl, fr, ft, fb, ol, orr, ot,
                                ob, step, gravity, a_pipe, l_pipe);
      }
    });
    std::swap(flux_, flux_next_);
    return;
  }
  const InertialParams<Real> p{dt, g, f.theta, f.dry_depth};
  const Real* manning = manning_.data();
  for_row_blocks(H, [&](int y0, int y1) {
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
    auto faces_y = [&](int j) {
      if (j < 0 || j > H - 2) return;
      face_y_row(j, W, H, kind_row(j - 1), kind_row(j), kind_row(j + 1), kind_row(j + 2), b, d,
                 manning, dx, dy, j >= 1 ? q_row(j - 1) : q_row(j), q_row(j),
                 j + 1 <= H - 2 ? q_row(j + 1) : q_row(j), p, face_row(j));
    };
    unit_q(y0 - 2);
    unit_q(y0 - 1);
    unit_q(y0);
    faces_y(y0 - 1);
    for (int y = y0; y < y1; ++y) {
      unit_q(y + 1);
      faces_y(y);
      face_x_row(y, W, kind_row(y), b, d, manning, dx, dy, fl, fr, p, q_x.data(), face_x.data());
      const Real* top = y >= 1 ? face_row(y - 1) : zeros.data();
      const Real* bottom = y <= H - 2 ? face_row(y) : zeros.data();
      split_row(y, W, kind_row(y), kind_row(y - 1), kind_row(y + 1), d, area, face_x.data(), top,
                bottom, dt, ol, orr, ot, ob);
    }
  });
  std::swap(flux_, flux_next_);
}

template void CpuBackend<float>::run_flow(float);
template void CpuBackend<double>::run_flow(double);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
