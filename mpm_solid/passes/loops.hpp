#pragma once
// The loops every pass of the MPM step runs: over the active nodes, over
// chunks of particles with their stencils, and scattering into the grid
// without locks (passes/*.cpp; not for use outside the solver).

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <type_traits>
#include <vector>

#include "mpm_solid/active_blocks.hpp"
#include "mpm_solid/particles.hpp"
#include "mpm_solid/stencil.hpp"

namespace outburst::mpm::passes {

using Runs = std::vector<NodeRun>;

// Runs f(i) over the nodes of the runs, in parallel.
template <class F>
void over_nodes(const Runs& runs, F&& f) {
  const int n = static_cast<int>(runs.size());
#pragma omp parallel for schedule(static)
  for (int r = 0; r < n; ++r)
    for (std::size_t i = runs[r].first, end = i + static_cast<std::size_t>(runs[r].count); i < end; ++i) f(i);
}

// The sum of f(i) over the nodes of the runs, in parallel.
template <class F>
double sum_over_nodes(const Runs& runs, F&& f) {
  const int n = static_cast<int>(runs.size());
  double sum = 0;
#pragma omp parallel for schedule(static) reduction(+ : sum)
  for (int r = 0; r < n; ++r)
    for (std::size_t i = runs[r].first, end = i + static_cast<std::size_t>(runs[r].count); i < end; ++i) sum += f(i);
  return sum;
}

template <class T>
T zero() {
  if constexpr (std::is_arithmetic_v<T>)
    return T(0);
  else
    return T::Zero();
}

// Scattering without locks: thread 0 adds straight into the grid field, the
// others into private copies that gather() adds in afterwards, over the
// active nodes (nothing is scattered elsewhere). buffer(t) is where thread t
// writes.
template <class T>
struct Scatter {
  std::vector<std::vector<T>>& others;  // threads 1, 2, ...
  std::vector<T>& total;
  const Runs& runs;

  void clear() {
    over_nodes(runs, [&](std::size_t i) { total[i] = zero<T>(); });
  }
  std::vector<T>& buffer(int t) { return t == 0 ? total : others[static_cast<std::size_t>(t - 1)]; }
  // Adds the other threads' copies into the total at node i, and clears them.
  void gather(std::size_t i) {
    for (auto& part : others) {
      total[i] += part[i];
      part[i] = zero<T>();
    }
  }
  void gather() {
    if (!others.empty()) over_nodes(runs, [&](std::size_t i) { gather(i); });
  }
};

// Which form the gathers' node loops take (mpm_solid/gathers.hpp; CMake's
// OUTBURST_GATHER picks it for the build).
#ifdef OUTBURST_GATHER_PAIRS
constexpr bool gather_pairs = true;
#else
constexpr bool gather_pairs = false;
#endif

// The helpers that run inside the particle loops (once per particle, or per
// chunk of them: over_chunks here, those of map_lanes.hpp and census.hpp,
// the gathers) are forced inline: called, each returned or took its
// matrices through memory, and the loop stalled reloading them whole from
// halves just stored (a store is not forwarded to a wider load): 6 % of a
// B-spline step.

// f(start, lanes) over the particles in chunks of s's width, s computed for
// each: the threads of the enclosing parallel region share the chunks.
template <int Dim, class Shape, int Width, class F>
[[gnu::always_inline]] inline void over_chunks(StencilLanes<Dim, Shape, Width>& s, const Particles<Dim>& p, F&& f) {
  const int n = static_cast<int>(p.size()), chunks = (n + Width - 1) / Width;
#pragma omp for schedule(static)
  for (int c = 0; c < chunks; ++c) {
    const int start = c * Width, lanes = std::min(Width, n - start);
    s.compute(p.x.data(), p.half_width.data(), [start](int lane) { return start + lane; }, lanes);
    f(start, lanes);
  }
}

}  // namespace outburst::mpm::passes
