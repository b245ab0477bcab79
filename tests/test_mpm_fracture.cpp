// Fracture with a length scale (issue 17, first part): a bar pulled past its
// peak by a plate moved at a set speed. With a fracture energy (the crack
// band) the energy dissipated per unit crack area stays the same as the grid
// is refined; with the paper's local law it shrinks with the cell. Measured,
// not yet as asserted in the issue: the crack band dissipates about 1.2 G_f
// with linear shape functions and 1.6 G_f with B-splines, whose velocity field
// spreads the crack over two to three cells (mpm_solid/README.md).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>

#include "mpm_fixtures.hpp"
#include "mpm_solid/materials/elastic_damage.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

// Coal (Table 1) with a fracture energy K_Ic^2 / E of outburst-prone coal
// (K_Ic = 0.12 MPa m^0.5), and nu = 0.25 for a quicker test.
const Elasticity coal{1600, 6e9, 0.25};
constexpr double strength = 0.2e6, residual = 0.3, fracture_energy = 0.12e6 * 0.12e6 / 6e9;
// The bar is shorter than 2 E G_f / f_t^2 (0.72 m): longer, the elastic energy
// it releases as the band softens would break it at once (a snap-back).
constexpr double length = 0.25, height = 0.05, speed = 0.01;  // [m], [m], [m/s]
// The band where the bar breaks is 5 % weaker, so that it breaks there; the
// grips, three cells at each end, twice as strong, so that it does not break
// where the plate and the wall meet it (as a dog-bone specimen).
constexpr double weak = 0.95, grip = 2.0;

struct Pull {
  double dissipated_per_area;  // by damage, over the crack area [J/m2]
  double peak_force;           // [N/m]
};

// The bar [0, length] x [0, height] on rollers at x = 0 and y = 0 (a
// symmetric half), pulled at x = length; h the cell, `local` the paper's law
// with eta = 5 instead of the crack band.
Pull pull(double h, bool local) {
  const Grid<2> gr = grid(length + 3 * h, height, h);
  Settings s;
  s.walls = {Wall{Wall::Type::roller}, Wall{}, Wall{Wall::Type::roller}, Wall{}};
  s.platens.push_back({Vec<2>(length - 0.25 * h, -1), Vec<2>(length + 3 * h, 1), 0, 0, speed});
  auto particles = block(gr, {0, 0}, {length, height}, coal.density, 2);
  const double band = 0.5 * length;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const double x = particles.x[i].x();
    particles.material[i] = x > band && x < band + h ? 1 : x < 3 * h || x > length - 3 * h ? 2 : 0;
    // Already stretching as the plate will stretch it: no wave at the start.
    particles.v[i].x() = speed * x / length;
  }
  std::vector<std::unique_ptr<Material>> materials;
  for (double share : {1.0, weak, grip}) {
    DamageParameters d{1e6, 0.5, share * strength, residual, 5.0, std::nullopt};
    if (!local) {
      d.fracture_energy = fracture_energy;
      d.band_width = h;
    }
    materials.push_back(std::make_unique<ElasticDamage>("coal", coal, d));
  }
  Solver solver(gr, std::move(materials), std::move(particles), s);
  // Well past the break the crack band predicts: the plate stretches the bar
  // to its peak, then the band opens by about G_f / f_tr.
  const double eps_t0 = weak * strength / coal.youngs_modulus;
  const double end = 2 * (length * eps_t0 + fracture_energy / (residual * weak * strength));
  Pull r{0, 0};
  while (solver.platen_displacement()[0] < end) {
    solver.step(solver.stable_time_step());
    r.peak_force = std::max(r.peak_force, solver.platen_force()[0]);
  }
  r.dissipated_per_area = solver.energies().damage / height;
  return r;
}

}  // namespace

TEST_CASE("crack band: a bar pulled apart dissipates the same energy per crack area at every resolution",
          "[mpm][fracture]") {
  std::printf("\nbar pulled apart, G_f = %.3f J/m2\n%8s %22s %22s %12s\n", fracture_energy, "cell [m]",
              "crack band [J/m2]", "local law [J/m2]", "peak [kN/m]");
  std::vector<double> banded, local;
  for (double h : {0.025, 0.0125, 0.00625, 0.003125}) {
    const Pull b = pull(h, false), l = pull(h, true);
    banded.push_back(b.dissipated_per_area);
    local.push_back(l.dissipated_per_area);
    std::printf("%8.4f %22.4f %22.4f %12.3f\n", h, b.dissipated_per_area, l.dissipated_per_area, b.peak_force / 1e3);
    // The peak: the weak band's strength over the bar's height (the plate's
    // reaction carries the explicit steps' waves: a few per cent).
    CHECK(b.peak_force == Approx(weak * strength * height).epsilon(0.06));
    // At least G_f (the band breaks through), at most twice it (two cells).
    CHECK(b.dissipated_per_area > fracture_energy);
    CHECK(b.dissipated_per_area < 2 * fracture_energy);
  }
  const auto [low, high] = std::minmax_element(banded.begin(), banded.end());
  std::printf("crack band: largest / smallest %.3f; local law, coarsest / finest %.3f\n", *high / *low,
              local.front() / local.back());
  CHECK(*high / *low < 1.15);
  // The local law's dissipation shrinks with the cell.
  CHECK(local.front() / local.back() > 2);
}
