#pragma once
// Reads the [mpm] section of a scene: grid, walls, materials and the bodies
// that fill regions with particles. `mpm-solid SCENE --explain` lists every key.

#include <memory>
#include <optional>
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

// Particles at n x n regular positions per grid cell, kept where `inside` holds.
template <class Inside>
void fill_cells(const Grid<2>& grid, int per_cell, const Vec<2>& lo, const Vec<2>& hi, Inside inside,
                std::vector<Vec<2>>& points) {
  const double h = grid.h, step = h / per_cell;
  for (int j = 0; j < grid.cells[1]; ++j)
    for (int i = 0; i < grid.cells[0]; ++i)
      for (int b = 0; b < per_cell; ++b)
        for (int a = 0; a < per_cell; ++a) {
          const Vec<2> x = grid.lower + Vec<2>(i * h + (a + 0.5) * step, j * h + (b + 0.5) * step);
          if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all() && inside(x))
            points.push_back(x);
        }
}

}  // namespace outburst::mpm
