#pragma once
// Manufactured solution of the nonlinear gas equation
//     d/dt (A P^(1/4)) = div(lambda grad P) + s
// with P = 2 + sin(pi x) sin(pi y) g(t), g = (1 + cos 3t) / 2 on the unit square,
// P = 2 on the boundary: the problem, and the L2 error of a solver's P.

#include <cmath>
#include <memory>

#include "seepage_fe/q1.hpp"
#include "seepage_fixtures.hpp"

namespace outburst::testing::manufactured_gas {

constexpr double pi = 3.14159265358979323846;
constexpr double A = 2.0, lambda = 0.1;

inline double g(double t) { return 0.5 * (1 + std::cos(3 * t)); }
inline double dg(double t) { return -1.5 * std::sin(3 * t); }
inline double exact(const Eigen::Vector2d& x, double t) {
  return 2 + std::sin(pi * x.x()) * std::sin(pi * x.y()) * g(t);
}
inline double source(const Eigen::Vector2d& x, double t) {
  const double s = std::sin(pi * x.x()) * std::sin(pi * x.y());
  const double P = 2 + s * g(t);
  return A * 0.25 * std::pow(P, -0.75) * s * dg(t) + lambda * 2 * pi * pi * s * g(t);
}

inline std::unique_ptr<seepage::Solver> manufactured(int n, seepage::Settings settings) {
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
inline double l2_error(const seepage::Solver& s, double t) {
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

}  // namespace outburst::testing::manufactured_gas
