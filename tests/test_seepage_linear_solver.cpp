// The Newton systems' linear solvers: conjugate gradients (seepage.linear_solver
// = "cg") and conjugate gradients on an earlier Jacobian's factor ("lagged")
// must leave the discretisation's answers as CHOLMOD leaves them (the
// manufactured solution's order, the gas balance); cg must fail loudly when it
// cannot reach its tolerance, lagged must renew its factor when it has gone
// stale; every CHOLMOD mode and ordering the benchmark measures must solve the
// Jacobian.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "convergence.hpp"
#include "seepage_manufactured.hpp"

using namespace outburst;
using namespace outburst::testing;

namespace {

seepage::Settings with(seepage::LinearSolver solver, seepage::Settings settings = {}) {
  settings.linear_solver = solver;
  return settings;
}
seepage::Settings with_cg(seepage::Settings settings = {}) { return with(seepage::LinearSolver::cg, settings); }

const char* name(seepage::LinearSolver solver) { return solver == seepage::LinearSolver::cg ? "cg" : "lagged"; }
constexpr seepage::LinearSolver iterative_solvers[] = {seepage::LinearSolver::cg, seepage::LinearSolver::lagged};

}  // namespace

TEST_CASE("with conjugate gradients Q1 keeps its second order on the manufactured gas solution",
          "[seepage][cg][lagged][mms]") {
  using namespace manufactured_gas;
  const double T = 0.5;
  for (const auto solver : iterative_solvers) {
    std::vector<ConvergenceRow> rows;
    for (int n : {8, 16, 32, 64}) {
      auto cg = manufactured(n, with(solver));
      auto direct = manufactured(n, {});
      for (int k = 0; k < 250; ++k) {  // BDF2 with dt = 2e-3: time error far below the spatial
        cg->advance(T / 250);
        direct->advance(T / 250);
      }
      rows.push_back({1.0 / n, l2_error(*cg, T)});
      INFO(name(solver) << ", n = " << n);
      const auto& t = cg->timings();
      CHECK(t.linear_iterations > 0);
      std::printf("%s, n = %d: Newton iterations %ld (direct %ld), cg iterations per Newton iteration %.2f, "
                  "factorisations %ld\n",
                  name(solver), n, t.nonlinear_iterations, direct->timings().nonlinear_iterations,
                  double(t.linear_iterations) / double(t.nonlinear_iterations), t.factorizations);
      // Solved to 1e-8, each Newton system is as good as solved exactly: Newton's
      // convergence is left as it was.
      CHECK(t.nonlinear_iterations <= 1.02 * direct->timings().nonlinear_iterations);
      // The point of lagging: a factor serves many Newton iterations.
      if (solver == seepage::LinearSolver::lagged) CHECK(10 * t.factorizations < t.nonlinear_iterations);
      // Both converge Newton to the same tolerance: their answers are one answer.
      CHECK((cg->unknown() - direct->unknown()).lpNorm<Eigen::Infinity>() <
            1e-9 * direct->unknown().lpNorm<Eigen::Infinity>());
    }
    print_convergence(fmt::format("seepage MMS, space, {} (BDF2, dt = 2e-3)", name(solver)), "h", rows);
    for (double order : observed_orders(rows)) CHECK(order == Approx(2.0).margin(0.1));
  }
}

TEST_CASE("with conjugate gradients stored gas plus what crossed the boundary stays constant",
          "[seepage][cg][lagged][balance]") {
  // As the direct solver's test (test_seepage_api.cpp): a time-varying face
  // pressure, an injected flux and uneven steps under both schemes and methods.
  for (const auto solver : iterative_solvers)
    for (auto scheme : {seepage::TimeScheme::backward_euler, seepage::TimeScheme::bdf2})
      for (auto method : {seepage::NonlinearMethod::newton, seepage::NonlinearMethod::picard}) {
        seepage::Settings settings = with(solver);
        settings.scheme = scheme;
        settings.method = method;
        settings.max_iterations = 200;
        const seepage::BoundaryCondition face{"left", seepage::BoundaryCondition::Type::pressure,
                                              TimeFunction({{0.0, 3e6}, {3600.0, 1e5}, {20000.0, 5e5}})};
        const seepage::BoundaryCondition inflow{"right", seepage::BoundaryCondition::Type::flux, TimeFunction(1e-6)};
        auto s = rectangle_solver(seepage::Law::gas, {10, 2}, {30, 4}, {1e-17, 2e-3, 3e6}, {face, inflow}, settings,
                                  {5.0, 1.0});
        double dt = 60;
        INFO(name(solver) << ", scheme " << int(scheme) << " method " << int(method));
        for (int i = 0; i < 30; ++i) {
          s.advance(dt);
          dt *= (i % 3 == 0) ? 0.7 : 1.6;
          const auto& b = s.balance();
          REQUIRE(std::abs(b.error()) < 1e-11 * b.initial_stored);
        }
        CHECK(s.timings().linear_iterations > 0);
        CHECK(s.balance().total_outflow() > 0);
      }
}

