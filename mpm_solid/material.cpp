#include "mpm_solid/material.hpp"

#include <algorithm>
#include <cmath>

#include "common/registry.hpp"

namespace outburst::mpm {

double Elasticity::p_wave_speed() const {
  return std::sqrt((lame_lambda() + 2 * shear_modulus()) / density);
}

template <int Dim>
Dissipation Material<Dim>::update_stress(Particles<Dim>& p, const std::vector<int>& members, double dt) const {
  require_velocity_gradients(p, members);
  return over_chunks(members, [&](std::span<const int> part) { return update_chunk(p, part, dt, nullptr); });
}

template <int Dim>
double Material<Dim>::strain_energy(const Particles<Dim>& p, const std::vector<int>& members) const {
  return sum_over(members, [&](int i) {
    const double zz = Dim == 2 ? p.stress_zz[i] : 0.0;
    return 0.5 * p.volume[i] * compliance_product(p.stress[i], zz, p.stress[i], zz);
  });
}

template class Material<2>;
template class Material<3>;

std::pair<double, double> DruckerPragerFit::coefficients(Kind kind, double c, double phi) {
  const double s = std::sin(phi), co = std::cos(phi), sqrt3 = std::sqrt(3.0);
  switch (kind) {
    case Kind::outer:  // through the compression corners of Mohr-Coulomb (the paper's)
      return {6 * s / (sqrt3 * (3 - s)), 6 * c * co / (sqrt3 * (3 - s))};
    case Kind::inner:  // through the extension corners
      return {6 * s / (sqrt3 * (3 + s)), 6 * c * co / (sqrt3 * (3 + s))};
    case Kind::plane_strain: {  // same collapse load as Mohr-Coulomb in plane strain
      const double t = std::tan(phi), root = std::sqrt(9 + 12 * t * t);
      return {3 * t / root, 3 * c / root};
    }
  }
  return {0, 0};
}

bool register_material(const MaterialModel& model) { return Registry<MaterialModel>::add(model, "material models"); }

const std::vector<MaterialModel>& material_models() { return Registry<MaterialModel>::all(); }

}  // namespace outburst::mpm
