// Manufactured solution for the whole explicit scheme (after Wallstedt and
// Guilkey 2008, linearised): a one-dimensional displacement field
//     u(X, t) = A sin(2 pi X) sin(pi t)   on 0 <= X <= 1, fixed at both ends,
// is driven by the body force b = rho u_tt - E u_XX, applied through the
// per-particle external force the coupler uses. A = 1e-6 keeps the geometric
// nonlinearity far below the discretisation error. The time step is the same
// small one on every grid, so the error measured is the spatial one. (GIMP
// equals linear here: the particles never leave the linear part of its
// weights.)
#include <catch2/catch.hpp>

#include <cmath>

#include "convergence.hpp"
#include "mpm_fixtures.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double A = 1e-6, E = 1.0, rho = 1.0;

double mms_error(ShapeKind shape, int cells) {
  const double h = 1.0 / cells;
  Grid<2> gr = grid(1.0, h, h);
  Particles<2> p = block(gr, {0, 0}, {1, h}, rho, 2);
  for (std::size_t i = 0; i < p.size(); ++i) p.v[i] = Vec<2>(A * pi * std::sin(2 * pi * p.x[i].x()), 0);
  Settings<2> s;
  s.shape = shape;
  s.flip_fraction = 1.0;
  s.walls = {Wall{Wall::Type::fixed}, Wall{Wall::Type::fixed}, Wall{Wall::Type::roller}, Wall{Wall::Type::roller}};
  Solver<2> solver(gr, elastic({rho, E, 0.0}), std::move(p), s);
  const int steps = 4 * 2560;
  const double dt = 1.0 / steps;
  double worst = 0;
  for (int n = 0; n < steps; ++n) {
    const double t = solver.time();
    const auto& q = solver.particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      const double x = q.x0[i].x();
      const double b = A * std::sin(2 * pi * x) * std::sin(pi * t) * (4 * pi * pi * E - pi * pi * rho);
      solver.external_force()[i] = Vec<2>(q.volume0[i] * b, 0);
    }
    solver.step(dt);
    if ((n + 1) % (steps / 8) != 0) continue;
    double sum = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      const double exact = A * std::sin(2 * pi * q.x0[i].x()) * std::sin(pi * solver.time());
      sum += std::pow(q.x[i].x() - q.x0[i].x() - exact, 2);
    }
    worst = std::max(worst, std::sqrt(sum / static_cast<double>(q.size())) / A);
  }
  return worst;
}

}  // namespace

TEST_CASE("the full scheme converges on a manufactured solution driven by external forces", "[mpm][mms]") {
  for (auto [shape, name, order] : {std::tuple{ShapeKind::gimp, "GIMP", 1.8}, std::tuple{ShapeKind::linear, "linear", 1.8},
                                    std::tuple{ShapeKind::bspline, "B-spline", 1.8}}) {
    std::vector<ConvergenceRow> rows;
    for (int cells : {8, 16, 32}) rows.push_back({1.0 / cells, mms_error(shape, cells)});
    print_convergence(std::string("MPM manufactured solution, USF, ") + name + ": max RMS displacement error / A",
                      "h", rows);
    for (double o : observed_orders(rows)) CHECK(o > order);
  }
}
