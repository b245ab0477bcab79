// Gravity: a column settling to its geostatic stress (and without locking when
// nearly incompressible), a step beyond the stable one under it, and a stress
// gone non-finite.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "common/program.hpp"
#include "mpm_fixtures.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

TEST_CASE("a column under gravity settles to sigma_yy = -rho g (H - y) and K0 lateral stress",
          "[mpm][gravity]") {
  const double H = 10, rho = 1000, g = 9.81, nu = 0.25;
  const Grid<2> gr = grid(1.0, 12.0, 0.25);
  Settings<2> s;
  s.shape = GENERATE(ShapeKind::gimp, ShapeKind::linear, ShapeKind::bspline);
  s.gravity = {0, -g};
  s.local_damping = 0.7;  // quasi-static: settle, then compare with the static answer
  s.walls = {Wall{Wall::Type::roller}, Wall{Wall::Type::roller}, Wall{Wall::Type::fixed}, Wall{}};
  Solver<2> solver(gr, elastic({rho, 1e8, nu}), block(gr, {0, 0}, {1, H}, rho, 2), s);
  for (int i = 0; i < 6000; ++i) solver.step(solver.stable_time_step());
  const auto& p = solver.particles();
  double sum = 0, worst_ratio = 0;
  int counted = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double exact = -rho * g * (H - p.x0[i].y());
    sum += std::pow(p.stress[i](1, 1) - exact, 2);
    // K0 = nu / (1 - nu) away from the free top, where the stress is small.
    if (p.x0[i].y() < H - 2) {
      worst_ratio = std::max(worst_ratio, std::abs(p.stress[i](0, 0) / p.stress[i](1, 1) - nu / (1 - nu)));
      ++counted;
    }
  }
  const double rms = std::sqrt(sum / static_cast<double>(p.size())) / (rho * g * H);
  std::printf("\ncolumn under gravity (shape %d): RMS |sigma_yy - rho g (H - y)| / (rho g H) = %.2e, "
              "worst |sigma_xx/sigma_yy - K0| = %.2e over %d particles, kinetic energy %.2e J/m\n",
              int(s.shape), rms, worst_ratio, counted, solver.energies().kinetic);
  CHECK(rms < 0.01);
  CHECK(worst_ratio < 0.02);
}

TEST_CASE("nodal dilatation smoothing removes the pressure checkerboard of a near-incompressible column",
          "[mpm][locking]") {
  // nu = 0.49 under gravity: without a remedy the mean stress oscillates from
  // particle to particle (volumetric locking); the static answer is smooth.
  const double H = 4, rho = 2000, g = 9.81, nu = 0.49;
  double rms[2];
  for (int remedy = 0; remedy < 2; ++remedy) {
    const Grid<2> gr = grid(1.0, 5.0, 0.125);
    Settings<2> s;
    s.shape = ShapeKind::gimp;
    s.gravity = {0, -g};
    s.local_damping = 0.7;
    s.smooth_dilatation = remedy == 1;
    s.walls = {Wall{Wall::Type::roller}, Wall{Wall::Type::roller}, Wall{Wall::Type::fixed}, Wall{}};
    Solver<2> solver(gr, elastic({rho, 1e8, nu}), block(gr, {0, 0}, {1, H}, rho, 2), s);
    for (int i = 0; i < 6000; ++i) solver.step(solver.stable_time_step());
    const auto& p = solver.particles();
    double sum = 0;
    const double k0 = nu / (1 - nu);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double syy = -rho * g * (H - p.x0[i].y());
      const double mean_exact = syy * (1 + k0) * (1 + nu) / 3;  // (sxx + syy + szz) / 3
      const double mean = (p.stress[i].trace() + p.stress_zz[i]) / 3;
      sum += std::pow(mean - mean_exact, 2);
    }
    rms[remedy] = std::sqrt(sum / static_cast<double>(p.size())) / (rho * g * H);
  }
  std::printf("\nnear-incompressible column (nu = 0.49): RMS mean-stress error / (rho g H): "
              "no remedy %.3e, nodal dilatation smoothing %.3e\n",
              rms[0], rms[1]);
  CHECK(rms[1] < 0.5 * rms[0]);
  CHECK(rms[1] < 0.02);
}

