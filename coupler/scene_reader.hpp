#pragma once
// Reads the [coupling] section of a scene: the scheme, the window, the
// acceleration, the convergence measures, and the gas-solid physics (Biot
// coefficient, permeability law, open space). `outburst SCENE --explain` lists
// every key with its default and meaning.

#include <optional>

#include "common/scene.hpp"
#include "coupler/coupling.hpp"
#include "coupler/gas_solid.hpp"
#include "coupler/stability.hpp"

namespace outburst::coupling {

struct CouplingSetup {
  SchemeSettings scheme;
  double window = 0;                 // [s]
  GasSolidSettings gas_solid;
  bool total_initial_stress = true;  // MPM bodies' initial stresses are total: add alpha p0
  // Fixed-stress split: GasSolidSettings::fixed_stress = alpha^2 / K_dr, K_dr
  // the smallest drained bulk modulus of the MPM materials. Unset: off, unless
  // the "auto" window pressure turns it on (read_coupled_setup).
  std::optional<bool> fixed_stress_split;
  // With Biot storage, the pressure the solid feels within a window; unset
  // ("auto"): read_coupled_setup picks it by coupler/stability.hpp.
  std::optional<stability::Pressure> window_pressure;
  // Run a scheme the analysis predicts unstable instead of refusing it (to
  // measure the stability map).
  bool allow_unstable = false;
};

CouplingSetup read_coupling(const scene::Table& coupling);

}  // namespace outburst::coupling
