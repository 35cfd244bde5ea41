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

#ifdef _OPENMP
#include <omp.h>
#endif

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
    const cell_params::FlowParams<Real> params = f;
    // Rows 1 .. H - 2 without clamping but for their first and last cell (the loop
    // vectorises), the first and last row clamped.
    for_rows(0, H, [=](int y) {
      const Real step = dt;
      const cell_params::FlowParams<Real> fp = params;
      auto general = [&](int x) {
        cell::shallow_water_cell(x, y, W, H, kind, b, d, q_x, q_y, manning, dx, dy, area, step, fp,
                                 ol, orr, ot, ob, q_x_new, q_y_new);
      };
      if (y >= 1 && y <= H - 2) {
        general(0);
        ERODEM_IVDEP
        for (int x = 1; x < W - 1; ++x)
          cell::shallow_water_cell_interior(x, y, W, kind, b, d, q_x, q_y, manning, dx, dy, area,
                                            step, fp, ol, orr, ot, ob, q_x_new, q_y_new);
        general(W - 1);
      } else {
        for (int x = 0; x < W; ++x) general(x);
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
#pragma omp parallel num_threads(threads_)
  {
#ifdef _OPENMP
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
#else
    const int t = 0, nt = 1;
#endif
    // This thread's rows [y0, y1), a static block as schedule(static) would give.
    const int y0 = static_cast<int>(static_cast<long>(H) * t / nt);
    const int y1 = static_cast<int>(static_cast<long>(H) * (t + 1) / nt);
    if (y0 < y1) {
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
    }
  }
  std::swap(flux_, flux_next_);
}

template void CpuBackend<float>::run_flow(float);
template void CpuBackend<double>::run_flow(double);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