TEST_CASE("the lagged solver renews its factor when the conductivity changes or its iterations grow",
          "[seepage][lagged]") {
  const seepage::Material coal{1e-17, 2e-3, 3e6};
  const auto solver = [&](seepage::Settings settings) {
    return rectangle_solver(seepage::Law::gas, {10, 1}, {40, 4}, coal, {fixed_pressure("left", 1e5)}, settings);
  };
  const auto lagged_with = [&](int lag_max_iterations) {
    seepage::Settings settings = with(seepage::LinearSolver::lagged);
    settings.lag_max_iterations = lag_max_iterations;
    return solver(settings);
  };
  const auto agrees = [](const auto& a, const auto& b) {
    return (a.unknown() - b.unknown()).template lpNorm<Eigen::Infinity>() <
           1e-9 * b.unknown().template lpNorm<Eigen::Infinity>();
  };
  auto direct = solver({});
  auto kept = lagged_with(1000);
  for (int k = 0; k < 10; ++k) {
    kept.advance(600);
    direct.advance(600);
  }
  // Fixed steps and conductivity: a factor the iterations converge on serves
  // the whole run.
  CHECK(kept.timings().factorizations == 1);
  CHECK(kept.timings().nonlinear_iterations > 10);
  CHECK(agrees(kept, direct));
  // A conductivity 1 % higher changes the Jacobian off its diagonal: one new
  // factor, though iterations on the old one would still converge.
  const std::vector<double> k(kept.mesh().num_cells(), 1.01 * kept.conductivity()[0]);
  kept.set_conductivity(k);
  direct.set_conductivity(k);
  kept.advance(600);
  direct.advance(600);
  CHECK(kept.timings().factorizations == 2);
  CHECK(agrees(kept, direct));
  // A small allowance: factors are renewed once iterations pass half of it
  // (or, past all of it, solved directly), every renewal counted, and the
  // answer stays the direct solver's.
  auto eager = lagged_with(4);
  auto direct_again = solver({});
  for (int k = 0; k < 10; ++k) {
    eager.advance(600);
    direct_again.advance(600);
  }
  const auto& t = eager.timings();
  INFO("renewals " << t.lagged_renewals << ", fallbacks " << t.lagged_fallbacks);
  CHECK(t.lagged_renewals > 0);
  CHECK(t.factorizations == 1 + t.lagged_renewals + t.lagged_fallbacks);
  CHECK(agrees(eager, direct_again));
}

TEST_CASE("an adaptive forcing term spends fewer conjugate gradient iterations for the same answer",
          "[seepage][cg][lagged][forcing]") {
  // Gas drains from a seam at 3 MPa through a face at 0.1 MPa in steps of
  // 10 min to 1 d, each taking several Newton iterations: the early ones
  // solved loosely, the last to cg_tolerance, where Newton stops as it did.
  const seepage::Material coal{1e-17, 2e-3, 3e6};
  const auto make = [&](seepage::Settings settings) {
    return rectangle_solver(seepage::Law::gas, {10, 1}, {80, 8}, coal, {fixed_pressure("left", 1e5)}, settings);
  };
  const auto drain = [](auto& s) {
    double dt = 600;
    for (int k = 0; k < 12; ++k, dt *= 1.6) s.advance(dt);
  };
  auto direct = make({});
  drain(direct);
  const double scale = direct.unknown().lpNorm<Eigen::Infinity>();
  for (const auto solver : iterative_solvers) {
    seepage::Settings loose = with(solver);
    loose.cg_forcing = seepage::Forcing::adaptive;
    auto fixed = make(with(solver)), adaptive = make(loose);
    drain(fixed);
    drain(adaptive);
    const auto& f = fixed.timings();
    const auto& a = adaptive.timings();
    std::printf("%s: Newton iterations %ld fixed, %ld adaptive; conjugate gradient iterations %ld fixed, %ld "
                "adaptive; factorisations %ld, %ld\n",
                name(solver), f.nonlinear_iterations, a.nonlinear_iterations, f.linear_iterations,
                a.linear_iterations, f.factorizations, a.factorizations);
    INFO(name(solver));
    CHECK(a.linear_iterations < 0.8 * f.linear_iterations);
    CHECK(a.nonlinear_iterations <= 1.5 * f.nonlinear_iterations);
    CHECK((adaptive.unknown() - direct.unknown()).lpNorm<Eigen::Infinity>() < 1e-9 * scale);
    CHECK((fixed.unknown() - direct.unknown()).lpNorm<Eigen::Infinity>() < 1e-9 * scale);
  }
  // Darcy flow is linear: one solve to cg_tolerance per Newton iteration, as
  // under the fixed forcing.
  const seepage::Material rock{1e-15 / 1e-3, 1e-9, 1e6};
  seepage::Settings loose = with_cg();
  loose.cg_forcing = seepage::Forcing::adaptive;
  auto fixed = rectangle_solver(seepage::Law::linear, {10, 1}, {40, 4}, rock, {fixed_pressure("left", 1e5)}, with_cg());
  auto adaptive = rectangle_solver(seepage::Law::linear, {10, 1}, {40, 4}, rock, {fixed_pressure("left", 1e5)}, loose);
  for (int k = 0; k < 5; ++k) {
    fixed.advance(0.5);
    adaptive.advance(0.5);
  }
  CHECK(adaptive.timings().nonlinear_iterations == fixed.timings().nonlinear_iterations);
  CHECK(adaptive.timings().linear_iterations == fixed.timings().linear_iterations);
}

