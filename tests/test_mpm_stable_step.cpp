// The stable step a solver gives between steps comes from the last move's
// census (no pass of its own); it must be, to the bit, what a fresh pass over
// the particles computes: a run continued from a checkpoint computes it
// afresh, and its steps must match the uninterrupted run's.
#include <catch2/catch.hpp>

#include "mpm_fixtures.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

double fresh(const Solver<2>& s) {
  return stable_time_step(s.materials(), s.particles(), s.grid().h, s.settings().courant);
}

}  // namespace

TEST_CASE("the stable step from the move's census equals a fresh pass over the particles, as particles leave",
          "[mpm][stable step]") {
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::usl, Scheme::musl);
  const bool apic = GENERATE(false, true);
  // A block thrown at the open right wall under gravity, compressed against
  // a fixed floor: velocities and densities change every step, and its front
  // leaves the grid (the fastest particles first).
  const Grid<2> g = grid(2.0, 1.0, 0.1);
  Particles<2> p = block(g, Vec<2>(1.2, 0.0), Vec<2>(1.9, 0.6), 1000, 2);
  for (std::size_t i = 0; i < p.size(); ++i) p.v[i] = Vec<2>(30.0 + 20.0 * p.x[i].x(), -5.0 * p.x[i].y());
  Settings<2> s;
  s.scheme = scheme;
  s.apic = apic;
  s.gravity = {0, -9.81};
  s.walls = {Wall{Wall::Type::roller}, Wall{}, Wall{Wall::Type::fixed}, Wall{}};
  Solver<2> solver(g, elastic({1000, 1e8, 0.3}), std::move(p), s);  // P waves of 400 m/s
  const std::size_t start = solver.particles().size();
  std::size_t removed_while_checked = 0;
  for (int k = 0; k < 200 && solver.particles().size() > start / 4; ++k) {
    const double dt = solver.stable_time_step();
    REQUIRE(dt == fresh(solver));
    removed_while_checked += solver.step(dt).removed;
  }
  INFO("particles left: " << solver.particles().size() << " of " << start);
  CHECK(removed_while_checked > 0);
  // After a restore the census is the wrong particles': a fresh pass.
  const auto state = solver.save_state();
  solver.step(solver.stable_time_step());
  solver.restore_state(state);
  CHECK(solver.stable_time_step() == fresh(solver));
}
