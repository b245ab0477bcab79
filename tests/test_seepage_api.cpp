// The driving API: point queries, save/restore, the gas balance, and hard steps.
#include <catch2/catch.hpp>

#include <cmath>

#include "seepage_fixtures.hpp"

using namespace outburst;
using namespace outburst::testing;

TEST_CASE("pressure and its gradient at arbitrary points reproduce a linear field exactly",
          "[seepage][api]") {
  // Steady linear flow between two fixed pressures: p is linear in x (linear law).
  auto s = rectangle_solver(seepage::Law::linear, {4, 2}, {7, 3}, {1e-12, 1e-9, 0.0},
                            {fixed_pressure("left", 2e6), fixed_pressure("right", 1e6)});
  for (int i = 0; i < 5; ++i) s.advance(1e9);
  for (double x : {0.0, 0.3, 1.7, 2.0, 3.99, 4.0})
    for (double y : {0.0, 0.41, 2.0}) {
      CHECK(*s.pressure_at({x, y}) == Approx(2e6 - 0.25e6 * x).epsilon(1e-10));
      const Eigen::Vector2d g = *s.pressure_gradient_at({x, y});
      CHECK(g.x() == Approx(-0.25e6).epsilon(1e-9));
      CHECK(std::abs(g.y()) < 1e-3);
    }
  CHECK_FALSE(s.pressure_at({4.5, 1.0}));
  CHECK_FALSE(s.pressure_gradient_at({1.0, -0.5}));
}

TEST_CASE("the gas law's p gradient is grad(P) / 2p", "[seepage][api]") {
  // P linear in x: P = P_left + (P_right - P_left) x / L at steady state.
  const double pl = 3e6, pr = 1e6, L = 5;
  auto s = rectangle_solver(seepage::Law::gas, {L, 1}, {10, 2}, {1e-17, 2e-3, pr},
                            {fixed_pressure("left", pl), fixed_pressure("right", pr)});
  for (int i = 0; i < 8; ++i) s.advance(1e8);
  const double x = 1.3;
  const double P = pl * pl + (pr * pr - pl * pl) * x / L;
  CHECK(*s.pressure_at({x, 0.5}) == Approx(std::sqrt(P)).epsilon(1e-9));
  CHECK(s.pressure_gradient_at({x, 0.5})->x() ==
        Approx((pr * pr - pl * pl) / L / (2 * std::sqrt(P))).epsilon(1e-8));
}

TEST_CASE("restoring a saved state reproduces the run bit for bit", "[seepage][api]") {
  auto s = rectangle_solver(seepage::Law::gas, {10, 1}, {40, 2}, {1e-17, 2e-3, 3e6},
                            {fixed_pressure("left", 1e5)});
  s.advance(3600);
  s.advance(7200);  // BDF2 now carries two time levels
  const auto saved = s.save_state();
  s.advance(7200);
  const Eigen::VectorXd first = s.unknown();
  const double released = s.balance().total_outflow();
  // A coupling sub-iteration might change the conductivity before rolling back.
  std::vector<double> other(s.mesh().num_cells(), 5e-17);
  s.set_conductivity(other);
  s.advance(100);
  s.restore_state(saved);
  CHECK(s.time() == 10800);
  s.advance(7200);
  CHECK((s.unknown() - first).lpNorm<Eigen::Infinity>() == 0.0);
  CHECK(s.balance().total_outflow() == released);
}

