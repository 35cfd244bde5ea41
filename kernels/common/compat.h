/* erodem — the common subset of C++ and OpenCL C in which per-cell formulas are written.
 *
 * Every process of MODEL.md is written once, as functions of one cell, in the headers of
 * kernels/common. The CPU reference (kernels/cpu) loops over cells calling them; the OpenCL kernels
 * (kernels/opencl) call the same functions from one work-item per cell. In C++ the
 * functions are templates on the floating-point type `real` (float or double); in OpenCL C
 * `real` is a typedef set by the build options.
 *
 * Storage layout: every field is a padded raster of W = nx + 2 columns by H = ny + 2 rows
 * with a one-cell halo. Cell (x, y) of the padded raster is at index x + y * W; the DEM's
 * cell (col, row) is at x = col + 1, y = row + 1. Halo cells and nodata cells are ghosts
 * whose kind (below) says how water crosses their faces. Row y = 0 is the north halo.
 */
#ifndef ERODEM_KERNELS_COMMON_COMPAT_H
#define ERODEM_KERNELS_COMMON_COMPAT_H

#ifdef __OPENCL_C_VERSION__
/* always_inline: PoCL (LLVM) otherwise keeps the larger cell functions as calls, and a
 * work-item loop with a call in it is not vectorised */
#define ERODEM_FN static inline __attribute__((always_inline))
#define ERODEM_FN_INLINED ERODEM_FN
#define ERODEM_INLINE static inline __attribute__((always_inline))
#define GLOBAL __global
#define ERODEM_EPSILON(T) ((T)FLT_EPSILON)
#define ERODEM_BEGIN_NAMESPACE
#define ERODEM_END_NAMESPACE
typedef uchar erodem_kind_t;
#else
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
namespace erodem {
namespace cell {
using std::cbrt;
using std::exp;
using std::expm1;
using std::fabs;
using std::fmax;
using std::fmin;
using std::isfinite;
using std::log1p;
using std::sqrt;
typedef std::uint8_t erodem_kind_t;
}  // namespace cell
}  // namespace erodem
/* The kinds' type is a template parameter too (erodem_kind_t, a byte by default): a CPU loop
 * may pass them as int (CpuBackend::water_row), since GCC sizes a loop's vectors by the
 * smallest type it reads (64 cells at once with AVX-512 for a byte, four registers for every
 * float value). */
#define ERODEM_FN                                             \
  template <class real, class erodem_kind_t = ::std::uint8_t> \
  inline
/* A cell function too large for GCC's inliner that a vectorised loop must still inline (the
 * shallow-water cell: its four faces and their Riemann problems). */
#define ERODEM_FN_INLINED                                     \
  template <class real, class erodem_kind_t = ::std::uint8_t> \
  inline __attribute__((always_inline))
#define ERODEM_INLINE inline
#define GLOBAL
#define ERODEM_EPSILON(T) std::numeric_limits<T>::epsilon()
#define ERODEM_BEGIN_NAMESPACE \
  namespace erodem {           \
  namespace cell {
#define ERODEM_END_NAMESPACE \
  }                          \
  }
#endif

/* One parameter struct per process: the run constants of its cell functions, members of
 * type `real` or `int` only, so that the host's Name<float> and the device's Name share one
 * layout (kernels/cell_params.hpp checks the size). The host converts the parameters into it
 * once (kernels/cell_params.cpp) and both backends pass it as it is: the CPU loops to the cell
 * functions, the OpenCL host as one kernel argument, by value. ERODEM_PARAMS_BEGIN(Name)
 * members ERODEM_PARAMS_END(Name) declares it, at file scope (outside ERODEM_BEGIN_NAMESPACE);
 * ERODEM_P(Name) names it in a cell function's signature. In C++ the structs live in
 * erodem::cell_params, outside the per-instruction-set namespaces of the CPU builds
 * (cpu/isa_prelude.hpp): they hold no code, and the one conversion (baseline code) fills the
 * type every build uses. The members sit between two macros, not in a macro argument: that
 * would need a variadic macro (the members' commas), which OpenCL C compilers may refuse
 * (NVIDIA's does: "variadic macros not supported in OpenCL"). */
