#include "mpm_solid/material.hpp"

#include <cmath>

namespace outburst::mpm {

double Elasticity::p_wave_speed() const {
  return std::sqrt((lame_lambda() + 2 * shear_modulus()) / density);
}

void LinearElastic::update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const {
  const double lambda = elasticity().lame_lambda(), g = elasticity().shear_modulus();
  const int n = static_cast<int>(members.size());
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n; ++k) {
    const int i = members[k];
    const Mat<2>& l = p.velocity_gradient[i];
    const Mat<2> d = 0.5 * (l + l.transpose());  // rate of deformation
    const Mat<2> w = 0.5 * (l - l.transpose());  // spin
    const double trace = d.trace();               // plane strain: d_zz = 0
    Mat<2>& s = p.stress[i];
    // sigma' = sigma + dt (C : D + W sigma - sigma W)
    const Mat<2> rotation = w * s - s * w;
    s += dt * (lambda * trace * Mat<2>::Identity() + 2 * g * d + rotation);
    p.stress_zz[i] += dt * lambda * trace;
  }
}

}  // namespace outburst::mpm
