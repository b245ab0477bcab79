// A chunk's stencils (StencilLanes, what the particle passes use) against a
// stencil per particle (Stencil, what APIC and the dilatation remedy use):
// the same nodes, weights and gradients to the bit, for every shape in 2D
// and 3D, and the same verdict on a support that leaves the ghost-padded grid;
// the runs of lanes the linear stencils scatter as one; and the gathers' two
// forms (mpm_solid/gathers.hpp) to the same bits.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "mpm_solid/gathers.hpp"
#include "mpm_solid/material.hpp"
#include "mpm_solid/shape.hpp"
#include "mpm_solid/stencil.hpp"

using namespace outburst::mpm;

namespace {

template <int Dim, class Shape>
void lanes_agree_with_particles() {
  Grid<Dim> g;
  g.h = 0.3;
  g.lower = Vec<Dim>::Constant(-1.0);
  for (int d = 0; d < Dim; ++d) g.cells[d] = 7 - d;  // a different node count along each axis
  for (int d = 0; d < Dim; ++d) g.upper[d] = g.lower[d] + g.cells[d] * g.h;
  // Positions up to 3 cells beyond the domain: some supports leave the 2
  // ghost rows.
  std::mt19937 rng(10 * Dim + Shape::support);
  std::vector<Vec<Dim>> x(203);
  std::vector<double> half_width(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int d = 0; d < Dim; ++d)
      x[i][d] = std::uniform_real_distribution<double>(g.lower[d] - 3 * g.h, g.upper[d] + 3 * g.h)(rng);
    half_width[i] = std::uniform_real_distribution<double>(0.1, 0.45)(rng);  // GIMP's, in cells
  }
  const Lattice<Dim> lattice(g);
  using Lanes = StencilLanes<Dim, Shape, 16>;
  Lanes lanes(lattice);
  const int n = static_cast<int>(x.size());
  int inside = 0, outside = 0, differ = 0;
  for (int start = 0; start < n; start += Lanes::width) {
    const int count = std::min(Lanes::width, n - start);
    // Every other chunk takes its particles backwards, as the fused pass takes
    // a material's members through an index.
    const bool backwards = start / Lanes::width % 2 == 1;
    const auto particle = [&](int lane) { return backwards ? start + count - 1 - lane : start + lane; };
    lanes.compute(x.data(), half_width.data(), particle, count);
    for (int lane = 0; lane < count; ++lane) {
      const int i = particle(lane);
      Stencil<Dim, Shape> one;
      const bool in = one.compute(lattice, x[i], half_width[i]);
      REQUIRE(lanes.inside(lane) == in);
      if (!in) {
        ++outside;
        continue;
      }
      ++inside;
      REQUIRE(lanes.lowest(lane) == one.base);
      Lanes::for_each_node([&](int k, const std::array<int, Dim>& a) {
        differ += lanes.first[lane] + lanes.offset[k] != static_cast<std::ptrdiff_t>(one.node[k]);
        differ += lanes.weight(a, lane) != one.weight[k];
        for (int d = 0; d < Dim; ++d) differ += lanes.gradient(d, a, lane) != one.gradient[d][k];
      });
    }
  }
  INFO(Shape::name << " in " << Dim << "D: " << inside << " supports inside, " << outside << " leaving");
  CHECK(inside > 50);
  CHECK(outside > 10);
  CHECK(differ == 0);
}

}  // namespace

TEST_CASE("a chunk's stencils give each particle's nodes, weights and gradients to the bit, and the same verdict "
          "on supports that leave the grid",
          "[mpm][stencil]") {
  lanes_agree_with_particles<2, Linear>();
  lanes_agree_with_particles<2, Gimp>();
  lanes_agree_with_particles<2, Bspline>();
  lanes_agree_with_particles<3, Linear>();
  lanes_agree_with_particles<3, Gimp>();
  lanes_agree_with_particles<3, Bspline>();
}

