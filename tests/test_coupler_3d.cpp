// The gas-solid coupling in 3D: the mapping between hexahedra and particles,
// a column driven one way by a prescribed gas pressure against the analytic
// answer, as tests/test_coupler_gas_solid.cpp checks the plane ones, and the
// order of the six stress components on both sides of the exchange.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "coupler/gas_solid.hpp"
#include "coupling_fixtures.hpp"
#include "mpm_fixtures.hpp"
#include "seepage_fixtures.hpp"

using namespace outburst;
using namespace outburst::coupling;
using namespace outburst::testing;

TEST_CASE("3D: hexahedra to points reproduce a linear field and its gradient exactly", "[coupler][mapping][3d]") {
  const Eigen::Vector3d b(-2.0, 0.7, 1.3);
  const double a = 3.0;
  auto seep = box_solver(seepage::Law::linear, {4, 2, 3}, {5, 3, 4}, {1e-9, 1e-9, 1e6}, {}, {}, {2.0, 0.5, 1.5});
  const MeshMapping map(seep.sampler());
  Eigen::VectorXd nodal(static_cast<Eigen::Index>(map.mesh().num_nodes()));
  for (std::size_t i = 0; i < map.mesh().num_nodes(); ++i)
    nodal[static_cast<Eigen::Index>(i)] = a + b.dot(map.mesh().nodes[i]);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(0, 1);
  double worst_value = 0, worst_gradient = 0;
  int found = 0;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d x(4.4 * u(random) - 0.2, 2 * u(random), 3 * u(random));  // some outside
    const auto s = map.sample(nodal, x);
    if (!s) {
      CHECK((x.x() < 0 || x.x() > 4));
      continue;
    }
    ++found;
    worst_value = std::max(worst_value, std::abs(s->value - (a + b.dot(x))));
    worst_gradient = std::max(worst_gradient, (s->gradient - b).norm());
  }
  std::printf("\nlinear field on a graded box of hexahedra: %d points, worst value error %.2e, gradient error %.2e\n",
              found, worst_value, worst_gradient);
  CHECK(found > 1500);
  CHECK(worst_value < 1e-12);
  CHECK(worst_gradient < 1e-11);
}

TEST_CASE("3D: points to hexahedra: volume fractions and averages conserve what they average",
          "[coupler][mapping][3d]") {
  auto seep = box_solver(seepage::Law::linear, {4, 2, 1}, {8, 4, 3}, {1e-9, 1e-9, 1e6}, {}, {}, {2.0, 1.0, 0.5});
  check_averages_conserve(MeshMapping(seep.sampler()), 1e-4);
}

