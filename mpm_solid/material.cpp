#include "mpm_solid/material.hpp"

#include <cmath>
#include <algorithm>
#include <map>
#include <stdexcept>

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

Invariants invariants(const Mat<2>& s, double s_zz) {
  Invariants r;
  r.mean = (s.trace() + s_zz) / 3;
  r.deviator = s - r.mean * Mat<2>::Identity();
  r.deviator_zz = s_zz - r.mean;
  r.sqrt_j2 = std::sqrt(0.5 * (r.deviator.squaredNorm() + r.deviator_zz * r.deviator_zz));
  return r;
}

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

namespace {

std::map<std::string_view, MaterialModel>& registry() {
  static std::map<std::string_view, MaterialModel> models;
  return models;
}

}  // namespace

bool register_material(const MaterialModel& model) {
  if (!registry().emplace(model.name, model).second)
    throw std::logic_error(fmt::format("two material models named \"{}\"", model.name));
  return true;
}

const std::vector<MaterialModel>& material_models() {
  static const std::vector<MaterialModel> models = [] {
    std::vector<MaterialModel> v;
    for (const auto& [name, model] : registry()) v.push_back(model);
    return v;
  }();
  return models;
}

}  // namespace outburst::mpm