namespace {
template <class Shape>
void far_supports_are_refused() {
  Grid<2> g;
  g.h = 0.3;
  g.lower = Vec<2>::Zero();
  g.cells = {7, 6};
  g.upper = Vec<2>(7 * g.h, 6 * g.h);
  // A billion cells and more off the grid, either side, up to int's ends
  // (floor_int's range): the lowest node must land where the support check
  // refuses it, not wrap past int's end.
  const std::vector<Vec<2>> x{{-3e8, 1.0}, {3e8, 1.0}, {1.0, -6.4e8}, {1.0, 6.4e8}, {-6.4e8, 6.4e8}};
  const std::vector<double> half_width(x.size(), 0.25);
  const Lattice<2> lattice(g);
  StencilLanes<2, Shape, 16> lanes(lattice);
  lanes.compute(x.data(), half_width.data(), [](int lane) { return lane; }, static_cast<int>(x.size()));
  for (std::size_t i = 0; i < x.size(); ++i) {
    INFO(Shape::name << ", particle at " << x[i].transpose());
    CHECK_FALSE(lanes.inside(static_cast<int>(i)));
    Stencil<2, Shape> one;
    CHECK_FALSE(one.compute(lattice, x[i], half_width[i]));
  }
}
}  // namespace

TEST_CASE("supports a billion cells or more off the grid are refused, not wrapped onto it", "[mpm][stencil]") {
  far_supports_are_refused<Linear>();
  far_supports_are_refused<Gimp>();
  far_supports_are_refused<Bspline>();
}

TEST_CASE("floor_int is std::floor as an int (whole numbers, either side of them, negative and signed zeros), and "
          "near int's ends the support check refuses it",
          "[mpm][stencil]") {
  std::vector<double> xs{0.0, -0.0, 0.5, -0.5, 1e-300, -1e-300, 2147483646.5, -2147483647.5};
  for (int k = -1000; k <= 1000; ++k) {
    const double whole = 0.37 * k - (k % 7);  // whole numbers and fractions on both sides of zero
    for (const double x : {std::floor(whole), whole})
      xs.insert(xs.end(), {x, std::nextafter(x, -1e9), std::nextafter(x, 1e9)});
  }
  for (const double x : xs) {
    INFO("x = " << x);
    CHECK(floor_int(x) == static_cast<int>(std::floor(x)));
  }
  // supported() with values the compiler cannot fold: a base near int's end
  // must not wrap past the check.
  volatile int end = std::numeric_limits<int>::max(), lowest = std::numeric_limits<int>::min(), support = 3,
               nodes = 1000;
  CHECK_FALSE(supported(end, support, nodes));
  CHECK_FALSE(supported(lowest, support, nodes));
  CHECK_FALSE(supported(-1, support, nodes));
  CHECK(supported(0, support, nodes));
  CHECK(supported(nodes - support, support, nodes));
  CHECK_FALSE(supported(nodes - support + 1, support, nodes));
  // Two billion either way (the lowest int one lower wraps), the support
  // check refuses it.
  for (const double x : {-2147483647.5, -2147483648.0, -2e9, 2e9, 2147483647.0}) {
    INFO("x = " << x);
    CHECK_FALSE(supported(floor_int(x), 3, 1000));
  }
}

namespace {
// Lanes in a cell, another cell, the first again, and a support far beyond
// the grid whose flat index aliases the first cell's (a whole row of nodes
// further along x, a row lower): only the linear stencils scatter runs, and
// a run takes the lanes that follow on the same stencil inside the grid.
template <class Shape>
std::vector<int> run_ends() {
  Grid<2> g;
  g.h = 0.3;
  g.lower = Vec<2>::Zero();
  g.cells = {7, 6};
  g.upper = Vec<2>(7 * g.h, 6 * g.h);
  const Lattice<2> lattice(g);
  const double row = lattice.nodes_along[0] * g.h;
  const std::vector<Vec<2>> x{{1.0, 0.7}, {1.1, 0.8}, {0.4, 0.8}, {1.0, 0.8}, {1.1, 0.7},
                              {1.0 + row, 0.7 - g.h}, {1.05, 0.75}};
  const std::vector<double> half_width(x.size(), 0.25);
  StencilLanes<2, Shape, 16> lanes(lattice);
  const int n = static_cast<int>(x.size());
  lanes.compute(x.data(), half_width.data(), [](int lane) { return lane; }, n);
  REQUIRE_FALSE(lanes.inside(5));
  REQUIRE(lanes.first[5] == lanes.first[0]);
  std::vector<int> ends;
  for (int lane = 0; lane < n; lane = ends.back())
    ends.push_back(lanes.inside(lane) ? lanes.run_end(lane, n) : lane + 1);
  return ends;
}
}  // namespace

TEST_CASE("run_end: under linear stencils a run is the lanes that follow on one stencil inside the grid, under "
          "the others one lane",
          "[mpm][stencil]") {
  CHECK(run_ends<Linear>() == std::vector<int>{2, 3, 5, 6, 7});
  CHECK(run_ends<Gimp>() == std::vector<int>{1, 2, 3, 4, 5, 6, 7});
  CHECK(run_ends<Bspline>() == std::vector<int>{1, 2, 3, 4, 5, 6, 7});
}

