#pragma once
// Shape functions of the background grid, one dimension at a time (2D and 3D
// weights are tensor products). Each is a policy the kernels are compiled for,
// so the choice costs nothing per particle:
//
//   Linear  - tent functions, 2 nodes per direction; cell-crossing noise.
//   Gimp    - uniform GIMP (Bardenhagen & Kober 2004): the tent convolved with
//             the particle's characteristic function of half-width lp.
//   Bspline - quadratic B-splines, 3 nodes per direction, C1 gradients.
//
// eval() takes the particle's grid coordinate xi (in cells from node 0) and the
// particle half-width lp in cells, and fills `support` weights and their
// derivatives d/dxi (divide by h for d/dx) for nodes base, base+1, ...

#include <cmath>

namespace outburst::mpm {

// floor(x) as an int: std::floor over SIMD lanes needs -fno-trapping-math from
// GCC, and without it the stencils' loops over a chunk's particles stayed
// scalar. The build takes that flag now (CMakeLists.txt), for other loops;
// floor_int keeps the stencils from depending on it. The truncation, one lower
// where it rounded up (x negative and not whole), is the same integer. x must
// lie within int's range, where the conversion is defined: the solver's
// stencils read the particles and tracers a scene placed on the grid, and after
// each step only the particles still on it (the census removes the ones that
// left and stops the run at a non-finite position; the move's mapping ahead
// skips the chunks the census found such a particle in). Holding x there first
// cost every kernel 15 %
// (docs/performance/log.md#the-mpm-kernel): GCC 12
// sinks the conversion into the select's branches, where it may trap, and keeps
// the stencils' loops scalar again. Near int's ends one lower wraps: unsigned,
// so that the wrap is defined, and the support check refuses it (supported()).
inline int floor_int(double x) {
  const int t = static_cast<int>(x);
  return static_cast<int>(static_cast<unsigned>(t) - (x < t));
}

// Whether the nodes base .. base + support - 1 lie within 0 .. nodes - 1:
// unsigned, so that a negative base or one near int's end (floor_int off the
// grid) fails too, where base + support would wrap.
inline bool supported(int base, int support, int nodes) {
  return static_cast<unsigned>(base) <= static_cast<unsigned>(nodes - support);
}

struct Linear {
  static constexpr int support = 2;
  static constexpr const char* name = "linear";
  // d w / d xi is -1 at the lower node and 1 at the upper, wherever xi is.
  static constexpr bool unit_slopes = true;
  static inline int eval(double xi, double /*lp*/, double* w, double* dw) {
    const int base = floor_int(xi);
    const double f = xi - base;
    w[0] = 1 - f;
    w[1] = f;
    dw[0] = -1;
    dw[1] = 1;
    return base;
  }
};

struct Gimp {
  static constexpr int support = 3;
  static constexpr const char* name = "gimp";
  static inline int eval(double xi, double lp, double* w, double* dw) {
    // Unsigned, and the nodes' places in double: floor_int wraps to int's
    // highest far below the grid, and one more would overflow.
    const int base = static_cast<int>(static_cast<unsigned>(floor_int(xi - 1 - lp)) + 1u);
    for (int k = 0; k < 3; ++k) {
      const double r = xi - (static_cast<double>(base) + k);
      const double a = std::abs(r);
      const double s = r < 0 ? -1.0 : 1.0;
      if (a < lp) {
        w[k] = 1 - (r * r + lp * lp) / (2 * lp);
        dw[k] = -r / lp;
      } else if (a < 1 - lp) {
        w[k] = 1 - a;
        dw[k] = -s;
      } else if (a < 1 + lp) {
        const double g = 1 + lp - a;
        w[k] = g * g / (4 * lp);
        dw[k] = -s * g / (2 * lp);
      } else {
        w[k] = 0;
        dw[k] = 0;
      }
    }
    return base;
  }
};

struct Bspline {
  static constexpr int support = 3;
  static constexpr const char* name = "bspline";
  static inline int eval(double xi, double /*lp*/, double* w, double* dw) {
    const int base = floor_int(xi - 0.5);
    const double f = xi - base;  // in [0.5, 1.5)
    w[0] = 0.5 * (1.5 - f) * (1.5 - f);
    w[1] = 0.75 - (f - 1) * (f - 1);
    w[2] = 0.5 * (f - 0.5) * (f - 0.5);
    dw[0] = f - 1.5;
    dw[1] = -2 * (f - 1);
    dw[2] = f - 0.5;
    return base;
  }
};

}  // namespace outburst::mpm