#ifdef __OPENCL_C_VERSION__
#define ERODEM_PARAMS_BEGIN(Name) typedef struct {
#define ERODEM_PARAMS_END(Name) \
  }                             \
  Name;
#define ERODEM_P(Name) Name
#else
#define ERODEM_PARAMS_BEGIN(Name) \
  namespace erodem {              \
  namespace cell_params {         \
  template <class real>           \
  struct Name {
#define ERODEM_PARAMS_END(Name) \
  }                             \
  ;                             \
  }                             \
  }
#define ERODEM_P(Name) ::erodem::cell_params::Name<real>
#endif

/* A small struct of values that cell functions pass between them (a face's fluxes, a cell's
 * results), members of type `real` or `int`: ERODEM_STRUCT_BEGIN(Name) members
 * ERODEM_STRUCT_END(Name) declares it inside ERODEM_BEGIN_NAMESPACE, ERODEM_S(Name) names it in
 * a cell function. In C++ it is a template on `real`, as the functions are. */
#ifdef __OPENCL_C_VERSION__
#define ERODEM_STRUCT_BEGIN(Name) typedef struct {
#define ERODEM_STRUCT_END(Name) \
  }                             \
  Name;
#define ERODEM_S(Name) Name
#else
#define ERODEM_STRUCT_BEGIN(Name) \
  template <class real>           \
  struct Name {
#define ERODEM_STRUCT_END(Name) \
  }                             \
  ;
#define ERODEM_S(Name) Name<real>
#endif

/* Cube root with the same bits on the CPU and every OpenCL device (float32). The C library's
 * cbrtf and OpenCL's cbrt may differ by an ulp, and the thresholds of the flow schemes (dry
 * faces, clipping) turn one ulp into visible differences after many steps. This one uses
 * only correctly rounded +, -, *, / (FP_CONTRACT off in the kernels): a bit-level first
 * guess and two Halley steps, within 1 ulp of the exact root (tests/test_cbrt.cpp).
 * erodem_cbrt_positive(x) is this function for float and cbrt_f64_positive (below) for
 * double (the CPU float64 reference). */
#ifdef __OPENCL_C_VERSION__
ERODEM_INLINE unsigned int erodem_float_bits(float x) {
  return as_uint(x);
}
ERODEM_INLINE float erodem_bits_float(unsigned int b) {
  return as_float(b);
}
#else
namespace erodem {
namespace cell {
inline unsigned int erodem_float_bits(float x) {
  std::uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}
inline float erodem_bits_float(unsigned int b) {
  const std::uint32_t u = b;
  float x;
  std::memcpy(&x, &u, sizeof x);
  return x;
}
}  // namespace cell
}  // namespace erodem
#endif

ERODEM_BEGIN_NAMESPACE
/* The index of padded cell (x, y) in a cell parameter array (hardness, Manning n, the rain
 * factor) of `pitch` values per row: W when the array holds a value per cell, 0 when the
 * parameter is uniform and the array one row of W copies of it (both backends then keep W
 * values, not W H: docs/architecture.md "Uniform parameters"). The pitch is a member of
 * the reading process's parameter struct, set by the backend that holds the array. */
ERODEM_INLINE int param_index(int x, int y, int pitch) {
  return x + y * pitch;
}

/* First guess of the cube root of a positive normal float x, within 3.3 % (Kahan's bit
 * trick): the bits of x over 3 plus the bias of the exponent times 2/3. The division by 3
 * is done in float, (float)bits * (1/3) truncated (exact enough for a guess), since neither
 * GCC nor PoCL vectorise a 32-bit integer division well; every step of it is exactly
 * defined (int -> float rounds to nearest, float -> int truncates), so every device gives
 * the same bits. */
ERODEM_INLINE float cbrt_f32_guess(float x) {
  const int bits = (int)erodem_float_bits(x); /* < 2^31 for x > 0 (not for -0: 0x80000000) */
  return erodem_bits_float((unsigned int)((int)((float)bits * 0.333333343f) + 709958130));
}