TEST_CASE("a step far beyond the stable one stops the run naming step, particle and field", "[mpm][robust]") {
  const Grid<2> gr = grid(4.0, 4.0, 0.25);
  Settings<2> s;
  s.gravity = {0, -9.81};
  s.walls[2] = {Wall::Type::fixed};
  Solver<2> solver(gr, elastic({1000, 1e7, 0.3}), block(gr, {1, 0}, {3, 2}, 1000, 2), s);
  const double dt = 5 * solver.stable_time_step() / s.courant;  // five times the CFL limit
  try {
    for (int i = 0; i < 1000; ++i) solver.step(dt);
    FAIL("the unstable run was not stopped");
  } catch (const SimulationError& e) {
    const std::string message = e.what();
    INFO(message);
    CHECK_THAT(message, Catch::Contains("mpm: step ") && Catch::Contains("particle ") &&
                            (Catch::Contains("velocity") || Catch::Contains("non-finite")));
    std::printf("\nunstable run stopped: %s\n", message.c_str());
  }
}

// Under USF a stress gone wrong in the update is named, not the positions and
// velocities its forces then spoil around it (those of lower index first).
template <int Dim>
void check_non_finite_stress_named(bool split) {
  Grid<Dim> gr;
  if constexpr (Dim == 2)
    gr = grid(4.0, 4.0, 0.25);
  else
    gr = grid(Vec<3>{2, 2, 2}, 0.25);
  Settings<Dim> s;
  s.gravity[1] = -9.81;
  s.walls[2] = {Wall::Type::fixed};
  s.smooth_dilatation = split;  // the split passes: gather, smoothing, update, forces
  Vec<Dim> lo = Vec<Dim>::Constant(0.5), hi = Vec<Dim>::Constant(1.5);
  Particles<Dim> p = block(gr, lo, hi, 1000, 2);
  // The last particle: the first ones in memory see its forces' NaN first.
  const std::size_t broken = p.size() - 1;
  p.stress[broken](0, Dim - 1) = std::numeric_limits<double>::quiet_NaN();
  Solver<Dim> solver(gr, elastic<Dim>({1000, 1e7, 0.3}), std::move(p), s);
  const int id = solver.particles().id[broken];
  CHECK_THROWS_WITH(solver.step(solver.stable_time_step()),
                    Catch::Contains("mpm: step 1 ") && Catch::Contains(fmt::format("particle {} ", id)) &&
                        Catch::Contains("non-finite stress"));
}

TEST_CASE("a non-finite stress stops the step naming it and its particle", "[mpm][robust]") {
  const bool split = GENERATE(false, true);
  INFO((split ? "split passes" : "fused pass"));
  SECTION("2D") { check_non_finite_stress_named<2>(split); }
  SECTION("3D") { check_non_finite_stress_named<3>(split); }
}

TEST_CASE("the steps' wall time is booked to their parts, in every scheme", "[mpm]") {
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::usl, Scheme::musl);
  const Grid<2> gr = grid(4.0, 4.0, 0.25);
  Settings<2> s;
  s.scheme = scheme;
  s.gravity = {0, -9.81};
  s.walls[2] = {Wall::Type::fixed};
  Solver<2> solver(gr, elastic({1000, 1e7, 0.3}), block(gr, {1, 0}, {3, 2}, 1000, 2), s);
  const double dt = solver.stable_time_step();
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 50; ++i) solver.step(dt);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const StepTimes& t = solver.step_times();
  CHECK(t.map > 0);
  CHECK(t.grid > 0);
  CHECK(t.stress > 0);
  CHECK(t.motion > 0);
  // Within the steps' time: what step() does around the kernel (the removal
  // of escaped particles) is booked to no part.
  CHECK(t.total() <= 1.01 * wall + 1e-4);
  CHECK_THAT(describe(t), Catch::StartsWith("particles to grid ") && Catch::EndsWith(" s"));
}
