#pragma once
// Reads the [coupling] section of a scene: the scheme, the window, the
// acceleration, the convergence measures, and the gas-solid physics (Biot
// coefficient, permeability law, open space). `outburst SCENE --explain` lists
// every key with its default and meaning.

#include "common/scene.hpp"
#include "coupler/coupling.hpp"
#include "coupler/gas_solid.hpp"

namespace outburst::coupling {

struct CouplingSetup {
  SchemeSettings scheme;
  double window = 0;                 // [s]
  GasSolidSettings gas_solid;
  bool total_initial_stress = true;  // MPM bodies' initial stresses are total: add alpha p0
  // Fixed-stress split: GasSolidSettings::fixed_stress = alpha^2 / K_dr, K_dr
  // the smallest drained bulk modulus of the MPM materials.
  bool fixed_stress_split = false;
};

CouplingSetup read_coupling(const scene::Table& coupling);

}  // namespace outburst::coupling