TEST_CASE("conjugate gradients solve the linear law as CHOLMOD does, reusing their preconditioner",
          "[seepage][cg][linear]") {
  // Darcy flow: the Jacobian depends on the step alone, so equal steps factorise once.
  const seepage::Material rock{1e-15 / 1e-3, 1e-9, 1e6};
  auto cg = rectangle_solver(seepage::Law::linear, {10, 1}, {40, 4}, rock, {fixed_pressure("left", 1e5)}, with_cg());
  auto direct = rectangle_solver(seepage::Law::linear, {10, 1}, {40, 4}, rock, {fixed_pressure("left", 1e5)});
  for (int k = 0; k < 10; ++k) {
    cg.advance(0.5);
    direct.advance(0.5);
  }
  CHECK(cg.timings().factorizations == direct.timings().factorizations);
  CHECK((cg.unknown() - direct.unknown()).lpNorm<Eigen::Infinity>() < 1e-9 * 1e6);
}

TEST_CASE("conjugate gradients that cannot reach their tolerance cut the step, then stop the run with the keys named",
          "[seepage][cg][robust]") {
  seepage::Settings settings = with_cg();
  settings.cg_max_iterations = 3;
  settings.max_step_cuts = 2;
  auto s = rectangle_solver(seepage::Law::gas, {10, 1}, {100, 4}, {1e-17, 2e-3, 1e7}, {fixed_pressure("left", 1e5)},
                            settings);
  CHECK_THROWS_WITH(s.advance(86400), Catch::Contains("could not be completed") &&
                                          Catch::Contains("halved 2 times") &&
                                          Catch::Contains("seepage.cg_max_iterations = 3") &&
                                          Catch::Contains("short of seepage.cg_tolerance"));
  CHECK(s.time() == 0);
}

TEST_CASE("every CHOLMOD mode and ordering solves the seepage Jacobian", "[seepage][direct]") {
  auto s = rectangle_solver(seepage::Law::gas, {1, 1}, {30, 30}, {0.1, 2.0, 3.0}, {fixed_pressure("left", 1.0)});
  s.advance(1e-3);
  const auto& j = s.jacobian();
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(j.rows(), 1.0, 2.0);
  const Eigen::VectorXd b = j.selfadjointView<Eigen::Lower>() * x;
  using F = seepage::Factorisation;
  for (auto mode : {F::Mode::simplicial, F::Mode::supernodal})
    for (auto ordering : {F::Ordering::amd, F::Ordering::metis, F::Ordering::nesdis, F::Ordering::cholmod_default}) {
      const F f{mode, ordering};
      seepage::Cholmod factor;
      seepage::configure(factor, f);
      factor.compute(j);
      INFO(f.name());
      REQUIRE(factor.info() == Eigen::Success);
      CHECK((factor.solve(b) - x).lpNorm<Eigen::Infinity>() < 1e-12);
      // configure() asked CHOLMOD for the ordering and mode named (by
      // default CHOLMOD itself picks AMD or METIS).
      const cholmod_common& c = factor.cholmod();
      const int used = c.method[c.selected].ordering;
      if (ordering == F::Ordering::cholmod_default)
        CHECK((used == CHOLMOD_AMD || used == CHOLMOD_METIS));
      else
        CHECK(used == (ordering == F::Ordering::amd     ? CHOLMOD_AMD
                       : ordering == F::Ordering::metis ? CHOLMOD_METIS
                                                        : CHOLMOD_NESDIS));
      CHECK(c.supernodal == (mode == F::Mode::simplicial ? CHOLMOD_SIMPLICIAL : CHOLMOD_SUPERNODAL));
    }
}
