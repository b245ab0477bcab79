// The grid's passes run over the blocks of nodes the particles reach
// (ActiveBlocks): a body on a grid four times as wide moves exactly as on the
// narrow one, and the passes cover the same nodes, not four times as many.
#include <catch2/catch.hpp>
#include <omp.h>

#include "mpm_fixtures.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

struct Run {
  Particles<2> particles;
  Energies energies;
  std::size_t active_nodes, grid_nodes;
};

// A block dropped on a fixed floor beside a fixed left wall, thrown to the
// right, for 300 steps, on a grid `width` wide with an open right side.
Run drop(double width, ShapeKind shape, Scheme scheme) {
  const Grid<2> g = grid(width, 2.0, 0.1);
  Particles<2> p = block(g, Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.8), 1000, 2);
  for (auto& v : p.v) v = Vec<2>(2.0, -1.0);
  Settings s;
  s.shape = shape;
  s.scheme = scheme;
  s.gravity = {0, -9.81};
  s.walls = {Wall{Wall::Type::fixed}, Wall{}, Wall{Wall::Type::fixed}, Wall{}};
  Solver solver(g, elastic({1000, 1e7, 0.3}), std::move(p), s);
  const double dt = solver.stable_time_step();
  for (int k = 0; k < 300; ++k) solver.step(dt);
  return {solver.particles(), solver.energies(), solver.active_nodes(), g.num_nodes()};
}

}  // namespace

TEST_CASE("a body on a wider, empty grid moves bit for bit as on a narrow one, over as many grid nodes",
          "[mpm][active grid]") {
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::gimp, ShapeKind::bspline);
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::musl);
  // One thread: with more, a wider grid shares its runs of nodes out
  // differently and the sums round differently.
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const Run narrow = drop(4.0, shape, scheme), wide = drop(16.0, shape, scheme);
  REQUIRE(narrow.particles.size() == wide.particles.size());
  for (std::size_t i = 0; i < narrow.particles.size(); ++i) {
    REQUIRE(narrow.particles.x[i] == wide.particles.x[i]);
    REQUIRE(narrow.particles.v[i] == wide.particles.v[i]);
    REQUIRE(narrow.particles.stress[i] == wide.particles.stress[i]);
  }
  CHECK(narrow.energies.total() == wide.energies.total());
  CHECK(narrow.energies.walls == wide.energies.walls);
  INFO("active nodes " << narrow.active_nodes << " of " << narrow.grid_nodes << " and " << wide.active_nodes
                       << " of " << wide.grid_nodes);
  CHECK(wide.active_nodes == narrow.active_nodes);
  CHECK(wide.active_nodes < wide.grid_nodes / 3);
  omp_set_num_threads(threads);
}
