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

// The OpenMP thread count for a scope (a solver takes it when built).
struct ThreadsFor {
  int before = omp_get_max_threads();
  explicit ThreadsFor(int n) { omp_set_num_threads(n); }
  ~ThreadsFor() { omp_set_num_threads(before); }
};

// The same particles, bit for bit: positions, velocities and stresses.
void require_same(const Particles<2>& a, const Particles<2>& b) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    REQUIRE(a.x[i] == b.x[i]);
    REQUIRE(a.v[i] == b.v[i]);
    REQUIRE(a.stress[i] == b.stress[i]);
  }
}

struct Run {
  Particles<2> particles;
  Energies energies;
  std::size_t active_nodes, grid_nodes;
};

// A block dropped on a fixed floor beside a fixed left wall, thrown to the
// right, for 300 steps, on a grid `width` wide with an open right side, into
// rigid steps on the floor as wide as the grid, overlapping each other and
// the floor's row, most of whose nodes lie in blocks no particle reaches.
Run drop(double width, ShapeKind shape, Scheme scheme) {
  const Grid<2> g = grid(width, 2.0, 0.1);
  Particles<2> p = block(g, Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.8), 1000, 2);
  for (auto& v : p.v) v = Vec<2>(2.0, -1.0);
  Settings<2> s;
  s.shape = shape;
  s.scheme = scheme;
  s.gravity = {0, -9.81};
  s.walls = {Wall{Wall::Type::fixed}, Wall{}, Wall{Wall::Type::fixed}, Wall{}};
  s.obstacles.push_back({Vec<2>(1.05, 0.0), Vec<2>(width, 0.1), Wall{Wall::Type::friction, 0.3}, false});
  s.obstacles.push_back({Vec<2>(1.1, 0.0), Vec<2>(width - 0.2, 0.15), Wall{Wall::Type::roller}, false});
  Solver<2> solver(g, elastic({1000, 1e7, 0.3}), std::move(p), s);
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
  const ThreadsFor one(1);
  const Run narrow = drop(4.0, shape, scheme), wide = drop(16.0, shape, scheme);
  require_same(narrow.particles, wide.particles);
  CHECK(narrow.energies.total() == wide.energies.total());
  CHECK(narrow.energies.walls == wide.energies.walls);
  INFO("active nodes " << narrow.active_nodes << " of " << narrow.grid_nodes << " and " << wide.active_nodes
                       << " of " << wide.grid_nodes);
  CHECK(wide.active_nodes == narrow.active_nodes);
  CHECK(wide.active_nodes < wide.grid_nodes / 3);
}

TEST_CASE("between steps every nodal value outside the active blocks is zero, on two threads, whatever the walls",
          "[mpm][active grid]") {
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::usl, Scheme::musl);
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::bspline);
  const Wall::Type left = GENERATE(Wall::Type::fixed, Wall::Type::roller, Wall::Type::friction, Wall::Type::open);
  const ThreadsFor two(2);
  // A thin domain (its walls' strips span blocks), 61 cells wide (no whole
  // number of blocks), a body thrown left along the floor into the left wall,
  // over a rigid step and under a platen pushing down on its top.
  const Grid<2> g = grid(6.1, 0.7, 0.1);
  Particles<2> p = block(g, Vec<2>(0.3, 0.0), Vec<2>(2.3, 0.5), 1000, 2);
  for (auto& v : p.v) v = Vec<2>(-1.0, 0.2);
  Settings<2> s;
  s.scheme = scheme;
  s.shape = shape;
  s.gravity = {0, -9.81};
  s.smooth_dilatation = scheme == Scheme::usl;
  s.walls = {Wall{left, 0.3}, Wall{Wall::Type::roller}, Wall{Wall::Type::fixed}, Wall{Wall::Type::roller}};
  s.obstacles.push_back({Vec<2>(4.0, 0.0), Vec<2>(4.5, 0.2), Wall{Wall::Type::friction, 0.4}, false});
  s.platens.push_back({Vec<2>(0.0, 0.5), Vec<2>(1.0, 0.6), 1, -1e3, std::nullopt});
  Solver<2> solver(g, elastic({1000, 1e7, 0.3}), std::move(p), s);
  for (int k = 0; k < 200; ++k) {
    solver.step(solver.stable_time_step());
    INFO("step " << k + 1);
    REQUIRE(solver.stray_nodal_values() == 0);
  }
  CHECK(solver.active_nodes() < g.num_nodes());
}

