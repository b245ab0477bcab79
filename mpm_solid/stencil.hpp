#pragma once
// The grid nodes a particle talks to, with their weights and weight gradients:
// the tensor product of a 1D shape policy over Dim directions.

#include <array>

#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

template <int Dim, class Shape>
struct Stencil {
  static constexpr int support = Shape::support;
  static constexpr int count = Dim == 2 ? support * support : support * support * support;

  std::array<std::size_t, count> node;
  std::array<double, count> weight;
  std::array<Vec<Dim>, count> gradient;  // d N / d x [1/m]

  // Returns false when a node of the support lies outside the (ghost-padded) grid.
  bool compute(const Grid<Dim>& g, const Vec<Dim>& x, double half_width) {
    double w[Dim][support], dw[Dim][support];
    std::array<int, Dim> base;
    for (int d = 0; d < Dim; ++d) {
      base[d] = Shape::eval(g.grid_coordinate(x[d], d), half_width, w[d], dw[d]);
      if (base[d] < 0 || base[d] + support > g.nodes_along(d)) return false;
    }
    const double inv_h = 1.0 / g.h;
    int k = 0;
    if constexpr (Dim == 2) {
      for (int j = 0; j < support; ++j)
        for (int i = 0; i < support; ++i, ++k) {
          node[k] = g.index({base[0] + i, base[1] + j});
          weight[k] = w[0][i] * w[1][j];
          gradient[k] = Vec<Dim>(dw[0][i] * w[1][j], w[0][i] * dw[1][j]) * inv_h;
        }
    } else {
      for (int l = 0; l < support; ++l)
        for (int j = 0; j < support; ++j)
          for (int i = 0; i < support; ++i, ++k) {
            node[k] = g.index({base[0] + i, base[1] + j, base[2] + l});
            weight[k] = w[0][i] * w[1][j] * w[2][l];
            gradient[k] = Vec<Dim>(dw[0][i] * w[1][j] * w[2][l], w[0][i] * dw[1][j] * w[2][l],
                                   w[0][i] * w[1][j] * dw[2][l]) *
                          inv_h;
          }
    }
    return true;
  }
};

}  // namespace outburst::mpm
