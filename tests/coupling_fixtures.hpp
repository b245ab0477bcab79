#pragma once
// Coupled set-ups built in code for the coupler's tests.

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

}  // namespace outburst::testing
