#pragma once
// The scatter of particles' mass and momentum to their stencils' nodes, a
// chunk of lanes at a time: the step's first pass (scatter.cpp) and, under
// USF, the move mapping the next step's (motion.cpp).

#include <array>
#include <cstdint>

#include "mpm_solid/active_blocks.hpp"
#include "mpm_solid/particles.hpp"
#include "mpm_solid/stencil.hpp"

namespace outburst::mpm::passes {

// Scatters the mass and momentum of particles start .. start + lanes - 1,
// whose stencils s holds, into m and mv, and marks the blocks they reach;
// returns how many lie beyond the ghost nodes (not mapped). A run of lanes
// on one stencil (StencilLanes::runs) is summed in registers, then added;
// elsewhere each lane adds straight into the nodes, as before the runs.
template <int Dim, class Shape, int Width>
[[gnu::always_inline]] inline long map_lanes(const Particles<Dim>& p, const StencilLanes<Dim, Shape, Width>& s,
                                             int start, int lanes, double* m, Vec<Dim>* mv, std::uint8_t* reached,
                                             const std::array<int, Dim - 1>& strides) {
  using Lanes = StencilLanes<Dim, Shape, Width>;
  // add(k, w m, w m v) at node k of the lane's stencil.
  const auto each_node = [&](int lane, auto&& add) __attribute__((always_inline)) {
    const int i = start + lane;
    const double mass = p.mass[i];
    const Vec<Dim> v = p.v[i];
    s.for_each_node([&](int k, const std::array<int, Dim>& a) {
      const double wm = s.weight(a, lane) * mass;
      add(k, wm, Vec<Dim>(wm * v));
    });
  };
  long outside = 0;
  for (int lane = 0; lane < lanes;) {
    if (!s.inside(lane)) {
      ++outside;
      ++lane;
      continue;
    }
    ActiveBlocks<Dim>::template set_reached<Shape::support>(reached, strides, s.lowest(lane));
    double* m_at = m + s.first[lane];
    Vec<Dim>* mv_at = mv + s.first[lane];
    if constexpr (Lanes::runs) {
      double mass_sum[Lanes::count] = {};
      Vec<Dim> momentum_sum[Lanes::count];
      for (auto& v : momentum_sum) v.setZero();
      for (const int end = s.run_end(lane, lanes); lane < end; ++lane)
        each_node(lane, [&](int k, double wm, const Vec<Dim>& wmv) {
          mass_sum[k] += wm;
          momentum_sum[k] += wmv;
        });
      for (int k = 0; k < Lanes::count; ++k) {
        m_at[s.offset[k]] += mass_sum[k];
        mv_at[s.offset[k]] += momentum_sum[k];
      }
    } else {
      each_node(lane++, [&](int k, double wm, const Vec<Dim>& wmv) {
        m_at[s.offset[k]] += wm;
        mv_at[s.offset[k]] += wmv;
      });
    }
  }
  return outside;
}

}  // namespace outburst::mpm::passes
