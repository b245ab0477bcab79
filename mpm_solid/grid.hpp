#pragma once
// The fixed background grid: square cells of size h over the physical domain,
// padded by `ghost` cells on each side so that wide shape functions (GIMP,
// B-splines) of particles near a wall still find all their nodes. Particles
// are located by arithmetic, never by search.

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

namespace outburst::mpm {

template <int Dim>
using Vec = Eigen::Matrix<double, Dim, 1>;
template <int Dim>
using Mat = Eigen::Matrix<double, Dim, Dim>;

template <int Dim>
struct Grid {
  static constexpr int ghost = 2;

  Vec<Dim> lower;              // physical domain [lower, upper]
  Vec<Dim> upper;
  double h = 1;                // cell size
  std::array<int, Dim> cells;  // physical cells per direction

  // Nodes per direction including ghosts.
  int nodes_along(int d) const { return cells[d] + 1 + 2 * ghost; }
  std::size_t num_nodes() const {
    std::size_t n = 1;
    for (int d = 0; d < Dim; ++d) n *= static_cast<std::size_t>(nodes_along(d));
    return n;
  }
  // How far apart in the flat index two nodes neighbouring along axis d lie.
  std::ptrdiff_t stride(int d) const {
    std::ptrdiff_t s = 1;
    for (int e = 0; e < d; ++e) s *= nodes_along(e);
    return s;
  }
  // Flat index of the node with integer grid coordinates i.
  std::size_t index(const std::array<int, Dim>& i) const {
    std::size_t flat = 0;
    for (int d = Dim - 1; d >= 0; --d) flat = flat * static_cast<std::size_t>(nodes_along(d)) + i[d];
    return flat;
  }
  Vec<Dim> node_position(const std::array<int, Dim>& i) const {
    Vec<Dim> x;
    for (int d = 0; d < Dim; ++d) x[d] = lower[d] + (i[d] - ghost) * h;
    return x;
  }
  bool inside(const Vec<Dim>& x) const {
    return (x.array() >= lower.array()).all() && (x.array() <= upper.array()).all();
  }
};

}  // namespace outburst::mpm
