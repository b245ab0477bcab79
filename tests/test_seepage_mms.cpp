// Manufactured solution of the nonlinear gas equation
//     d/dt (A P^(1/4)) = div(lambda grad P) + s
// with P = 2 + sin(pi x) sin(pi y) g(t), g = (1 + cos 3t) / 2 on the unit square,
// P = 2 on the boundary. Measures the spatial order (L2, Q1: 2) and the time
// order of backward Euler (1) and BDF2 (2), and checks Newton and Picard agree.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

#include "convergence.hpp"
#include "seepage_fe/q1.hpp"
#include "seepage_fixtures.hpp"

using namespace outburst;
using namespace outburst::testing;

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double A = 2.0, lambda = 0.1;

double g(double t) { return 0.5 * (1 + std::cos(3 * t)); }
double dg(double t) { return -1.5 * std::sin(3 * t); }
double exact(const Eigen::Vector2d& x, double t) {
  return 2 + std::sin(pi * x.x()) * std::sin(pi * x.y()) * g(t);
}
double source(const Eigen::Vector2d& x, double t) {
  const double s = std::sin(pi * x.x()) * std::sin(pi * x.y());
  const double P = 2 + s * g(t);
  return A * 0.25 * std::pow(P, -0.75) * s * dg(t) + lambda * 2 * pi * pi * s * g(t);
}

std::unique_ptr<seepage::Solver> manufactured(int n, seepage::Settings settings) {
  auto p = rectangle_problem(
      seepage::Law::gas, {1, 1}, {n, n}, {lambda, A, std::sqrt(2.0)},
      {fixed_pressure("left", std::sqrt(2.0)), fixed_pressure("right", std::sqrt(2.0)),
       fixed_pressure("bottom", std::sqrt(2.0)), fixed_pressure("top", std::sqrt(2.0))});
  auto solver = std::make_unique<seepage::Solver>(std::move(p.mesh), std::move(p.model), settings);
  solver->set_source(source);
  std::vector<double> p0;
  for (const auto& x : solver->mesh().nodes) p0.push_back(std::sqrt(exact(x, 0.0)));
  solver->set_initial_pressure(p0);
  return solver;
}

// || P_h - P ||_L2 with a 3x3 Gauss rule per cell.
double l2_error(const seepage::Solver& s, double t) {
  const double gp[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double sum = 0;
  const auto& m = s.mesh();
  for (const auto& c : m.cells) {
    const seepage::q1::Corners x{m.nodes[c[0]], m.nodes[c[1]], m.nodes[c[2]], m.nodes[c[3]]};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const auto p = seepage::q1::evaluate(x, gp[i], gp[j]);
        double uh = 0;
        Eigen::Vector2d at = Eigen::Vector2d::Zero();
        for (int a = 0; a < 4; ++a) {
          uh += p.n[a] * s.unknown()[c[a]];
          at += p.n[a] * x[a];
        }
        sum += gw[i] * gw[j] * p.det_j * std::pow(uh - exact(at, t), 2);
      }
  }
  return std::sqrt(sum);
}

}  // namespace

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
