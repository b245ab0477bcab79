#pragma once
// The grid nodes a particle talks to, with their weights and weight gradients:
// the tensor product of a 1D shape policy over Dim directions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "mpm_solid/grid.hpp"
#include "mpm_solid/shape.hpp"

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
    double w[Dim][support], dw[Dim][support], rel[Dim];  // dw: d w / d xi
    // The gradients' products in StencilLanes' order, (d w / d xi) times
    // 1 / h first, so that the two agree to the bit
    // (tests/test_mpm_stencil.cpp).
    const double inv_h = g.inv_h;
    for (int d = 0; d < Dim; ++d) {
      const double xi = (x[d] - g.lower[d]) * inv_h + Grid<Dim>::ghost;
      base[d] = Shape::eval(xi, half_width, w[d], dw[d]);
      rel[d] = (base[d] - xi) * g.h;
      if (!supported(base[d], support, g.nodes_along[d])) return false;
    }
    int k = 0;
    if constexpr (Dim == 2) {
      const std::size_t first = g.index({base[0], base[1]}), row = static_cast<std::size_t>(g.nodes_along[0]);
      for (int j = 0; j < support; ++j)
        for (int i = 0; i < support; ++i, ++k) {
          node[k] = first + j * row + i;
          weight[k] = w[0][i] * w[1][j];
          gradient[0][k] = dw[0][i] * inv_h * w[1][j];
          gradient[1][k] = dw[1][j] * inv_h * w[0][i];
          if constexpr (Offsets) offset[k] = Vec<Dim>(rel[0] + i * g.h, rel[1] + j * g.h);
        }
    } else {
      for (int l = 0; l < support; ++l)
        for (int j = 0; j < support; ++j)
          for (int i = 0; i < support; ++i, ++k) {
            node[k] = g.index({base[0] + i, base[1] + j, base[2] + l});
            weight[k] = w[0][i] * w[1][j] * w[2][l];
            gradient[0][k] = dw[0][i] * inv_h * w[1][j] * w[2][l];
            gradient[1][k] = dw[1][j] * inv_h * w[0][i] * w[2][l];
            gradient[2][k] = dw[2][l] * inv_h * w[0][i] * w[1][j];
            if constexpr (Offsets) offset[k] = Vec<Dim>(rel[0] + i * g.h, rel[1] + j * g.h, rel[2] + l * g.h);
          }
    }
    return true;
  }
};

// Particles per chunk of the passes over SIMD lanes: several vectors' worth,
// and few enough that a chunk's stencils and sums stay in L1 (32 measured a
// little faster than 16 in every row of mpm-benchmark, 8 slower:
// docs/performance/mpm.md#chunks-of-32-particles).
inline constexpr int chunk_lanes = 32;

// The stencils of a chunk of up to Width particles, one lane per particle:
// each direction's 1D weights, from which a node's weight and gradient are
// formed where a pass uses them, to the same bits as Stencil::compute's
// (under unit slopes a factor of -1 or 1 taken as a sign). Nothing per node
// is stored and read back, and the gathers' node loops run over the lanes,
// for the compiler to vectorise, or over a lane's nodes a pair of components
// at a time (mpm_solid/gathers.hpp; docs/performance/mpm.md#the-gathers-lanes-or-pairs
// has what each gained).
template <int Dim, class Shape, int Width = chunk_lanes>
struct StencilLanes {
  static constexpr int support = Shape::support;
  static constexpr int count = Stencil<Dim, Shape>::count;
  static constexpr int width = Width;

  const Lattice<Dim>& lattice;
  const double inv_h;
  std::array<std::ptrdiff_t, count> offset;  // of node k from the lowest node, in flat indices
  alignas(64) std::int64_t first[Width];     // flat index of each lane's lowest node
  alignas(64) int base[Dim][Width];          // grid coordinates of each lane's lowest node
  alignas(64) double w[Dim][support][Width];
  // Shapes whose d w / d xi is -1 then 1 wherever the particle sits (Linear).
  static constexpr bool unit_slopes = requires { requires Shape::unit_slopes; };
  // d w / d x [1/m]: 1 / h taken once per lane and direction, where it used
  // to be taken at every node's gradient (a product fewer per node and
  // direction in the velocity gradient and force passes:
  // docs/performance/log.md#the-mpm-kernel). Under unit slopes w times 1 / h instead (a product, as the
  // gradients' is: a division would round otherwise): a gradient's factor
  // along its own direction is then -1 / h or 1 / h, and in the plane a
  // gradient is one of these entries, signed.
  alignas(64) double dw[Dim][support][Width];

  explicit StencilLanes(const Lattice<Dim>& g) : lattice(g), inv_h(g.inv_h) {
    const std::ptrdiff_t row = g.nodes_along[0], plane = Dim == 3 ? row * g.nodes_along[1] : 0;
    for_each_node([&](int k, const std::array<int, Dim>& a) {
      offset[k] = a[0] + a[1] * row + (Dim == 3 ? a[Dim - 1] * plane : 0);
    });
  }

  // f(k, a) over the stencil's nodes in Stencil's order, a the node's place
  // along each direction.
  template <class F>
  static void for_each_node(F&& f) {
    int k = 0;
    if constexpr (Dim == 2) {
      for (int j = 0; j < support; ++j)
        for (int i = 0; i < support; ++i) f(k++, std::array<int, Dim>{i, j});
    } else {
      for (int l = 0; l < support; ++l)
        for (int j = 0; j < support; ++j)
          for (int i = 0; i < support; ++i) f(k++, std::array<int, Dim>{i, j, l});
    }
  }