/* Smallest and largest x that cbrt_f32_positive takes: on [1e-30, 1e38] the cube y^3 and
 * 2 y^3 + x of its Halley steps stay normal and finite, so it needs no scaling. */
#define ERODEM_CBRT_MIN 1.0e-30f
#define ERODEM_CBRT_MAX 1.0e38f

/* Cube root of x in [ERODEM_CBRT_MIN, ERODEM_CBRT_MAX] (NaN gives NaN), branch-free, so
 * loops over cells vectorise. The caller keeps x in range (local_inertial_q: faces
 * shallower than ERODEM_FACE_DEPTH_MIN = 1e-16 m are dry); scaling tiny and huge x by powers of two
 * inside, as a cube root of every float must, took 15 % of the local-inertial face pass on
 * PoCL. */
ERODEM_INLINE float cbrt_f32_positive(float x) {
  float y = cbrt_f32_guess(x);
  /* two Halley steps (cubic convergence: 3.3 % -> 2e-5 -> below float rounding; a third
   * step changes no result by more than rounding), written out: PoCL does not vectorise a
   * work-item loop that holds an inner loop */
  float y3 = y * y * y;
  y = y - y * ((y3 - x) / (y3 + y3 + x));
  y3 = y * y * y;
  y = y - y * ((y3 - x) / (y3 + y3 + x));
  return y;
}
ERODEM_END_NAMESPACE

#ifdef __OPENCL_C_VERSION__
#define erodem_cbrt_positive(x) cbrt_f32_positive(x)
#else
namespace erodem {
namespace cell {
/* Cube root of a double x in [ERODEM_CBRT_MIN, ERODEM_CBRT_MAX] (the CPU float64 reference):
 * cbrt_f32_positive of x rounded to float (within 1 float ulp, 1.2e-7, of the root of x) and
 * one Halley step in double (cubic convergence: 1.2e-7 -> 1e-21, below double rounding), so
 * within 1 ulp of the exact root (tests/test_cbrt.cpp, against long double). Branch-free and
 * without a call, so the loops that take it vectorise; the C library's cbrt, a call, kept the
 * local-inertial face loop scalar: float64 flow ran 11.6x slower than float32 at 1024²
 * (docs/performance.md, float64). */
inline double cbrt_f64_positive(double x) {
  const double y = static_cast<double>(cbrt_f32_positive(static_cast<float>(x)));
  const double y3 = y * y * y;
  return y - y * ((y3 - x) / (y3 + y3 + x));
}
/* The cube root of x in [ERODEM_CBRT_MIN, ERODEM_CBRT_MAX]: cbrt_f32_positive for float,
 * cbrt_f64_positive for double. */
inline float erodem_cbrt_positive(float x) {
  return cbrt_f32_positive(x);
}
inline double erodem_cbrt_positive(double x) {
  return cbrt_f64_positive(x);
}
}  // namespace cell
}  // namespace erodem
#endif

/* exp(-x) for x >= 0, and (1 - exp(-x)) / x (1 at x = 0), with the same bits on the CPU and
 * every OpenCL device (float32): the libraries' exp and expm1 may differ by an ulp, which the
 * bed turns into visible differences of the flow after many steps (the physical erosion law's
 * exact exchange, erosion.h). Correctly rounded +, -, * and / only: x = n ln 2 + r with |r| <=
 * 0.35 (ln 2 in two parts, Cody & Waite, so n ln2_hi is exact), exp(-r) by its Taylor
 * polynomial to r^7 (error below 6e-9), times 2^-n built from its bits; 0 beyond x = 87 (below
 * the smallest normal float). The weight by its Taylor series to x^7 below x = 0.5 (error
 * below 2e-8), else from exp(-x). Branch-free (the choices are products with 0 or 1), so
 * loops vectorise. For double (the CPU float64 reference): exp_neg_f64 and relax_weight_f64
 * below, the same construction to double's precision. */
