// 1D elastic bar vibration (fixed at x = 0, free at x = L) against the analytic
// first mode, with the convergence under grid refinement for each shape
// function. The bar is one cell high between rollers, nu = 0: a 1D problem.
//   v(x, 0) = v0 sin(beta x), beta = pi / (2L), omega = beta c, c = sqrt(E / rho)
//   u(x, t) = (v0 / omega) sin(omega t) sin(beta x)
#include <catch2/catch.hpp>

#include <cmath>

#include "convergence.hpp"
#include "mpm_solid/materials/elastic.hpp"
#include "mpm_solid/solver.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double L = 1.0, E = 100.0, rho = 1.0, v0 = 0.01;

// Max over a period of the RMS displacement error, relative to the amplitude.
double bar_error(ShapeKind shape, Scheme scheme, int cells_along_bar) {
  const double h = L / cells_along_bar;
  Grid<2> grid;
  grid.h = h;
  grid.lower = {0, 0};
  grid.cells = {cells_along_bar + cells_along_bar / 4, 1};
  grid.upper = grid.lower + Vec<2>(grid.cells[0] * h, h);
  const double beta = pi / (2 * L), c = std::sqrt(E / rho), omega = beta * c;
  const int ppc = 2;
  Particles<2> particles;
  const double volume = (h / ppc) * (h / ppc);
  for (int i = 0; i < cells_along_bar * ppc; ++i)
    for (int j = 0; j < ppc; ++j) {
      const Vec<2> x((i + 0.5) * h / ppc, (j + 0.5) * h / ppc);
      particles.add(x, Vec<2>(v0 * std::sin(beta * x.x()), 0), rho * volume, volume, 0.5 / ppc, Mat<2>::Zero(), 0,
                    0);
    }
  std::vector<std::unique_ptr<Material<2>>> materials;
  materials.push_back(std::make_unique<LinearElastic<2>>("bar", Elasticity{rho, E, 0.0}));
  Settings<2> settings;
  settings.shape = shape;
  settings.scheme = scheme;
  settings.flip_fraction = 1.0;
  settings.walls[0] = {Wall::Type::fixed, 0};
  settings.walls[2] = settings.walls[3] = {Wall::Type::roller, 0};
  Solver<2> solver(grid, std::move(materials), std::move(particles), settings);

  // One small step for every grid, so the error measured is the spatial one.
  const double period = 2 * pi / omega;
  const int steps = static_cast<int>(std::ceil(period / (0.05 * (L / 128) / c)));
  const double dt = period / steps;
  double worst = 0;
  for (int n = 1; n <= steps; ++n) {
    solver.step(dt);
    if (n % std::max(1, steps / 16) != 0) continue;
    const auto& p = solver.particles();
    double sum = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double exact = v0 / omega * std::sin(omega * solver.time()) * std::sin(beta * p.x0[i].x());
      sum += std::pow(p.x[i].x() - p.x0[i].x() - exact, 2);
    }
    worst = std::max(worst, std::sqrt(sum / static_cast<double>(p.size())) / (v0 / omega));
  }
  return worst;
}

}  // namespace

TEST_CASE("the elastic bar vibrates as the analytic mode and converges under refinement", "[mpm][bar]") {
  struct Case {
    ShapeKind shape;
    const char* name;
    double min_order;  // asserted on every refinement but the last
  };
  // Measured (see the printed tables): GIMP and B-splines converge at second
  // order; linear at second order down to h = L/32, then levels off.
  for (const Case& c : {Case{ShapeKind::gimp, "GIMP", 1.9}, Case{ShapeKind::linear, "linear", 1.9},
                        Case{ShapeKind::bspline, "B-spline", 1.9}}) {
    std::vector<ConvergenceRow> rows;
    for (int cells : {8, 16, 32, 64}) rows.push_back({L / cells, bar_error(c.shape, Scheme::usf, cells)});
    print_convergence(std::string("bar vibration, USF, ") + c.name + ": max RMS displacement error / amplitude",
                      "h", rows);
    const auto orders = observed_orders(rows);
    for (std::size_t k = 0; k + 1 < orders.size(); ++k) CHECK(orders[k] > c.min_order);
    CHECK(rows.back().error < 0.015);
  }
}
