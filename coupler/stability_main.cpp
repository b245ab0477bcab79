// coupling-stability: what coupler/stability.hpp predicts for a coupled scene
// with Biot storage: the growth rate of every window scheme at the scene's
// window, as CSV on standard output (cases/terzaghi/stability_map.py plots it).
#include <cstdio>

#include <fmt/format.h>

#include "common/program.hpp"
#include "coupler/model.hpp"

using namespace outburst;

namespace {

template <int Dim>
int run_in(const RunOptions& options, scene::Document& doc) {
  const coupling::CoupledSetup<Dim> setup = coupling::read_coupled_scene<Dim>(doc.root());
  if (!finish_reading(options, doc)) return 0;
  if (!setup.coupling.gas_solid.biot_storage)
    throw scene::Error(fmt::format("{}: the stability analysis is of the Biot storage coupling: set "
                                   "coupling.biot_storage = true",
                                   doc.file().string()));
  const auto regimes = coupling::poroelastic_regimes(setup);
  std::puts("scheme,window_pressure,fixed_stress,window_s,growth_per_s,wavelength_m,stable");
  using coupling::stability::Pressure;
  for (const bool iterated : {true, false})
    for (const Pressure pressure : {Pressure::ramp, Pressure::end})
      for (const bool fixed_stress : {false, true}) {
        // Iterated to convergence, the fixed-stress terms cancel: one row.
        if (iterated && fixed_stress) continue;
        const coupling::stability::Window w{iterated, fixed_stress, pressure, setup.coupling.window};
        coupling::stability::Growth worst{-1e300, 0};
        for (const auto& r : regimes)
          if (const auto g = coupling::stability::growth(r, w); g.rate > worst.rate) worst = g;
        std::printf("%s\n", fmt::format("{},{},{},{:.6g},{:.6g},{:.6g},{}", iterated ? "implicit" : "explicit",
                                        pressure == Pressure::ramp ? "ramp" : "end", fixed_stress ? 1 : 0, w.size,
                                        worst.rate, 2 * 3.141592653589793 / worst.wavenumber,
                                        worst.rate <= 0 ? 1 : 0)
                                .c_str());
      }
  return 0;
}

int run(const RunOptions& options, scene::Document& doc) {
  return coupling::coupled_dimension(doc.root()) == 2 ? run_in<2>(options, doc) : run_in<3>(options, doc);
}

}  // namespace

int main(int argc, char** argv) {
  return run_program("coupling-stability",
                     "Predicted growth rate of each poroelastic window scheme for a coupled scene (CSV)", argc, argv,
                     run);
}
