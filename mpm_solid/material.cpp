#include "mpm_solid/material.hpp"

#include <cmath>
#include <tuple>

namespace outburst::mpm {

double Elasticity::p_wave_speed() const {
  return std::sqrt((lame_lambda() + 2 * shear_modulus()) / density);
}

void elastic_trial(const Elasticity& e, const Mat<2>& l, double dt, Mat<2>& s, double& s_zz) {
  const Mat<2> d = 0.5 * (l + l.transpose());  // rate of deformation
  const Mat<2> w = 0.5 * (l - l.transpose());  // spin
  const double trace = d.trace();               // plane strain: d_zz = 0
  // sigma' = sigma + dt (C : D + W sigma - sigma W)
  const Mat<2> rotation = w * s - s * w;
  s += dt * (e.lame_lambda() * trace * Mat<2>::Identity() + 2 * e.shear_modulus() * d + rotation);
  s_zz += dt * e.lame_lambda() * trace;
}

double LinearElastic::update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const {
  const int n = static_cast<int>(members.size());
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n; ++k) {
    const int i = members[k];
    elastic_trial(elasticity(), p.velocity_gradient[i], dt, p.stress[i], p.stress_zz[i]);
  }
  return 0;
}

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

DruckerPrager::DruckerPrager(std::string name, Elasticity elasticity, double cohesion, double friction_angle,
                             double dilation_angle, DruckerPragerFit::Kind fit)
    : Material(std::move(name), elasticity) {
  std::tie(alpha_, k_) = DruckerPragerFit::coefficients(fit, cohesion, friction_angle);
  alpha_dilation_ = DruckerPragerFit::coefficients(fit, 0.0, dilation_angle).first;
}

namespace {

// Mean stress and deviator of a plane-strain state (zz included in both).
struct Invariants {
  double mean;        // I1 / 3
  Mat<2> deviator;    // in-plane part of s
  double deviator_zz;
  double sqrt_j2;
};

Invariants invariants(const Mat<2>& s, double s_zz) {
  Invariants r;
  r.mean = (s.trace() + s_zz) / 3;
  r.deviator = s - r.mean * Mat<2>::Identity();
  r.deviator_zz = s_zz - r.mean;
  r.sqrt_j2 = std::sqrt(0.5 * (r.deviator.squaredNorm() + r.deviator_zz * r.deviator_zz));
  return r;
}

}  // namespace

double Material::strain_energy_density(const Mat<2>& s, double s_zz) const {
  const auto inv = invariants(s, s_zz);
  const double g = elasticity_.shear_modulus(), bulk = elasticity_.lame_lambda() + 2.0 / 3.0 * g;
  return inv.sqrt_j2 * inv.sqrt_j2 / (2 * g) + inv.mean * inv.mean / (2 * bulk);
}

double DruckerPrager::yield(const Mat<2>& s, double s_zz) const {
  const auto inv = invariants(s, s_zz);
  return alpha_ * inv.mean + inv.sqrt_j2 - k_;
}

double DruckerPrager::return_map(Mat<2>& s, double& s_zz, double* work_density) const {
  const auto inv = invariants(s, s_zz);
  const double f = alpha_ * inv.mean + inv.sqrt_j2 - k_;
  if (f <= 0) return 0;
  const double g = elasticity().shear_modulus();
  const double bulk = elasticity().lame_lambda() + 2.0 / 3.0 * g;
  // Flow along dg/dsigma = (alpha_d / 3) I + s / (2 sqrt(J2)): the mean stress
  // drops by K alpha_d dlambda and sqrt(J2) by G dlambda.
  double dlambda = f / (g + bulk * alpha_ * alpha_dilation_);
  double mean = inv.mean - bulk * alpha_dilation_ * dlambda;
  double sqrt_j2 = inv.sqrt_j2 - g * dlambda;
  if (sqrt_j2 < 0) {
    // Past the apex (only a cone with alpha > 0 has one): the only admissible
    // state is hydrostatic tension at the apex.
    mean = k_ / alpha_;
    sqrt_j2 = 0;
    dlambda = inv.sqrt_j2 / g;
  }
  const double scale = inv.sqrt_j2 > 0 ? sqrt_j2 / inv.sqrt_j2 : 0.0;
  s = mean * Mat<2>::Identity() + scale * inv.deviator;
  s_zz = mean + scale * inv.deviator_zz;
  // Plastic work sigma : C^-1 : (sigma_trial - sigma): the deviator only shrinks
  // along itself, so its part is sqrt(J2) (sqrt(J2)_trial - sqrt(J2)) / G.
  if (work_density)
    *work_density = sqrt_j2 * (inv.sqrt_j2 - sqrt_j2) / g + mean * (inv.mean - mean) / bulk;
  return dlambda;
}

double DruckerPrager::update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const {
  const int n = static_cast<int>(members.size());
  // Equivalent plastic strain per unit multiplier: sqrt(2/3 |dg/dsigma|^2).
  const double strain_per_multiplier = std::sqrt(2.0 / 3.0 * (0.5 + alpha_dilation_ * alpha_dilation_ / 3));
  double dissipated = 0;
#pragma omp parallel for schedule(static) reduction(+ : dissipated)
  for (int k = 0; k < n; ++k) {
    const int i = members[k];
    elastic_trial(elasticity(), p.velocity_gradient[i], dt, p.stress[i], p.stress_zz[i]);
    double work = 0;
    const double multiplier = return_map(p.stress[i], p.stress_zz[i], &work);
    if (multiplier == 0) continue;
    p.plastic_strain[i] += strain_per_multiplier * multiplier;
    dissipated += p.volume[i] * work;
  }
  return dissipated;
}

}  // namespace outburst::mpm
