#pragma once
// The layers of ghost nodes beyond the walls, and the fold of what particles
// scatter there into the mirror nodes inside (grid_update.cpp, walls.cpp; not
// for use outside the solver).

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

// What particles scatter to ghost nodes beyond a fixed or roller wall belongs,
// by symmetry, to their mirror images inside: an image particle beyond the wall
// would give the inside node exactly what the real one gives the ghost node,
// reflected. Without this the nodes next to a wall miss their images' share and
// wide shape functions (B-splines reach 1.5 cells) lose an order of accuracy.
template <int Dim>
template <class F>
void Solver<Dim>::over_layer(int axis, int row, F&& f) const {
  std::array<int, Dim> ij{};
  ij[axis] = row;
  const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;  // the other axes (b: 3D only)
  const int layers = Dim == 2 ? 1 : grid_.nodes_along(b), along = grid_.nodes_along(a);
  const std::ptrdiff_t step = grid_.stride(a);
  constexpr int size = ActiveBlocks<Dim>::size;
  for (int l = 0; l < layers; ++l) {
    if constexpr (Dim == 3) ij[b] = l;
    for (int from = 0; from < along; from += size) {
      ij[a] = from;
      if (!active_.holds(ij)) continue;
      auto i = static_cast<std::ptrdiff_t>(grid_.index(ij));
      for (int k = from; k < std::min(from + size, along); ++k, i += step) f(static_cast<std::size_t>(i));
    }
  }
}

template <int Dim>
template <class F>
void Solver<Dim>::over_ghost_layer(int side, int depth, F&& f) const {
  const int g = Grid<Dim>::ghost, axis = side / 2;
  const int outward = side % 2 == 0 ? -1 : 1;  // wall normal, out of the domain
  const int wall_row = outward < 0 ? g : g + grid_.cells[axis];
  const std::ptrdiff_t inward = -2 * depth * outward * grid_.stride(axis);
  over_layer(axis, wall_row + depth * outward, [&](std::size_t node) { f(node, node + inward); });
}

namespace passes {
// A vector at a node reflected across a fixed or roller wall normal to
// `axis`: the normal component odd, the tangential ones odd at a fixed wall
// (no slip) and even at a roller.
template <int Dim>
Vec<Dim> reflected(const Vec<Dim>& v, int axis, Wall::Type type) {
  Vec<Dim> r;
  for (int d = 0; d < Dim; ++d) r[d] = d == axis || type == Wall::Type::fixed ? -v[d] : v[d];
  return r;
}
}  // namespace passes

template <int Dim>
template <class F>
void Solver<Dim>::fold_ghosts(std::vector<double>* mass, std::vector<Vec<Dim>>& vectors, F&& refresh) const {
  for (int side = 0; side < 2 * Dim; ++side) {
    const Wall::Type type = settings_.walls[side].type;
    if (!mirrors(type)) continue;
    for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth)
      over_ghost_layer(side, depth, [&](std::size_t from, std::size_t to) {
        if (mass) (*mass)[to] += (*mass)[from];
        vectors[to] += passes::reflected<Dim>(vectors[from], side / 2, type);
        refresh(to);
      });
  }
}

}  // namespace outburst::mpm
