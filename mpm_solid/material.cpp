#include "mpm_solid/material.hpp"

#include <cmath>
#include <algorithm>
#include <limits>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>

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

namespace {

// Runs update(i), the stress update of particle i returning what it
// dissipated, over `members` in parallel, after carrying the particle's
// deformation gradient and volume over the step: one pass over the particles
// serves kinematics and constitution.
template <class Update>
Dissipation each_member(Particles<2>& p, const std::vector<int>& members, double dt, Update&& update) {
  const int n = static_cast<int>(members.size());
  double plastic = 0, damage = 0;
#pragma omp parallel for schedule(static) reduction(+ : plastic, damage)
  for (int k = 0; k < n; ++k) {
    const int i = members[k];
    p.deformation[i] = (Mat<2>::Identity() + dt * p.velocity_gradient[i]) * p.deformation[i];
    p.volume[i] = p.volume0[i] * p.deformation[i].determinant();
    const Dissipation d = update(i);
    plastic += d.plastic;
    damage += d.damage;
  }
  return {plastic, damage};
}

// Sum of f(i) over the members, in parallel.
template <class F>
double sum_over(const std::vector<int>& members, F&& f) {
  const int n = static_cast<int>(members.size());
  double sum = 0;
#pragma omp parallel for schedule(static) reduction(+ : sum)
  for (int k = 0; k < n; ++k) sum += f(members[k]);
  return sum;
}

}  // namespace