  // Lanes 0 .. lanes-1 from particles particle(0), particle(1), ... of the
  // positions x and half-widths (in cells). inside() says whether each
  // lane's support lies in the ghost-padded grid: where it does not, first
  // and offset point outside the nodal arrays. The mass scatter (a step's
  // first pass, or the last step's move mapping ahead) refuses such
  // particles, and positions change only at a step's end, so the passes
  // after it read and write the nodes unchecked.
  template <class Index>
  void compute(const Vec<Dim>* x, const double* half_width, Index particle, int lanes) {
    // Locals: read through the lattice, these would be loaded again for
    // every lane, after every store into the lanes' arrays.
    const Vec<Dim> lower = lattice.lower;
    const double inv_h = this->inv_h;
    const std::array<int, Dim> nodes_along = lattice.nodes_along;
    // The directions written out (along<d>), and floor_int for std::floor:
    // as a loop, the directions left each lane's weights to scatter stores,
    // and GCC takes std::floor over lanes only without trapping math (which
    // the build now turns off, for other loops); either kept this loop
    // scalar.
    const double* position = x->data();
#pragma omp simd
    for (int lane = 0; lane < lanes; ++lane) {
      const std::ptrdiff_t i = particle(lane);
      std::int64_t flat = 0;
      [&]<int... D>(std::integer_sequence<int, D...>) {
        (along<Dim - 1 - D>(position[Dim * i + Dim - 1 - D], half_width[i], lower, inv_h, nodes_along, lane, flat),
         ...);
      }(std::make_integer_sequence<int, Dim>{});
      first[lane] = flat;
    }
  }

  // Lane `lane`'s weights along direction d, and its lowest node's place.
  template <int d>
  [[gnu::always_inline]] void along(double x, double half_width, const Vec<Dim>& lower, double inv_h,
                                    const std::array<int, Dim>& nodes_along, int lane, std::int64_t& flat) {
    const double xi = (x - lower[d]) * inv_h + Grid<Dim>::ghost;
    double wd[support], dwd[support];
    const int base = Shape::eval(xi, half_width, wd, dwd);
#pragma GCC unroll 3
    for (int a = 0; a < support; ++a) {
      w[d][a][lane] = wd[a];
      dw[d][a][lane] = (unit_slopes ? wd[a] : dwd[a]) * inv_h;
    }
    flat = flat * nodes_along[d] + base;
    this->base[d][lane] = base;
  }

  // Whether every node of the lane's support lies inside the ghost-padded
  // grid (else `first` and `offset` point outside the nodal arrays).
  bool inside(int lane) const {
    bool in = true;
    for (int d = 0; d < Dim; ++d) in = in && supported(base[d][lane], support, lattice.nodes_along[d]);
    return in;
  }
  // Whether lanes on one stencil are scattered as a run: summed in
  // registers and added to each node once, where lane after lane each
  // node's sum waited on the last lane's store. Only under linear shapes
  // (support 2), whose stencil is the particle's cell, shared by the
  // particles seeded in it. A quadratic B-spline stencil starts at the
  // nearest node's lower neighbour, so a cell's particles at 2 a side have
  // four different ones, and runs done for every shape had slowed B-splines
  // (docs/performance/mpm.md#scatters-in-runs-under-linear-shapes). GIMP's seeds do share a stencil, but with
  // runs its scatters measured slower in single runs (not kept).
  static constexpr bool runs = support == 2;

  // The end of the run of lanes from `lane` on its stencil; every lane
  // inside the grid, as all are once the mapping has refused the others.
  int run_end(int lane, int lanes) const {
    int end = lane + 1;
    if constexpr (runs)
      // inside() too: a flat index beyond the grid's rows can alias one within.
      while (end < lanes && first[end] == first[lane] && inside(end)) ++end;
    return end;
  }

  std::array<int, Dim> lowest(int lane) const {
    std::array<int, Dim> b;
    for (int d = 0; d < Dim; ++d) b[d] = base[d][lane];
    return b;
  }

  double weight(const std::array<int, Dim>& a, int lane) const {
    if constexpr (Dim == 2)
      return w[0][a[0]][lane] * w[1][a[1]][lane];
    else
      return w[0][a[0]][lane] * w[1][a[1]][lane] * w[2][a[2]][lane];
  }
  // d N / d x_d [1/m]
  double gradient(int d, const std::array<int, Dim>& a, int lane) const {
    // (-1 * (1 / h)) w is -(w (1 / h)) to the bit: rounding is symmetric in
    // the sign.
    const auto signed_along = [&](int along, double x) { return a[along] == 0 ? -x : x; };
    if constexpr (unit_slopes && Dim == 2)
      return d == 0 ? signed_along(0, dw[1][a[1]][lane]) : signed_along(1, dw[0][a[0]][lane]);
    else if constexpr (unit_slopes)
      return d == 0   ? signed_along(0, dw[1][a[1]][lane] * w[2][a[2]][lane])
             : d == 1 ? signed_along(1, dw[0][a[0]][lane] * w[2][a[2]][lane])
                      : signed_along(2, dw[0][a[0]][lane] * w[1][a[1]][lane]);
    else if constexpr (Dim == 2)
      return d == 0 ? dw[0][a[0]][lane] * w[1][a[1]][lane] : dw[1][a[1]][lane] * w[0][a[0]][lane];
    else
      return d == 0   ? dw[0][a[0]][lane] * w[1][a[1]][lane] * w[2][a[2]][lane]
             : d == 1 ? dw[1][a[1]][lane] * w[0][a[0]][lane] * w[2][a[2]][lane]
                      : dw[2][a[2]][lane] * w[0][a[0]][lane] * w[1][a[1]][lane];
  }
};

}  // namespace outburst::mpm