TEST_CASE("a body crossing blocks leaves no velocity behind in the blocks it left, on two threads",
          "[mpm][active grid]") {
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::usl, Scheme::musl);
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::bspline);
  const ThreadsFor two(2);
  // A block 0.5 m wide flying right through open space, 1.6 m in 200 steps
  // (two blocks of 8 nodes at h = 0.1 m): the grid's velocities, written only
  // where the mapping reaches, must be cleared where it no longer does.
  const Grid<2> g = grid(4.0, 1.0, 0.1);
  Particles<2> p = block(g, Vec<2>(0.2, 0.2), Vec<2>(0.7, 0.7), 1000, 2);
  for (auto& v : p.v) v = Vec<2>(40.0, 0.0);
  Settings<2> s;
  s.scheme = scheme;
  s.shape = shape;
  Solver<2> solver(g, elastic({1000, 1e7, 0.3}), std::move(p), s);
  const double start = solver.particles().x[0].x();
  const double dt = 2e-4;
  for (int k = 0; k < 200; ++k) {
    solver.step(dt);
    INFO("step " << k + 1);
    REQUIRE(solver.stray_nodal_values() == 0);
  }
  CHECK(solver.particles().x[0].x() - start > 1.5);
}

namespace {

// A block thrown right under gravity along a fixed floor, out of the grid's
// open right side (particles leave from about step 20), under USF.
Solver<2> thrown(ShapeKind shape) {
  const Grid<2> g = grid(2.0, 1.0, 0.1);
  Particles<2> p = block(g, Vec<2>(1.2, 0.0), Vec<2>(1.9, 0.5), 1000, 2);
  for (auto& v : p.v) v = Vec<2>(20.0, 1.0);
  Settings<2> s;
  s.shape = shape;
  s.gravity = {0, -9.81};
  s.walls = {Wall{Wall::Type::fixed}, Wall{}, Wall{Wall::Type::fixed}, Wall{}};
  return Solver<2>(g, elastic({1000, 1e7, 0.3}), std::move(p), s);
}

}  // namespace

TEST_CASE("USF's move maps the next step's mass and momentum as a fresh mapping would, and maps again after a change",
          "[mpm][active grid]") {
  // GIMP's stencils read the particles' half-widths too.
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::gimp, ShapeKind::bspline);
  const ThreadsFor two(2);
  const double dt = 2.5e-4;  // 0.3 of a cell over the P wave
  const int steps = 80;
  // Each step of `fresh` starts from a restored state: a mapping afresh.
  Solver<2> ahead = thrown(shape), fresh = thrown(shape);
  std::size_t removed = 0;
  for (int k = 0; k < steps; ++k) {
    removed += ahead.step(dt).removed;
    fresh.step(dt);
    fresh.restore_state(fresh.save_state());
    INFO("step " << k + 1);
    REQUIRE(ahead.stray_nodal_values() == 0);
  }
  CHECK(removed > 0);  // the removals' mapping again is checked
  require_same(ahead.particles(), fresh.particles());

  // Back to an earlier state, the steps are the first run's again: nothing
  // of the later state's mapping is left. Before any particle leaves, so
  // that only the restore can make the mapping afresh.
  Solver<2> back = thrown(shape);
  const int early = 10;
  for (int k = 0; k < early; ++k) REQUIRE(back.step(dt).removed == 0);
  const auto before = back.save_state();
  for (int k = 0; k < 10; ++k) back.step(dt);
  back.restore_state(before);
  for (int k = early; k < steps; ++k) back.step(dt);
  require_same(ahead.particles(), back.particles());

  // The settling stage ends with the particles at rest: the dynamic stage's
  // first step maps their momentum afresh, zero.
  Solver<2> settled = thrown(shape), settled_fresh = thrown(shape);
  for (Solver<2>* s : {&settled, &settled_fresh}) s->settle({0.01, 0.8}, dt);
  settled_fresh.restore_state(settled_fresh.save_state());
  for (int k = 0; k < 10; ++k) {
    settled.step(dt);
    settled_fresh.step(dt);
  }
  require_same(settled.particles(), settled_fresh.particles());
}