ERODEM_BEGIN_NAMESPACE
ERODEM_INLINE float exp_neg_f32(float x) {
  const float xc = x < 87.0f ? x : 87.0f;
  const int n = (int)(xc * 1.44269504f + 0.5f);
  const float r = (xc - (float)n * 0.693145751953125f) - (float)n * 1.42860677e-6f;
  float p = -1.98412698e-4f; /* -1/7! */
  p = p * r + 1.38888889e-3f;
  p = p * r - 8.33333333e-3f;
  p = p * r + 4.16666667e-2f;
  p = p * r - 1.66666667e-1f;
  p = p * r + 0.5f;
  p = p * r - 1.0f;
  p = p * r + 1.0f;
  const float scale = erodem_bits_float((unsigned int)(127 - n) << 23);
  /* times 1 or 0, not a select: GCC threads a select on x < 87 through the clamp above into
   * two paths, and the loop then is not vectorised ("control flow in loop") */
  const float in_range = (float)(x < 87.0f);
  return p * scale * in_range;
}
ERODEM_INLINE float relax_weight_f32(float x) {
  float p = -2.48015873e-5f; /* -1/8! */
  p = p * x + 1.98412698e-4f;
  p = p * x - 1.38888889e-3f;
  p = p * x + 8.33333333e-3f;
  p = p * x - 4.16666667e-2f;
  p = p * x + 1.66666667e-1f;
  p = p * x - 0.5f;
  p = p * x + 1.0f;
  const float big = (1.0f - exp_neg_f32(x)) / (x > 0.5f ? x : 1.0f);
  const float large = (float)(x > 0.5f); /* the same blend by 1 and 0 (exact: both finite) */
  return large * big + (1.0f - large) * p;
}
ERODEM_END_NAMESPACE

#ifndef __OPENCL_C_VERSION__
namespace erodem {
namespace cell {
/* 1/k! for k = 0 .. 15, each the double nearest it. */
constexpr double kInverseFactorial[16] = {1.0,
                                          1.0,
                                          0.5,
                                          1.66666666666666667e-1,
                                          4.16666666666666667e-2,
                                          8.33333333333333333e-3,
                                          1.38888888888888889e-3,
                                          1.98412698412698413e-4,
                                          2.48015873015873016e-5,
                                          2.75573192239858907e-6,
                                          2.75573192239858907e-7,
                                          2.50521083854417188e-8,
                                          2.08767569878680990e-9,
                                          1.60590438368216146e-10,
                                          1.14707455977297247e-11,
                                          7.64716373181981648e-13};
/* sum over k = 0 .. n of (-x)^k / (k + shift)! by Horner's rule from the highest term (n +
 * shift <= 15). Called with constant n and shift, the loop unrolls into the written-out
 * polynomial, and the cell loops that take it still vectorise. */
inline double alternating_factorial_series(double x, int shift, int n) {
  double p = (n % 2 ? -1.0 : 1.0) * kInverseFactorial[n + shift];
  for (int k = n - 1; k >= 0; --k) p = p * x + (k % 2 ? -1.0 : 1.0) * kInverseFactorial[k + shift];
  return p;
}
/* exp(-x) for x >= 0 in double, as exp_neg_f32: x = n ln 2 + r, |r| <= 0.35 (ln 2 in two
 * parts: the first has 32 significant bits, so n ln2_hi is exact for n < 2^21), exp(-r) by its
 * Taylor polynomial to r^13 (tail below 5e-18), times 2^-n from its bits; 0 beyond x = 708
 * (exp(-708) = 3.3e-308, just above the smallest normal double; the C library would give
 * subnormals up to 745). Within 2 ulps of the exact value (tests/test_exp.cpp, against long
 * double). The C library's exp, a call, kept the physical erosion law's cell loop scalar:
 * its float64 pass ran 14x slower than float32 (docs/performance.md, float64). */
inline double exp_neg_f64(double x) {
  const double xc = x < 708.0 ? x : 708.0;
  const int n = static_cast<int>(xc * 1.4426950408889634 + 0.5);
  const double r = (xc - n * 0.693147180369123816490) - n * 1.90821492927058770002e-10;
  const double p = alternating_factorial_series(r, 0, 13);
  const std::uint64_t bits = static_cast<std::uint64_t>(1023 - n) << 52;
  double scale;
  std::memcpy(&scale, &bits, sizeof scale);
  const double in_range = static_cast<double>(x < 708.0); /* a product, not a select */
  return p * scale * in_range;
}
/* (1 - exp(-x)) / x for x >= 0 in double (1 at x = 0): its Taylor series to x^14 below x =
 * 0.5 (tail below 2e-18), else from exp_neg_f64; within 2 ulps (tests/test_exp.cpp). */
inline double relax_weight_f64(double x) {
  const double p = alternating_factorial_series(x, 1, 14);
  const double big = (1.0 - exp_neg_f64(x)) / (x > 0.5 ? x : 1.0);
  const double large = static_cast<double>(x > 0.5);
  return large * big + (1.0 - large) * p;
}
}  // namespace cell
}  // namespace erodem
#endif

