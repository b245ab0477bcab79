#pragma once
// Small MPM problems built in code for the verification tests.

#include <memory>
#include <type_traits>

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

// A box [0, size] of cubes of side h.
inline mpm::Grid<3> grid(const mpm::Vec<3>& size, double h) {
  mpm::Grid<3> g;
  g.h = h;
  g.lower = mpm::Vec<3>::Zero();
  for (int d = 0; d < 3; ++d) {
    g.cells[d] = static_cast<int>(std::lround(size[d] / h));
    g.upper[d] = g.cells[d] * h;
  }
  return g;
}

// A rectangular body (a box in 3D) of one material, at rest and unstressed.
template <int Dim>
mpm::Particles<Dim> block(const mpm::Grid<Dim>& g, const std::type_identity_t<mpm::Vec<Dim>>& lo,
                          const std::type_identity_t<mpm::Vec<Dim>>& hi, double density, int per_cell) {
  std::vector<mpm::Vec<Dim>> points;
  mpm::fill_cells<Dim>(g, per_cell, lo, hi, [](const mpm::Vec<Dim>&) { return true; }, points);
  mpm::Particles<Dim> p;
  const double side = g.h / per_cell, volume = Dim == 2 ? side * side : side * side * side;
  for (const auto& x : points)
    p.add(x, mpm::Vec<Dim>::Zero(), density * volume, volume, 0.5 / per_cell, mpm::Mat<Dim>::Zero(), 0, 0);
  return p;
}

template <int Dim = 2>
std::vector<std::unique_ptr<mpm::Material<Dim>>> elastic(const mpm::Elasticity& e) {
  std::vector<std::unique_ptr<mpm::Material<Dim>>> m;
  m.push_back(std::make_unique<mpm::LinearElastic<Dim>>("elastic", e));
  return m;
}

}  // namespace outburst::testing
