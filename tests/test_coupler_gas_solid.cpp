// The gas-solid coupling: mesh-particle mappings, and the solid driven by a
// prescribed gas pressure field (one-way) against the analytic answer.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "coupler/gas_solid.hpp"
#include "coupling_fixtures.hpp"
#include "mpm_fixtures.hpp"
#include "seepage_fixtures.hpp"

using namespace outburst;
using namespace outburst::coupling;
using namespace outburst::testing;

TEST_CASE("mesh to points reproduces a linear field and its gradient exactly", "[coupler][mapping]") {
  const double a = 3.0, bx = -2.0, by = 0.7;
  const auto check = [&](const seepage::Mesh& mesh, const char* what) {
    const seepage::Sampler sampler(mesh);
    const MeshMapping map(sampler);
    Eigen::VectorXd nodal(static_cast<Eigen::Index>(map.mesh().num_nodes()));
    for (std::size_t i = 0; i < map.mesh().num_nodes(); ++i)
      nodal[static_cast<Eigen::Index>(i)] = a + bx * map.mesh().nodes[i].x() + by * map.mesh().nodes[i].y();
    Eigen::Vector2d lo = map.mesh().nodes[0], hi = lo;
    for (const auto& x : map.mesh().nodes) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    std::mt19937 random(7);
    std::uniform_real_distribution<double> u(0, 1);
    double worst_value = 0, worst_gradient = 0;
    int found = 0;
    for (int k = 0; k < 2000; ++k) {
      const Eigen::Vector2d x = lo + Eigen::Vector2d(u(random), u(random)).cwiseProduct(hi - lo);
      const auto s = map.sample(nodal, x);
      if (!s) continue;
      ++found;
      worst_value = std::max(worst_value, std::abs(s->value - (a + bx * x.x() + by * x.y())));
      worst_gradient = std::max(worst_gradient, (s->gradient - Eigen::Vector2d(bx, by)).norm());
    }
    std::printf("\nlinear field on the %s mesh: %d points, worst value error %.2e, gradient error %.2e\n", what,
                found, worst_value, worst_gradient);
    CHECK(found > 1000);
    CHECK(worst_value < 1e-12);
    CHECK(worst_gradient < 1e-11);
  };
  check(rectangle_problem(seepage::Law::gas, {7, 3}, {13, 5}, {1, 1, 1}, {}, {3.0, 0.5}).mesh, "graded");
  check(seepage::read_gmsh(std::string(OUTBURST_SOURCE_DIR) + "/cases/verification/two_layers.msh"),
        "unstructured Gmsh");
}

TEST_CASE("points to mesh: volume fractions and averages conserve what they average", "[coupler][mapping]") {
  const seepage::Mesh mesh = rectangle_problem(seepage::Law::gas, {4, 2}, {8, 4}, {1, 1, 1}, {}, {2.0, 1.0}).mesh;
  const seepage::Sampler sampler(mesh);
  check_averages_conserve(MeshMapping(sampler), 1e-3);
}

TEST_CASE("one-way: a column under a linear gas pressure settles to the analytic displacement and effective stress",
          "[coupler][one_way]") {
  // p = p0 (1 - y / H): the gas pushes the column up with alpha p0 / H per
  // volume; the bottom is fixed and the top free, so the effective stress is
  // sigma'_yy = f (H - y) (tension) and u_y = f / M (H y - y^2 / 2), M the
  // constrained modulus.
  const double H = 10, p0 = 3e6, alpha = 0.5, E = 1e9, nu = 0.25, rho = 1500;
  auto seep = rectangle_solver(seepage::Law::linear, {1, H}, {2, 20}, {1e-9, 1e-9, p0},
                               {fixed_pressure("bottom", p0), fixed_pressure("top", 0)});
  std::vector<double> linear(seep.mesh().num_nodes());
  for (std::size_t i = 0; i < linear.size(); ++i) linear[i] = p0 * (1 - seep.mesh().nodes[i].y() / H);
  seep.set_initial_pressure(linear);

  const mpm::Grid<2> gr = grid(1.0, 11.0, 0.25);
  mpm::Settings<2> s;
  s.local_damping = 0.7;
  s.walls = {mpm::Wall{mpm::Wall::Type::roller}, mpm::Wall{mpm::Wall::Type::roller},
             mpm::Wall{mpm::Wall::Type::fixed}, mpm::Wall{}};
  mpm::Solver<2> solid(gr, elastic({rho, E, nu}), block(gr, {0, 0}, {1, H}, rho, 2), s);

  OneWay<2> one_way(seep, solid, alpha);
  one_way.run_to(0.5, 0.005);

  const double f = alpha * p0 / H, M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const auto& p = solid.particles();
  double stress_error = 0, displacement_error = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double y = p.x0[i].y();
    stress_error = std::max(stress_error, std::abs(p.stress[i](1, 1) - f * (H - y)));
    displacement_error = std::max(displacement_error, std::abs(p.x[i].y() - y - f / M * (H * y - y * y / 2)));
  }
  const double top_u = f / M * H * H / 2;
  std::printf("\none-way column: worst |sigma'_yy - f (H - y)| / (f H) = %.2e, worst displacement error / u_top = "
              "%.2e (u_top = %.3g mm)\n",
              stress_error / (f * H), displacement_error / top_u, 1e3 * top_u);
  CHECK(stress_error < 0.01 * f * H);
  CHECK(displacement_error < 0.003 * top_u);

  // The clocks a coupled run's log shares its wall time by (coupler/main.cpp):
  // the MPM steps and the gas force read before each lie inside the solid's windows.
  double solid_seconds = 0;
  for (const auto& r : one_way.coupling.records()) solid_seconds += r.second_seconds;
  const double gas_force = one_way.solid_side.gas_force_seconds();
  CHECK(gas_force > 0);
  CHECK(solid.step_times().total() > 0);
  CHECK(solid.step_times().total() + gas_force <= 1.01 * solid_seconds + 1e-4);
}