TEST_CASE("stored gas plus what crossed the boundary stays constant", "[seepage][api][balance]") {
  // Time-varying face pressure, an injected flux on the far side and uneven steps,
  // under both time schemes and both nonlinear methods.
  for (auto scheme : {seepage::TimeScheme::backward_euler, seepage::TimeScheme::bdf2})
    for (auto method : {seepage::NonlinearMethod::newton, seepage::NonlinearMethod::picard}) {
      seepage::Settings settings;
      settings.scheme = scheme;
      settings.method = method;
      settings.max_iterations = 200;
      const seepage::BoundaryCondition face{
          "left", seepage::BoundaryCondition::Type::pressure,
          TimeFunction({{0.0, 3e6}, {3600.0, 1e5}, {20000.0, 5e5}})};
      const seepage::BoundaryCondition inflow{"right", seepage::BoundaryCondition::Type::flux,
                                              TimeFunction(1e-6)};
      auto s = rectangle_solver(seepage::Law::gas, {10, 2}, {30, 4}, {1e-17, 2e-3, 3e6},
                                {face, inflow}, settings, {5.0, 1.0});
      double dt = 60;
      for (int i = 0; i < 30; ++i) {
        s.advance(dt);
        dt *= (i % 3 == 0) ? 0.7 : 1.6;
        const auto& b = s.balance();
        REQUIRE(std::abs(b.error()) < 1e-11 * b.initial_stored);
      }
      INFO("scheme " << int(scheme) << " method " << int(method));
      CHECK(s.balance().total_outflow() > 0);
      CHECK(s.balance().inflow_through_flux == Approx(1e-6 * 2 * s.time()).epsilon(1e-12));
    }
}

TEST_CASE("a violent first step is cut and retried, keeping P positive", "[seepage][api][robust]") {
  // p drops from 10 MPa to 0.1 MPa at the face in one step of a full day, with
  // Newton allowed only 4 iterations: the step must be cut, yet finish.
  seepage::Settings settings;
  settings.max_iterations = 4;
  auto s = rectangle_solver(seepage::Law::gas, {10, 1}, {100, 1}, {1e-17, 2e-3, 1e7},
                            {fixed_pressure("left", 1e5)}, settings, {50.0, 1.0});
  const auto report = s.advance(86400);
  std::printf("\nviolent step: %d cuts, %d substeps, smallest %.3g s\n", report.cuts, report.substeps,
              report.smallest_substep);
  CHECK(report.cuts > 0);
  CHECK(s.time() == Approx(86400));
  CHECK(s.unknown().minCoeff() > 0);
  // Balanced to the nonlinear tolerance (1e-10 on the update) of two huge steps.
  CHECK(std::abs(s.balance().error()) < 1e-9 * s.balance().initial_stored);
}

TEST_CASE("a step that cannot be completed stops with a clear message", "[seepage][api][robust]") {
  seepage::Settings settings;
  settings.max_iterations = 1;
  settings.max_step_cuts = 2;
  auto s = rectangle_solver(seepage::Law::gas, {10, 1}, {100, 1}, {1e-17, 2e-3, 1e7},
                            {fixed_pressure("left", 1e5)}, settings, {50.0, 1.0});
  CHECK_THROWS_WITH(s.advance(86400), Catch::Contains("could not be completed") &&
                                          Catch::Contains("halved 2 times"));
}

TEST_CASE("open nodes hold the open pressure, book their gas as outflow, and roll back with the state",
          "[seepage][api][open]") {
  // A sealed seam (no boundary conditions): opening a column of nodes in the
  // middle (a cavity) drains it; closing them again seals it.
  auto s = rectangle_solver(seepage::Law::gas, {10, 1}, {20, 2}, {1e-17, 2e-3, 3e6}, {});
  s.advance(600);
  const auto saved = s.save_state();
  std::vector<char> open(s.mesh().num_nodes(), 0);
  for (std::size_t i = 0; i < open.size(); ++i) open[i] = std::abs(s.mesh().nodes[i].x() - 5.0) < 1e-9;
  s.set_open_nodes(open, 1e5);
  for (int k = 0; k < 5; ++k) s.advance(3600);
  CHECK(*s.pressure_at({5.0, 0.5}) == Approx(1e5).epsilon(1e-12));
  CHECK(*s.pressure_at({4.0, 0.5}) < 3e6);
  const auto& b = s.balance();
  REQUIRE(b.pressure_boundaries.back() == "open space");
  CHECK(b.total_outflow() > 0);
  std::printf("\nopen nodes: released %.4g m3/m, balance error %.2e\n", b.total_outflow(), b.error());
  CHECK(std::abs(b.error()) < 1e-9 * b.total_outflow());
  // Rolling back restores the sealed seam: the pressure stays uniform.
  s.restore_state(saved);
  s.advance(3600);
  CHECK(*s.pressure_at({5.0, 0.5}) == Approx(3e6).epsilon(1e-9));
}
