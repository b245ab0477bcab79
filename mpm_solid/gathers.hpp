#pragma once
// The node loops of the two gathers over a chunk's stencils (StencilLanes):
// the velocity gradient the stress update takes, and the sums the motion
// update takes. Each comes in two forms that give the same bits:
// - lanes: for each node, the chunk's particles over SIMD lanes, each lane
//   loading its own node's components one at a time (the nodes of two lanes
//   lie apart);
// - pairs (the plane only): a particle at a time, a node's two components,
//   which lie side by side, loaded as one vector of two doubles.
// Each component's sum takes the nodes in the same order, with the same
// products, either way. Where the build's vectors hold two doubles pairs
// load half as often; where they hold four, lanes fill them (CMake's
// OUTBURST_GATHER picks; tests/test_mpm_stencil.cpp holds the two to the
// same bits).

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>

#include "mpm_solid/stencil.hpp"

namespace outburst::mpm::gathers {

// GCC's vector extensions: a node's two components.
using Pair = double __attribute__((vector_size(16)));

// Through memcpy: the nodal arrays are doubles to the compiler (Eigen aligns
// a Vec<2> to 16 bytes, the tests' arrays to 8).
[[gnu::always_inline]] inline Pair load_pair(const double* at) {
  Pair v;
  std::memcpy(&v, at, sizeof v);
  return v;
}

// L = grad v from the nodal velocities (Dim components a node) at the
// particles of a chunk's lanes: d v_b / d x_d of lane `lane` at
// out[d][b][lane], each lane's entries in Eigen's order (entry e = b + Dim d
// at out[0][0] + e * Width).
template <bool Pairs, int Dim, class Shape, int Width>
[[gnu::always_inline]] inline void velocity_gradients(const double* nodal, const StencilLanes<Dim, Shape, Width>& s,
                                                      int lanes, double (&out)[Dim][Dim][Width]) {
  if constexpr (Pairs && Dim == 2) {
    for (int lane = 0; lane < lanes; ++lane) {
      const double* v = nodal + 2 * s.first[lane];
      Pair l[2] = {};
      s.for_each_node([&](int k, const std::array<int, Dim>& a) __attribute__((always_inline)) {
        const Pair at = load_pair(v + 2 * s.offset[k]);
        l[0] += at * s.gradient(0, a, lane);
        l[1] += at * s.gradient(1, a, lane);
      });
      for (int d = 0; d < 2; ++d)
        for (int b = 0; b < 2; ++b) out[d][b][lane] = l[d][b];
    }
  } else {
    // Summed in a local: in `out` the sums were loaded and stored again at
    // every node, as the nodal velocities might alias it.
    alignas(64) double l[Dim][Dim][Width] = {};
    s.for_each_node([&](int k, const std::array<int, Dim>& a) {
      const std::ptrdiff_t offset = s.offset[k];
#pragma omp simd
      for (int lane = 0; lane < lanes; ++lane) {
        const double* v = nodal + Dim * (s.first[lane] + offset);
#pragma GCC unroll 3
        for (int d = 0; d < Dim; ++d) {
          const double g = s.gradient(d, a, lane);
#pragma GCC unroll 3
          for (int b = 0; b < Dim; ++b) l[d][b][lane] += v[b] * g;
        }
      }
    });
    std::copy_n(&l[0][0][0], Dim * Dim * Width, &out[0][0][0]);
  }
}

// The motion update's sums over the nodes of each lane's stencil, from the
// nodal velocities before (now) and after (next) the grid update: v_pic =
// sum w v_next and dv = sum w (v_next - v_now). The sums start from zero.
template <bool Pairs, int Dim, class Shape, int Width>
[[gnu::always_inline]] inline void motion_sums(const double* now, const double* next,
                                               const StencilLanes<Dim, Shape, Width>& s, int lanes,
                                               double (&v_pic)[Dim][Width], double (&dv)[Dim][Width]) {
  if constexpr (Pairs && Dim == 2) {
    for (int lane = 0; lane < lanes; ++lane) {
      const double *v = now + 2 * s.first[lane], *v_new = next + 2 * s.first[lane];
      Pair pic = {}, change_sum = {};
      s.for_each_node([&](int k, const std::array<int, Dim>& a) __attribute__((always_inline)) {
        const double weight = s.weight(a, lane);
        const Pair at_new = load_pair(v_new + 2 * s.offset[k]);
        pic += weight * at_new;
        change_sum += weight * (at_new - load_pair(v + 2 * s.offset[k]));
      });
      for (int e = 0; e < 2; ++e) {
        v_pic[e][lane] = pic[e];
        dv[e][lane] = change_sum[e];
      }
    }
  } else {
    for (int lane = 0; lane < lanes; ++lane)
      for (int e = 0; e < Dim; ++e) v_pic[e][lane] = dv[e][lane] = 0;
    s.for_each_node([&](int k, const std::array<int, Dim>& a) {
      const std::ptrdiff_t offset = s.offset[k];
#pragma omp simd
      for (int lane = 0; lane < lanes; ++lane) {
        const double weight = s.weight(a, lane);
        const double *v = now + Dim * (s.first[lane] + offset), *v_new = next + Dim * (s.first[lane] + offset);
#pragma GCC unroll 3
        for (int e = 0; e < Dim; ++e) {
          v_pic[e][lane] += weight * v_new[e];
          dv[e][lane] += weight * (v_new[e] - v[e]);
        }
      }
    });
  }
}

}  // namespace outburst::mpm::gathers
