#pragma once
// Small MPM problems built in code for the verification tests.

#include <memory>

#include "mpm_solid/materials/elastic.hpp"
#include "mpm_solid/scene_reader.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::testing {

inline mpm::Grid<2> grid(double width, double height, double h) {
  mpm::Grid<2> g;
  g.h = h;
  g.lower = {0, 0};
  g.cells = {static_cast<int>(std::lround(width / h)), static_cast<int>(std::lround(height / h))};
  g.upper = {g.cells[0] * h, g.cells[1] * h};
  return g;
}

// A rectangular body of one elastic material.
inline mpm::Particles<2> block(const mpm::Grid<2>& g, const mpm::Vec<2>& lo, const mpm::Vec<2>& hi,
                               double density, int per_cell) {
  std::vector<mpm::Vec<2>> points;
  mpm::fill_cells(g, per_cell, lo, hi, [](const mpm::Vec<2>&) { return true; }, points);
  mpm::Particles<2> p;
  const double volume = (g.h / per_cell) * (g.h / per_cell);
  for (const auto& x : points)
    p.add(x, mpm::Vec<2>::Zero(), density * volume, volume, 0.5 / per_cell, mpm::Mat<2>::Zero(), 0, 0);
  return p;
}

inline std::vector<std::unique_ptr<mpm::Material>> elastic(const mpm::Elasticity& e) {
  std::vector<std::unique_ptr<mpm::Material>> m;
  m.push_back(std::make_unique<mpm::LinearElastic>("elastic", e));
  return m;
}

}  // namespace outburst::testing