Dissipation LinearElastic::update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const {
  return each_member(p, members, dt, [&](int i) {
    elastic_trial(elasticity(), p.velocity_gradient[i], dt, p.stress[i], p.stress_zz[i]);
    return Dissipation{};
  });
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

double Material::compliance_product(const Mat<2>& a, double a_zz, const Mat<2>& b, double b_zz) const {
  const auto ia = invariants(a, a_zz), ib = invariants(b, b_zz);
  const double g = elasticity_.shear_modulus(), bulk = elasticity_.lame_lambda() + 2.0 / 3.0 * g;
  const double deviatoric = ia.deviator.cwiseProduct(ib.deviator).sum() + ia.deviator_zz * ib.deviator_zz;
  return deviatoric / (2 * g) + ia.mean * ib.mean / bulk;
}

double Material::strain_energy(const Particles<2>& p, const std::vector<int>& members) const {
  return sum_over(members, [&](int i) {
    return 0.5 * p.volume[i] * compliance_product(p.stress[i], p.stress_zz[i], p.stress[i], p.stress_zz[i]);
  });
}

double DruckerPrager::yield(const Mat<2>& s, double s_zz) const {
  const auto inv = invariants(s, s_zz);
  return alpha_ * inv.mean + inv.sqrt_j2 - k_;
}

double drucker_prager_return(double alpha, double k, double alpha_dilation, double g, double bulk, Mat<2>& s,
                             double& s_zz, double* work_density) {
  const auto inv = invariants(s, s_zz);
  const double f = alpha * inv.mean + inv.sqrt_j2 - k;
  if (f <= 0) return 0;
  // Flow along dg/dsigma = (alpha_d / 3) I + s / (2 sqrt(J2)): the mean stress
  // drops by K alpha_d dlambda and sqrt(J2) by G dlambda.
  double dlambda = f / (g + bulk * alpha * alpha_dilation);
  double mean = inv.mean - bulk * alpha_dilation * dlambda;
  double sqrt_j2 = inv.sqrt_j2 - g * dlambda;
  if (sqrt_j2 < 0) {
    // Past the apex (only a cone with alpha > 0 has one): the only admissible
    // state is hydrostatic tension at the apex.
    mean = k / alpha;
    sqrt_j2 = 0;
    dlambda = inv.sqrt_j2 / g;
  }
  const double scale = inv.sqrt_j2 > 0 ? sqrt_j2 / inv.sqrt_j2 : 0.0;
  s = mean * Mat<2>::Identity() + scale * inv.deviator;
  s_zz = mean + scale * inv.deviator_zz;
  // Plastic work sigma : C^-1 : (sigma_trial - sigma): the deviator only shrinks
  // along itself, so its part is sqrt(J2) (sqrt(J2)_trial - sqrt(J2)) / G.
  if (work_density) *work_density = sqrt_j2 * (inv.sqrt_j2 - sqrt_j2) / g + mean * (inv.mean - mean) / bulk;
  return dlambda;
}

double DruckerPrager::return_map(Mat<2>& s, double& s_zz, double* work_density) const {
  const double g = elasticity().shear_modulus();
  return drucker_prager_return(alpha_, k_, alpha_dilation_, g, elasticity().lame_lambda() + 2.0 / 3.0 * g, s, s_zz,
                               work_density);
}

Dissipation DruckerPrager::update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const {
  // Equivalent plastic strain per unit multiplier: sqrt(2/3 |dg/dsigma|^2).
  const double strain_per_multiplier = std::sqrt(2.0 / 3.0 * (0.5 + alpha_dilation_ * alpha_dilation_ / 3));
  return each_member(p, members, dt, [&](int i) {
    elastic_trial(elasticity(), p.velocity_gradient[i], dt, p.stress[i], p.stress_zz[i]);
    double work = 0;
    const double multiplier = return_map(p.stress[i], p.stress_zz[i], &work);
    if (multiplier == 0) return Dissipation{};
    p.plastic_strain[i] += strain_per_multiplier * multiplier;
    return Dissipation{p.volume[i] * work, 0};
  });
}

namespace {

// In-plane principal values (a >= b) and the unit vector of a.
struct Principal {
  double a, b;
  Vec<2> direction;
};

Principal principal(const Mat<2>& s) {
  const double centre = 0.5 * (s(0, 0) + s(1, 1));
  const double half = 0.5 * (s(0, 0) - s(1, 1));
  const double radius = std::sqrt(half * half + s(0, 1) * s(0, 1));
  if (radius == 0) return {centre, centre, Vec<2>(1, 0)};
  // Half-angle formulas from cos 2t = half / radius, sin 2t = s_xy / radius:
  // no trigonometric calls in the innermost loop of the damage law.
  const double cos2 = half / radius;
  const double c = std::sqrt(0.5 * (1 + cos2)), sn = std::copysign(std::sqrt(0.5 * (1 - cos2)), s(0, 1));
  return {centre + radius, centre - radius, Vec<2>(c, sn)};
}

Mat<2> compose(double a, double b, const Vec<2>& direction) {
  const Vec<2> normal(-direction.y(), direction.x());
  return a * direction * direction.transpose() + b * normal * normal.transpose();
}

// Open cracks: tensile principal parts scaled by (1 - D) (or back, by 1/(1 - D)).
double crack(double principal_value, double factor) {
  return principal_value > 0 ? factor * principal_value : principal_value;
}

}  // namespace

double largest_band_width(const DamageParameters& d, const Elasticity& e) {
  return d.fracture_energy ? 2 * e.youngs_modulus * *d.fracture_energy / (d.tensile_strength * d.tensile_strength)
                           : std::numeric_limits<double>::infinity();
}

ElasticDamage::ElasticDamage(std::string name, Elasticity elasticity, DamageParameters damage)
    : Material(std::move(name), elasticity), parameters_(damage) {
  const double eps_t0 = damage.tensile_strength / elasticity.youngs_modulus;
  if (!damage.fracture_energy) {
    ultimate_strain_ = damage.ultimate_ratio * eps_t0;
  } else {
    if (!(damage.band_width > 0 && damage.band_width <= largest_band_width(damage, elasticity) &&
          damage.residual_ratio > 0))
      throw std::invalid_argument(fmt::format(
          "material \"{}\": a crack band of {:g} m with G_f = {:g} J/m2 and a residual ratio of {:g} cannot hold",
          this->name(), damage.band_width, *damage.fracture_energy, damage.residual_ratio));
    const double per_volume = *damage.fracture_energy / damage.band_width;
    ultimate_strain_ =
        eps_t0 + (per_volume - 0.5 * damage.tensile_strength * eps_t0) / (damage.residual_ratio * damage.tensile_strength);
  }
  std::tie(alpha_, k0_) =
      DruckerPragerFit::coefficients(DruckerPragerFit::Kind::outer, damage.cohesion, damage.friction_angle);
  sin_phi_ = std::sin(damage.friction_angle);
  cos_phi_ = std::cos(damage.friction_angle);
  ucs_ = 2 * damage.cohesion * cos_phi_ / (1 - sin_phi_);
}

double ElasticDamage::damage(double previous, const Mat<2>& effective, double effective_zz) const {
  const auto& d = parameters_;
  const double e0 = elasticity().youngs_modulus, nu = elasticity().poisson_ratio;
  const Principal pr = principal(effective);
  const double s1 = std::max(pr.a, effective_zz), s3 = std::min(pr.b, effective_zz);
  const double s2 = pr.a + pr.b + effective_zz - s1 - s3;
  const auto strain = [&](double si, double sj, double sk) { return (si - nu * (sj + sk)) / e0; };
  double damage = previous;
  if (s1 >= d.tensile_strength) {
    const double eps1 = strain(s1, s2, s3);
    const double tensile =
        eps1 >= ultimate_strain_ ? 1.0 : 1 - d.residual_ratio * d.tensile_strength / (e0 * eps1);
    damage = std::max(damage, tensile);
  }
  if (0.5 * (s1 - s3) >= d.cohesion * cos_phi_ - 0.5 * (s1 + s3) * sin_phi_) {
    const double eps3 = strain(s3, s1, s2);
    if (eps3 < 0) damage = std::max(damage, 1 - d.residual_ratio * ucs_ / (e0 * -eps3));
  }
  return std::clamp(damage, 0.0, 1.0);
}

Dissipation ElasticDamage::update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const {
  const double g = elasticity().shear_modulus(), bulk = elasticity().lame_lambda() + 2.0 / 3.0 * g;
  return each_member(p, members, dt, [&](int i) {
    Dissipation dissipated;
    Mat<2>& effective = p.effective_stress[i];
    double& effective_zz = p.effective_stress_zz[i];
    elastic_trial(elasticity(), p.velocity_gradient[i], dt, effective, effective_zz);
    const double previous = p.damage[i];
    const double d = damage(previous, effective, effective_zz);
    p.damage[i] = d;
    // The stress acting: open cracks carry no share of tension.
    const Principal pr = principal(effective);
    Mat<2> s = compose(crack(pr.a, 1 - d), crack(pr.b, 1 - d), pr.direction);
    double s_zz = crack(effective_zz, 1 - d);
    if (d > previous) {
      // Y dD: the energy the cracks take at the strain they opened at.
      const Mat<2> before = compose(crack(pr.a, 1 - previous), crack(pr.b, 1 - previous), pr.direction);
      const double before_zz = crack(effective_zz, 1 - previous);
      dissipated.damage = 0.5 * p.volume[i] *
                          (compliance_product(before, before_zz, effective, effective_zz) -
                           compliance_product(s, s_zz, effective, effective_zz));
    }
    // Friction bounds compressive states, with the cohesion the cracks leave;
    // tension is the damage law's to soften (a cone there would cap the elastic
    // strain the damage is read from).
    double work = 0;
    const bool compressive = s.trace() + s_zz < 0;
    if (const double multiplier =
            compressive ? drucker_prager_return(alpha_, (1 - d) * k0_, 0.0, g, bulk, s, s_zz, &work) : 0.0;
        multiplier > 0) {
      p.plastic_strain[i] += multiplier / std::sqrt(3.0);  // no dilation: sqrt(2/3 |dg/dsigma|^2) = 1/sqrt(3)
      dissipated.plastic = p.volume[i] * work;
      // Carry the return back to the undamaged stress (same principal axes).
      const Principal back = principal(s);
      const double open = d < 1 ? 1 / (1 - d) : 0.0;
      effective = compose(crack(back.a, open), crack(back.b, open), back.direction);
      effective_zz = crack(s_zz, open);
    }
    p.stress[i] = s;
    p.stress_zz[i] = s_zz;
    if (d >= 1) p.volume[i] = std::min(p.volume[i], parameters_.bulking_factor * p.volume0[i]);
    return dissipated;
  });
}

double ElasticDamage::strain_energy(const Particles<2>& p, const std::vector<int>& members) const {
  return sum_over(members, [&](int i) {
    return 0.5 * p.volume[i] *
           compliance_product(p.stress[i], p.stress_zz[i], p.effective_stress[i], p.effective_stress_zz[i]);
  });
}

}  // namespace outburst::mpm
