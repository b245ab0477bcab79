// Loads and damping: a surface traction, and viscous damping with what it books.
#include <catch2/catch.hpp>

#include <cmath>

#include "common/program.hpp"
#include "mpm_fixtures.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

TEST_CASE("a traction on the top surface loads the block to sigma_yy = -t", "[mpm][traction]") {
  // Read through the scene reader, as a user writes it.
  auto doc = scene::Document::parse(R"toml(
[scene]
solvers = ["mpm"]
end_time = "1 s"
[mpm]
shape = "gimp"
local_damping = 0.7
tracers = [["0.5 m", "1.9 m"]]
[mpm.grid]
size = ["1 m", "2.5 m"]
cell_size = "0.1 m"
[mpm.walls]
left = "roller"
right = "roller"
bottom = "fixed"
[[mpm.materials]]
name = "rock"
density = "2500 kg/m3"
youngs_modulus = "1 GPa"
poisson_ratio = 0.25
[[mpm.bodies]]
material = "rock"
box_min = ["0 m", "0 m"]
box_max = ["1 m", "2 m"]
[[mpm.tractions]]
box_min = ["0 m", "1.5 m"]
box_max = ["1 m", "2 m"]
surface = "up"
traction = ["0 Pa", "-1.5 MPa"]
)toml",
                                    "traction.toml");
  auto root = doc->root();
  read_scene_header(root);
  auto setup = read_setup<2>(*root.table("mpm", "", true));
  doc->reject_unused();
  REQUIRE(setup.tracers.size() == 1);
  Solver<2> solver(setup.grid, std::move(setup.materials), std::move(setup.particles), setup.settings);
  for (int i = 0; i < 3000; ++i) solver.step(solver.stable_time_step());
  // The load acts on the top particles and spreads through the top cell: the
  // particles in that cell carry part of it; below, the stress is uniform.
  double worst = 0;
  for (std::size_t i = 0; i < solver.particles().size(); ++i)
    if (solver.particles().x0[i].y() < 2 - 0.1)
      worst = std::max(worst, std::abs(solver.particles().stress[i](1, 1) + 1.5e6));
  std::printf("\ntop traction 1.5 MPa: worst |sigma_yy + t| = %.3g Pa below the loaded cell\n", worst);
  CHECK(worst < 0.01 * 1.5e6);
}

TEST_CASE("viscous damping slows a drifting block as exp(-c t) and books what it takes", "[mpm][damping]") {
  const double c = 5.0, v0 = 2.0, t_end = 0.2;
  const Grid<2> gr = grid(4.0, 2.0, 0.1);
  Settings<2> s;
  s.viscous_damping = c;
  auto particles = block(gr, {1.0, 0.5}, {1.5, 1.0}, 1000, 2);
  for (auto& v : particles.v) v = Vec<2>(v0, 0);
  Solver<2> solver(gr, elastic({1000, 5e7, 0.3}), std::move(particles), s);
  const double start = solver.energies().total();
  while (solver.time() < t_end) solver.step(std::min(solver.stable_time_step(), t_end - solver.time()));
  const auto& p = solver.particles();
  double v = 0;
  for (const auto& vi : p.v) v += vi.x() / static_cast<double>(p.size());
  const Energies e = solver.energies();
  std::printf("\nviscous damping: velocity %.5f m/s (exp(-c t) v0 = %.5f), damping %.4g J/m, balance error %.2e of "
              "the initial kinetic energy\n",
              v, v0 * std::exp(-c * t_end), e.damping, (e.total() - start) / start);
  CHECK(v == Approx(v0 * std::exp(-c * t_end)).epsilon(0.01));
  CHECK(std::abs(e.total() - start) < 1e-2 * start);
}