TEST_CASE("3D one-way: a column under a linear gas pressure settles to the analytic displacement and effective "
          "stress",
          "[coupler][one_way][3d]") {
  // p = p0 (1 - y / H): the gas pushes the column up with alpha p0 / H per
  // volume; the bottom is fixed, the sides are rollers and the top is free,
  // so sigma'_yy = f (H - y) (tension) and u_y = f / M (H y - y^2 / 2), M
  // the constrained modulus; sigma'_xx = sigma'_zz = nu / (1 - nu) sigma'_yy.
  const double H = 10, p0 = 3e6, alpha = 0.5, E = 1e9, nu = 0.25, rho = 1500;
  auto seep = box_solver(seepage::Law::linear, {1, H, 1}, {2, 20, 2}, {1e-9, 1e-9, p0},
                         {fixed_pressure("bottom", p0), fixed_pressure("top", 0)});
  std::vector<double> linear(seep.mesh().num_nodes());
  for (std::size_t i = 0; i < linear.size(); ++i) linear[i] = p0 * (1 - seep.mesh().nodes[i].y() / H);
  seep.set_initial_pressure(linear);

  const mpm::Grid<3> gr = grid(mpm::Vec<3>(1.0, 11.0, 1.0), 0.25);
  mpm::Settings<3> s;
  s.local_damping = 0.7;
  for (auto& w : s.walls) w = mpm::Wall{mpm::Wall::Type::roller};
  s.walls[2] = mpm::Wall{mpm::Wall::Type::fixed};
  s.walls[3] = mpm::Wall{};
  mpm::Solver<3> solid(gr, elastic<3>({rho, E, nu}), block<3>(gr, mpm::Vec<3>::Zero(), mpm::Vec<3>(1, H, 1), rho, 2),
                       s);

  OneWay<3> one_way(seep, solid, alpha);
  one_way.run_to(0.5, 0.005);
  const auto& map = one_way.map;

  const double f = alpha * p0 / H, M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const auto& p = solid.particles();
  double stress_error = 0, lateral_error = 0, displacement_error = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double y = p.x0[i].y(), exact = f * (H - y);
    stress_error = std::max(stress_error, std::abs(p.stress[i](1, 1) - exact));
    const double k0 = nu / (1 - nu);
    lateral_error = std::max(
        {lateral_error, std::abs(p.stress[i](0, 0) - k0 * exact), std::abs(p.stress[i](2, 2) - k0 * exact)});
    displacement_error = std::max(displacement_error, std::abs(p.x[i].y() - y - f / M * (H * y - y * y / 2)));
  }
  const double top_u = f / M * H * H / 2;
  std::printf("\n3D one-way column: worst |sigma'_yy - f (H - y)| / (f H) = %.2e, lateral %.2e, worst displacement "
              "error / u_top = %.2e (u_top = %.3g mm)\n",
              stress_error / (f * H), lateral_error / (f * H), displacement_error / top_u, 1e3 * top_u);
  CHECK(stress_error < 0.01 * f * H);
  CHECK(lateral_error < 0.01 * f * H);
  CHECK(displacement_error < 0.003 * top_u);
  // With the permeability coupling the solid sends its cells' mean stress,
  // six components (xx, yy, zz, yz, xz, xy), which conserve sum V sigma: on
  // the settled column, and on the same particles given a stress whose six
  // components differ and vary in space (the column's shear is zero, so a
  // shear component sent in another's slot would pass on it alone).
  GasSolidSettings with_stress = one_way.settings;
  with_stress.permeability_coupling = true;
  const auto pressure = one_way.seepage_side.read("pressure");
  const auto check_sent = [&](mpm::Solver<3>& sender) {
    const SolidParticipant probe(sender, map, with_stress, pressure, std::nullopt);
    const Eigen::VectorXd mean = probe.read("stress"), fraction = probe.read("occupancy");
    const auto nc = static_cast<Eigen::Index>(seep.mesh().num_cells());
    REQUIRE(mean.size() == 6 * nc);
    Eigen::Matrix<double, 6, 1> mapped = Eigen::Matrix<double, 6, 1>::Zero(), direct = mapped;
    for (Eigen::Index cell = 0; cell < nc; ++cell)
      mapped += fraction[cell] * map.cell_area()[static_cast<std::size_t>(cell)] * mean.segment<6>(6 * cell);
    const auto& q = sender.particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      const auto& t = q.stress[i];
      if (map.cell_of(q.x[i]) < 0) continue;
      direct += q.volume[i] *
                (Eigen::Matrix<double, 6, 1>() << t(0, 0), t(1, 1), t(2, 2), t(1, 2), t(0, 2), t(0, 1)).finished();
    }
    for (int k = 0; k < 6; ++k) CHECK(std::abs(mapped[k] - direct[k]) < 1e-12 * direct.norm());
  };
  check_sent(solid);
  auto sheared = block<3>(gr, mpm::Vec<3>::Zero(), mpm::Vec<3>(1, H, 1), rho, 2);
  for (std::size_t i = 0; i < sheared.size(); ++i) {
    const auto& x = sheared.x[i];
    const double xy = 6 + x.z(), xz = 5 - x.x(), yz = 2 + 3 * x.x() * x.y();  // means 6.5, 4.5, 9.5
    sheared.stress[i] << 1 + x.y(), xy, xz, xy, 2 - x.y(), yz, xz, yz, 3 + x.z();
  }
  mpm::Solver<3> with_shear(gr, elastic<3>({rho, E, nu}), std::move(sheared), s);
  check_sent(with_shear);
}

TEST_CASE("3D: the seepage reads a cell's stress in the order the solid sends it", "[coupler][permeability][3d]") {
  // lambda = lambda0 exp(beta sigma_min), sigma_min the smallest principal
  // value of the whole tensor. Its three shear components differ, so a tensor
  // put together from the six sent values in another order has other
  // principal values.
  auto seep = box_solver(seepage::Law::linear, {2, 1, 1}, {2, 1, 1}, {1e-9, 1e-9, 1e6}, {});
  GasSolidSettings settings;
  settings.permeability.beta = 2e-7;
  SeepageParticipant<3> side(seep, settings);
  Eigen::Matrix3d sigma;
  sigma << -3e6, 0.8e6, -0.5e6, 0.8e6, -1e6, 1.2e6, -0.5e6, 1.2e6, -2e6;
  Eigen::VectorXd stress(12);
  for (int c = 0; c < 2; ++c) {
    const Eigen::Matrix3d t = (1 + c) * sigma;
    stress.segment<6>(6 * c) << t(0, 0), t(1, 1), t(2, 2), t(1, 2), t(0, 2), t(0, 1);
  }
  side.write("stress", stress);
  side.write("occupancy", Eigen::VectorXd::Ones(2));
  side.advance(1.0);
  for (int c = 0; c < 2; ++c) {
    const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>((1 + c) * sigma).eigenvalues()[0];
    CHECK(seep.conductivity()[static_cast<std::size_t>(c)] ==
          Approx(1e-9 * std::exp(settings.permeability.beta * smallest)).epsilon(1e-12));
  }
}