#ifdef __OPENCL_C_VERSION__
#define erodem_exp_neg(x) exp_neg_f32(x)
#define erodem_relax_weight(x) relax_weight_f32(x)
#else
namespace erodem {
namespace cell {
inline float erodem_exp_neg(float x) {
  return exp_neg_f32(x);
}
inline double erodem_exp_neg(double x) {
  return exp_neg_f64(x);
}
inline float erodem_relax_weight(float x) {
  return relax_weight_f32(x);
}
inline double erodem_relax_weight(double x) {
  return relax_weight_f64(x);
}
}  // namespace cell
}  // namespace erodem
#endif

/* The larger (smaller) of two numbers that are not NaN (for NaN the two languages differ: fmax
 * gives the other number, the comparison gives b). The same value everywhere else, bit for bit; the
 * spelling is per compiler: in the local-inertial face loops PoCL vectorises fmax across
 * work-items but not the comparison (27 instead of 33 loops 8 wide on AVX2,
 * tests/pocl_vectorisation.sh), and GCC the comparison but not fmax (the two face loops of
 * kernels/cpu/flow.cpp stay scalar: fmax must keep NaN semantics). */
#ifdef __OPENCL_C_VERSION__
#define erodem_max(a, b) fmax(a, b)
#define erodem_min(a, b) fmin(a, b)
#else
#define erodem_max(a, b) ((a) > (b) ? (a) : (b))
#define erodem_min(a, b) ((a) < (b) ? (a) : (b))
#endif

/* Cell kinds (the `kind` field). */
#define ERODEM_CELL_ACTIVE 0 /* a DEM cell that carries water, sediment and bed */
#define ERODEM_CELL_WALL 1   /* closed: no flux across any of its faces */
#define ERODEM_CELL_OPEN 2   /* free outflow: takes water from active cells, gives none */
#define ERODEM_CELL_FIXED 3  /* fixed water level (sea): exchanges water both ways, unlimited */

/* Face directions, the order of the four flux fields. */
#define ERODEM_LEFT 0   /* west,  x - 1 */
#define ERODEM_RIGHT 1  /* east,  x + 1 */
#define ERODEM_TOP 2    /* north, y - 1 */
#define ERODEM_BOTTOM 3 /* south, y + 1 */

/* The geometry between padded rows j and j + 1 (each row has its own dx, dy: geographic grids),
 * one formula for every stencil and both backends: the width (m) of the faces between them,
 * the mean of the rows' east-west sizes, and the distance (m) between their centres, the mean
 * of their north-south sizes. */
ERODEM_BEGIN_NAMESPACE
ERODEM_FN real face_y_width(GLOBAL const real* dx, int j) {
  return (real)0.5 * (dx[j] + dx[j + 1]);
}
ERODEM_FN real centre_distance_y(GLOBAL const real* dy, int j) {
  return (real)0.5 * (dy[j] + dy[j + 1]);
}
ERODEM_END_NAMESPACE

#endif
