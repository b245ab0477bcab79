#pragma once
// The grid nodes a particle talks to, with their weights and weight gradients:
// the tensor product of a 1D shape policy over Dim directions.

#include <array>

#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

// The grid's numbers a stencil needs, taken into a particle loop's locals
// once per pass. Read through the grid instead, they would be loaded again
// for every particle, and 1 / h divided again: the loop's stores into the
// nodal and particle arrays might, for all the compiler knows, change them.
template <int Dim>
struct Lattice {
  Vec<Dim> lower;
  double h, inv_h;
  std::array<int, Dim> nodes_along;  // ghosts included
  explicit Lattice(const Grid<Dim>& g) : lower(g.lower), h(g.h), inv_h(1.0 / g.h) {
    for (int d = 0; d < Dim; ++d) nodes_along[d] = g.nodes_along(d);
  }
  std::size_t index(const std::array<int, Dim>& i) const {
    std::size_t flat = 0;
    for (int d = Dim - 1; d >= 0; --d) flat = flat * static_cast<std::size_t>(nodes_along[d]) + i[d];
    return flat;
  }
};

template <int Dim, class Shape>
struct Stencil {
  static constexpr int support = Shape::support;
  static constexpr int count = Dim == 2 ? support * support : support * support * support;

  std::array<std::size_t, count> node;
  std::array<double, count> weight;
  // d N / d x_d [1/m], one array per direction: kernels read them as scalars,
  // and scalars written as scalars forward to their loads without a stall.
  std::array<std::array<double, count>, Dim> gradient;
  std::array<Vec<Dim>, count> offset;    // x_node - x_particle [m], only with Offsets
  std::array<int, Dim> base;             // grid coordinates of the lowest node

  // Returns false when a node of the support lies outside the (ghost-padded) grid.
  template <bool Offsets = false>
  bool compute(const Lattice<Dim>& g, const Vec<Dim>& x, double half_width) {
    double w[Dim][support], dw[Dim][support], rel[Dim];
    const double inv_h = g.inv_h;
    for (int d = 0; d < Dim; ++d) {
      const double xi = (x[d] - g.lower[d]) * inv_h + Grid<Dim>::ghost;
      base[d] = Shape::eval(xi, half_width, w[d], dw[d]);
      rel[d] = (base[d] - xi) * g.h;
      if (base[d] < 0 || base[d] + support > g.nodes_along[d]) return false;
    }
    int k = 0;
    if constexpr (Dim == 2) {
      const std::size_t first = g.index({base[0], base[1]}), row = static_cast<std::size_t>(g.nodes_along[0]);
      for (int j = 0; j < support; ++j)
        for (int i = 0; i < support; ++i, ++k) {
          node[k] = first + j * row + i;
          weight[k] = w[0][i] * w[1][j];
          gradient[0][k] = dw[0][i] * w[1][j] * inv_h;
          gradient[1][k] = w[0][i] * dw[1][j] * inv_h;
          if constexpr (Offsets) offset[k] = Vec<Dim>(rel[0] + i * g.h, rel[1] + j * g.h);
        }
    } else {
      for (int l = 0; l < support; ++l)
        for (int j = 0; j < support; ++j)
          for (int i = 0; i < support; ++i, ++k) {
            node[k] = g.index({base[0] + i, base[1] + j, base[2] + l});
            weight[k] = w[0][i] * w[1][j] * w[2][l];
            gradient[0][k] = dw[0][i] * w[1][j] * w[2][l] * inv_h;
            gradient[1][k] = w[0][i] * dw[1][j] * w[2][l] * inv_h;
            gradient[2][k] = w[0][i] * w[1][j] * dw[2][l] * inv_h;
            if constexpr (Offsets) offset[k] = Vec<Dim>(rel[0] + i * g.h, rel[1] + j * g.h, rel[2] + l * g.h);
          }
    }
    return true;
  }
};

}  // namespace outburst::mpm
