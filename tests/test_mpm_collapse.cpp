// The shipped granular column collapse (a = 1) against Lube et al.'s 2D run-out
// scaling (L_inf - L0) / L0 = 1.2 a, as a sanity band: MPM with Drucker-Prager
// is not expected to match the experiment closely, but far outside the band
// something is wrong (too stiff, no friction, numerical fluidisation).
#include <catch2/catch.hpp>

#include "common/program.hpp"
#include "mpm_solid/scene_reader.hpp"

using namespace outburst;

TEST_CASE("the granular column collapses to Lube's run-out and comes to rest", "[mpm][collapse]") {
  auto doc = scene::Document::load(std::string(OUTBURST_SOURCE_DIR) + "/cases/granular_collapse/granular_collapse.toml",
                                   {"mpm.grid.cell_size=\"0.05 m\""});
  auto root = doc->root();
  const auto header = read_scene_header(root);
  auto setup = mpm::read_setup<2>(*root.table("mpm", "", true));
  doc->reject_unused();
  mpm::Solver<2> solver(setup.grid, std::move(setup.materials), std::move(setup.particles), setup.settings);
  double l0 = 0, h0 = 0;
  for (const auto& x : solver.particles().x) {
    l0 = std::max(l0, x.x());
    h0 = std::max(h0, x.y());
  }
  while (solver.time() < header.end_time)
    solver.step(std::min(solver.stable_time_step(), header.end_time - solver.time()));
  double run_out = 0, height = 0, speed = 0;
  for (std::size_t i = 0; i < solver.particles().size(); ++i) {
    run_out = std::max(run_out, solver.particles().x[i].x());
    height = std::max(height, solver.particles().x[i].y());
    speed = std::max(speed, solver.particles().v[i].norm());
  }
  const double a = h0 / l0, spread = (run_out - l0) / l0;
  std::printf("\ngranular collapse a = %.2f: (L - L0)/L0 = %.3f (Lube: %.3f), final height %.3f of %.3f m, "
              "fastest particle %.3g m/s\n",
              a, spread, 1.2 * a, height, h0, speed);
  CHECK(spread > 0.5 * 1.2 * a);
  CHECK(spread < 2.0 * 1.2 * a);
  CHECK(height < h0);
  CHECK(speed < 0.05);  // at rest
  CHECK(solver.removed_particles() == 0);
}
