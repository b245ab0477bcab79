#pragma once
// Reads the [mpm] section of a scene: grid, walls, materials and the bodies
// that fill regions with particles. `mpm-solid SCENE --explain` lists every key.
// A scene is 2D (plane strain) or 3D as its grid's size has two or three
// components; every vector key then takes as many.

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

template <int Dim>
struct Setup {
  Grid<Dim> grid;
  std::vector<std::unique_ptr<Material<Dim>>> materials;
  Particles<Dim> particles;
  Settings<Dim> settings;
  std::optional<double> fixed_time_step;  // [s]; otherwise the CFL step each step
  std::vector<int> tracers;               // particle ids whose histories are written
  Settling settling;                      // the quasi-static stage before t = 0
};

// The dimension of the scene: the number of components of [mpm.grid] size
// (2 or 3; anything else is refused there).
int scene_dimension(const scene::Table& mpm);

template <int Dim>
Setup<Dim> read_setup(const scene::Table& mpm);

// How far the box [lo, hi] reaches past the grid, as "2 m past the grid's
// right edge (x = 45 m)"; empty when it lies inside.
template <int Dim>
std::string overhang(const Grid<Dim>& grid, const Vec<Dim>& lo, const Vec<Dim>& hi);

// Refuses, at mpm.courant (or mpm.time_step), a run of more steps than any
// run may take, estimated from the stable step at the start.
template <int Dim>
void check_run_length(const scene::Table& mpm, const Setup<Dim>& setup, double end_time);
// Refuses, at mpm.time_step, a fixed step beyond the particles' stable step
// h / (c + |v|): every program checks it before --check returns.
template <int Dim>
void check_time_step(const scene::Table& mpm, const Setup<Dim>& setup);

// Particles at n x n (x n) regular positions per grid cell, kept where
// `inside` holds.
template <int Dim, class Inside>
void fill_cells(const Grid<Dim>& grid, int per_cell, const Vec<Dim>& lo, const Vec<Dim>& hi, Inside inside,
                std::vector<Vec<Dim>>& points) {
  const double h = grid.h, step = h / per_cell;
  // Only the cells [lo, hi] touches: a small body on a big grid is filled in no time.
  const auto cells_between = [&](int d) {
    const auto at = [&](double x) { return static_cast<int>(std::clamp(x, 0.0, static_cast<double>(grid.cells[d]))); };
    return std::pair{at(std::floor((lo[d] - grid.lower[d]) / h)), at(std::ceil((hi[d] - grid.lower[d]) / h))};
  };
  const auto [i0, i1] = cells_between(0);
  const auto [j0, j1] = cells_between(1);
  const auto [k0, k1] = Dim == 3 ? cells_between(Dim - 1) : std::pair{0, 1};
  const int per_cell_z = Dim == 3 ? per_cell : 1;
  for (int k = k0; k < k1; ++k)
    for (int j = j0; j < j1; ++j)
      for (int i = i0; i < i1; ++i)
        for (int c = 0; c < per_cell_z; ++c)
          for (int b = 0; b < per_cell; ++b)
            for (int a = 0; a < per_cell; ++a) {
              // One rounding order, written out: left to the compiler's choice of
              // contraction into FMA, the seeds moved by an ulp whenever inlining
              // around this loop changed, and the chaotic outburst with them.
              Vec<Dim> offset;
              offset[0] = std::fma(i, h, (a + 0.5) * step);
              offset[1] = std::fma(j, h, (b + 0.5) * step);
              if constexpr (Dim == 3) offset[2] = std::fma(k, h, (c + 0.5) * step);
              const Vec<Dim> x = grid.lower + offset;
              if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all() && inside(x))
                points.push_back(x);
            }
}

}  // namespace outburst::mpm
