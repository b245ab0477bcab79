#pragma once
// Coupled set-ups built in code for the coupler's tests.

#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include "coupler/coupling.hpp"
#include "coupler/gas_solid.hpp"

namespace outburst::testing {

// The seepage's pressure driving the solid one way (alpha times it, no
// permeability coupling, nothing sent back), window by window.
template <int Dim>
struct OneWay {
  coupling::GasSolidSettings settings;
  coupling::SeepageParticipant<Dim> seepage_side;
  coupling::MeshMapping<Dim> map;
  coupling::SolidParticipant<Dim> solid_side;
  coupling::Coupling coupling;

  OneWay(seepage::SolverOf<Dim>& seep, mpm::Solver<Dim>& solid, double alpha)
      : settings(one_way_settings(alpha)),
        seepage_side(seep, settings),
        map(seep.sampler()),
        solid_side(solid, map, settings, seepage_side.read("pressure"), std::nullopt),
        coupling(seepage_side, solid_side, pressure_only()) {}
  OneWay(const OneWay&) = delete;
  OneWay& operator=(const OneWay&) = delete;

  void run_to(double end, double window) {
    while (coupling.time() < end) coupling.advance(window);
  }

 private:
  static coupling::GasSolidSettings one_way_settings(double alpha) {
    coupling::GasSolidSettings gs;
    gs.biot = alpha;
    gs.permeability_coupling = false;
    return gs;
  }
  static coupling::SchemeSettings pressure_only() {
    coupling::SchemeSettings scheme;
    scheme.kind = coupling::SchemeSettings::Kind::one_way;
    scheme.to_second = {"pressure"};
    return scheme;
  }
};

// Cell averages of 5000 scattered points (some beyond the mesh, which spans
// x = 0..4, y = 0..2 and in 3D z = 0..1) of two values each: the volume and
// both volume-weighted sums the cells hold are the points' inside the mesh.
template <int Dim>
void check_averages_conserve(const coupling::MeshMapping<Dim>& map, double particle_volume) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Matrix<double, Dim, 1>> x;
  std::vector<double> volume, values;
  double total_volume = 0, total_first = 0, total_second = 0;
  for (int k = 0; k < 5000; ++k) {
    Eigen::Matrix<double, Dim, 1> point;
    point.x() = 4.4 * u(random) - 0.2;
    point.y() = 2 * u(random);
    if constexpr (Dim == 3) point.z() = u(random);
    x.push_back(point);
    volume.push_back(particle_volume * (1 + u(random)));
    values.push_back(u(random));
    values.push_back(-5 * u(random));
    if (point.x() >= 0 && point.x() <= 4) {
      total_volume += volume.back();
      total_first += volume.back() * values[values.size() - 2];
      total_second += volume.back() * values.back();
    }
  }
  const auto avg = map.average(x, volume, values, 2);
  double mapped_volume = 0, mapped_first = 0, mapped_second = 0, cells = 0;
  for (std::size_t c = 0; c < map.mesh().num_cells(); ++c) {
    const double solid = avg.fraction[c] * map.cell_area()[c];
    cells += map.cell_area()[c];
    mapped_volume += solid;
    mapped_first += solid * avg.mean[2 * c];
    mapped_second += solid * avg.mean[2 * c + 1];
  }
  CHECK(cells == Approx(8.0).epsilon(1e-12));
  CHECK(mapped_volume == Approx(total_volume).epsilon(1e-12));
  CHECK(mapped_first == Approx(total_first).epsilon(1e-12));
  CHECK(mapped_second == Approx(total_second).epsilon(1e-12));
}

}  // namespace outburst::testing
