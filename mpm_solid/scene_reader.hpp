#pragma once
// Reads the [mpm] section of a scene: grid, walls, materials and the bodies
// that fill regions with particles. `mpm-solid SCENE --explain` lists every key.

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <optional>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

struct Setup {
  Grid<2> grid;
  std::vector<std::unique_ptr<Material>> materials;
  Particles<2> particles;
  Settings settings;
  std::optional<double> fixed_time_step;  // [s]; otherwise the CFL step each step
  std::vector<int> tracers;               // particle ids whose histories are written
  Settling settling;                      // the quasi-static stage before t = 0
};

Setup read_setup(const scene::Table& mpm);

// How far the box [lo, hi] reaches past the grid, as "2 m past the grid's
// right edge (x = 45 m)"; empty when it lies inside.
std::string overhang(const Grid<2>& grid, const Vec<2>& lo, const Vec<2>& hi);

// Refuses, at mpm.courant (or mpm.time_step), a run of more steps than any
// run may take, estimated from the stable step at the start.
void check_run_length(const scene::Table& mpm, const Setup& setup, double end_time);
// Refuses, at mpm.time_step, a fixed step beyond the particles' stable step
// h / (c + |v|): every program checks it before --check returns.
void check_time_step(const scene::Table& mpm, const Setup& setup);

// Particles at n x n regular positions per grid cell, kept where `inside` holds.
template <class Inside>
void fill_cells(const Grid<2>& grid, int per_cell, const Vec<2>& lo, const Vec<2>& hi, Inside inside,
                std::vector<Vec<2>>& points) {
  const double h = grid.h, step = h / per_cell;
  // Only the cells [lo, hi] touches: a small body on a big grid is filled in no time.
  const auto cells_between = [&](int d) {
    const auto at = [&](double x) { return static_cast<int>(std::clamp(x, 0.0, static_cast<double>(grid.cells[d]))); };
    return std::pair{at(std::floor((lo[d] - grid.lower[d]) / h)), at(std::ceil((hi[d] - grid.lower[d]) / h))};
  };
  const auto [i0, i1] = cells_between(0);
  const auto [j0, j1] = cells_between(1);
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i)
      for (int b = 0; b < per_cell; ++b)
        for (int a = 0; a < per_cell; ++a) {
          // One rounding order, written out: left to the compiler's choice of
          // contraction into FMA, the seeds moved by an ulp whenever inlining
          // around this loop changed, and the chaotic outburst with them.
          const Vec<2> x = grid.lower + Vec<2>(std::fma(i, h, (a + 0.5) * step), std::fma(j, h, (b + 0.5) * step));
          if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all() && inside(x))
            points.push_back(x);
        }
}

}  // namespace outburst::mpm
