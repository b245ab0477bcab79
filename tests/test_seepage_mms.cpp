// The manufactured gas solution (seepage_manufactured.hpp): measures the
// spatial order (L2, Q1: 2) and the time order of backward Euler (1) and BDF2
// (2), and checks Newton and Picard agree.
#include <catch2/catch.hpp>

#include "convergence.hpp"
#include "seepage_manufactured.hpp"

using namespace outburst;
using namespace outburst::testing;
using namespace outburst::testing::manufactured_gas;

TEST_CASE("Q1 converges at second order in L2 on the manufactured gas solution", "[seepage][mms]") {
  const double T = 0.5;
  std::vector<ConvergenceRow> rows;
  for (int n : {8, 16, 32, 64}) {
    auto s = manufactured(n, {});
    run_steps(*s, T, 1000);  // BDF2 with dt = 5e-4: time error far below the spatial
    rows.push_back({1.0 / n, l2_error(*s, T)});
  }
  print_convergence("seepage MMS, space (BDF2, dt = 5e-4)", "h", rows);
  for (double order : observed_orders(rows)) CHECK(order == Approx(2.0).margin(0.1));
}

TEST_CASE("backward Euler is first and BDF2 second order in time", "[seepage][mms]") {
  const double T = 0.5;
  const int n = 16;
  for (auto scheme : {seepage::TimeScheme::backward_euler, seepage::TimeScheme::bdf2}) {
    seepage::Settings settings;
    settings.scheme = scheme;
    settings.tolerance = 1e-13;
    // The reference is the same mesh with a tiny step, so only the time error remains.
    auto reference = manufactured(n, settings);
    run_steps(*reference, T, 8192);
    std::vector<ConvergenceRow> rows;
    for (int steps : {8, 16, 32, 64}) {
      auto s = manufactured(n, settings);
      run_steps(*s, T, steps);
      rows.push_back({T / steps, (s->unknown() - reference->unknown()).lpNorm<Eigen::Infinity>()});
    }
    const bool bdf2 = scheme == seepage::TimeScheme::bdf2;
    print_convergence(bdf2 ? "seepage MMS, time, BDF2" : "seepage MMS, time, backward Euler", "dt",
                      rows);
    const double expected = bdf2 ? 2.0 : 1.0;
    const auto orders = observed_orders(rows);
    CHECK(orders.back() == Approx(expected).margin(0.1));
    CHECK(orders[orders.size() - 2] == Approx(expected).margin(0.15));
  }
}

TEST_CASE("Newton and Picard solve the same discrete equations, Newton in fewer iterations",
          "[seepage][mms]") {
  seepage::Settings newton, picard;
  picard.method = seepage::NonlinearMethod::picard;
  picard.max_iterations = 200;
  newton.tolerance = picard.tolerance = 1e-12;
  auto a = manufactured(16, newton);
  auto b = manufactured(16, picard);
  int iterations_newton = 0, iterations_picard = 0;
  for (int i = 0; i < 10; ++i) {
    iterations_newton += a->advance(0.05).nonlinear_iterations;
    iterations_picard += b->advance(0.05).nonlinear_iterations;
  }
  std::printf("\nnonlinear iterations over 10 steps: Newton %d, Picard %d\n", iterations_newton,
              iterations_picard);
  CHECK((a->unknown() - b->unknown()).lpNorm<Eigen::Infinity>() <
        1e-9 * a->unknown().lpNorm<Eigen::Infinity>());
  CHECK(iterations_newton < iterations_picard);
}