namespace {
// Whether `count` entries of each lane-major row agree to the bit.
template <std::size_t Rows, int Width>
bool same_bits(const double (&a)[Rows][Width], const double (&b)[Rows][Width], int count) {
  for (std::size_t r = 0; r < Rows; ++r)
    if (std::memcmp(a[r], b[r], sizeof(double) * static_cast<std::size_t>(count)) != 0) return false;
  return true;
}

template <class Shape, int width>
void gather_forms_agree() {
  Grid<2> g;
  g.h = 0.25;
  g.lower = Vec<2>(-0.5, 1.0);
  g.cells = {9, 6};
  g.upper = Vec<2>(g.lower[0] + 9 * g.h, g.lower[1] + 6 * g.h);
  const Lattice<2> lattice(g);
  std::mt19937 rng(7 + Shape::support);
  // Velocities over six decades and both signs, so that any change in the
  // order of a sum, or in which products fuse, shows in the last bits.
  const auto value = [&] {
    return std::uniform_real_distribution<double>(-1, 1)(rng) *
           std::pow(10.0, std::uniform_real_distribution<double>(-3, 3)(rng));
  };
  std::vector<double> now(2 * static_cast<std::size_t>(lattice.nodes_along[0] * lattice.nodes_along[1])), next(now.size());
  for (std::size_t i = 0; i < now.size(); ++i) {
    now[i] = value();
    next[i] = now[i] + (i % 5 == 0 ? 0.0 : value());  // some nodes unchanged
  }
  std::vector<Vec<2>> x(203);
  std::vector<double> half_width(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int d = 0; d < 2; ++d) x[i][d] = std::uniform_real_distribution<double>(g.lower[d], g.upper[d])(rng);
    half_width[i] = std::uniform_real_distribution<double>(0.1, 0.45)(rng);
  }
  StencilLanes<2, Shape, width> s(lattice);
  int chunks = 0;
  for (int start = 0; start < static_cast<int>(x.size()); start += width, ++chunks) {
    const int lanes = std::min(width, static_cast<int>(x.size()) - start);
    s.compute(x.data(), half_width.data(), [start](int lane) { return start + lane; }, lanes);
    for (int lane = 0; lane < lanes; ++lane) REQUIRE(s.inside(lane));
    INFO(Shape::name << ", chunks of " << width << ", from particle " << start << ", " << lanes << " lanes");
    double l_lanes[2][2][width], l_pairs[2][2][width];
    gathers::velocity_gradients<false>(now.data(), s, lanes, l_lanes);
    gathers::velocity_gradients<true>(now.data(), s, lanes, l_pairs);
    CHECK(same_bits(l_lanes[0], l_pairs[0], lanes));
    CHECK(same_bits(l_lanes[1], l_pairs[1], lanes));
    double pic_lanes[2][width], dv_lanes[2][width];
    double pic_pairs[2][width], dv_pairs[2][width];
    gathers::motion_sums<false>(now.data(), next.data(), s, lanes, pic_lanes, dv_lanes);
    gathers::motion_sums<true>(now.data(), next.data(), s, lanes, pic_pairs, dv_pairs);
    CHECK(same_bits(pic_lanes, pic_pairs, lanes));
    CHECK(same_bits(dv_lanes, dv_pairs, lanes));
    // Not zero: a gather that summed nothing would agree too.
    int unchanged = 0;
    for (int lane = 0; lane < lanes; ++lane) unchanged += dv_pairs[0][lane] == 0 && dv_pairs[1][lane] == 0;
    CHECK(unchanged == 0);
  }
  CHECK(chunks == (203 + width - 1) / width);  // the last one partial
}
}  // namespace

TEST_CASE("the gathers' two forms, a chunk's particles over lanes and a node's velocity as one pair, give the same "
          "velocity gradients and motion sums to the bit",
          "[mpm][stencil]") {
  // The widths of the passes' chunks: the motion gather's, and the fused
  // update's.
  gather_forms_agree<Linear, chunk_lanes>();
  gather_forms_agree<Gimp, chunk_lanes>();
  gather_forms_agree<Bspline, chunk_lanes>();
  gather_forms_agree<Linear, chunk_size>();
  gather_forms_agree<Gimp, chunk_size>();
  gather_forms_agree<Bspline, chunk_size>();
}
