#include "mpm_solid/materials/elastic_damage.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <variant>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "mpm_solid/materials/principal.hpp"
#include "mpm_solid/nonlocal.hpp"

namespace outburst::mpm {

double largest_band_width(const DamageParameters& d, const Elasticity& e) {
  return d.fracture_energy ? 2 * e.youngs_modulus * *d.fracture_energy / (d.tensile_strength * d.tensile_strength)
                           : std::numeric_limits<double>::infinity();
}

template <int Dim>
ElasticDamage<Dim>::ElasticDamage(std::string name, Elasticity elasticity, DamageParameters damage)
    : Material<Dim>(std::move(name), elasticity), parameters_(damage) {
  if (!damage.fracture_energy) {
    ultimate_strain_ = damage.ultimate_ratio * (damage.tensile_strength / elasticity.youngs_modulus);
  } else {
    if (!(damage.band_width > 0 && damage.band_width <= largest_band_width(damage, elasticity)))
      throw std::invalid_argument(fmt::format(
          "material \"{}\": a crack band {:g} m wide with G_f = {:g} J/m2 (at most 2 E G_f / f_t^2 = {:g} m)",
          this->name(), damage.band_width, *damage.fracture_energy, largest_band_width(damage, elasticity)));
    // The area under linear softening, f_t eps_tu / 2, times the band's width.
    ultimate_strain_ = 2 * *damage.fracture_energy / (damage.band_width * damage.tensile_strength);
  }
  std::tie(alpha_, k0_) =
      DruckerPragerFit::coefficients(DruckerPragerFit::Kind::outer, damage.cohesion, damage.friction_angle);
  sin_phi_ = std::sin(damage.friction_angle);
  cos_phi_ = std::cos(damage.friction_angle);
  ucs_ = 2 * damage.cohesion * cos_phi_ / (1 - sin_phi_);
}

namespace {

// splitmix64's finaliser (Steele, Lea & Flood 2014).
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Inverse of F(u) = 1 - exp(-(u / u0)^m) at the uniform draw in [0, 1) that
// `bits` carry, with u0 = 1 / Gamma(1 + 1/m) for a mean of 1.
double weibull(double m, std::uint64_t bits) {
  const double uniform = static_cast<double>(bits >> 11) * 0x1p-53;
  const double u0 = 1 / std::tgamma(1 + 1 / m);
  return u0 * std::pow(-std::log1p(-uniform), 1 / m);
}

std::uint64_t strength_bits(const DamageParameters::Heterogeneity& h, std::int64_t id) {
  return mix(h.seed ^ mix(static_cast<std::uint64_t>(id)));
}

}  // namespace

double weibull_strength_scale(const DamageParameters::Heterogeneity& h, std::int64_t id) {
  return weibull(h.homogeneity_index, strength_bits(h, id));
}

double weibull_modulus_scale(const DamageParameters::Heterogeneity& h, std::int64_t id) {
  // A second hash of the strength's bits: independent of the strength's
  // draw, and a function of the seed and the id alone.
  return weibull(h.modulus_index(), mix(strength_bits(h, id)));
}

template <int Dim>
std::int64_t DamageParameters::Heterogeneity::key(std::int64_t id, const Vec<Dim>& x0) const {
  if (!grain_size) return id;
  std::array<std::int64_t, Dim> grain;
  for (int d = 0; d < Dim; ++d) grain[d] = static_cast<std::int64_t>(std::floor(x0[d] / *grain_size));
  return static_cast<std::int64_t>(bin_key<Dim>(grain));
}

template std::int64_t DamageParameters::Heterogeneity::key<2>(std::int64_t, const Vec<2>&) const;
template std::int64_t DamageParameters::Heterogeneity::key<3>(std::int64_t, const Vec<3>&) const;

template <int Dim>
void ElasticDamage<Dim>::create_fields(Particles<Dim>& p, const std::vector<int>& members) const {
  p.need_plastic_strain();
  p.need_damage();
  if (parameters_.internal_length) p.need("nonlocal damage");
  if (!parameters_.heterogeneity) return;
  p.need("heterogeneity");
  const auto& h = *parameters_.heterogeneity;
  for (const int i : members) {
    p.strength_scale[i] = weibull_strength_scale(h, h.key<Dim>(p.id[i], p.x0[i]));
    p.modulus_scale[i] = weibull_modulus_scale(h, h.key<Dim>(p.id[i], p.x0[i]));
  }
}

template <int Dim>
struct ElasticDamage<Dim>::Stresses {
  // In the plane, the in-plane matrix's, made once for the damage law and
  // the acting stress. In 3D each makes its own: intact coal needs no axes,
  // and shared, the 3D outburst moved by round-off (6e-7 of the stress by
  // 0.05 s, on one thread without FP contraction), which no isolated test of
  // the decomposition reproduced.
  std::conditional_t<Dim == 2, Principal<2>, std::monostate> principal;
  double s1, s2, s3;    // s1 >= s2 >= s3, out-of-plane included
  double eps1, eps3;    // the strains along s1 and s3
};

template <int Dim>
template <class Plane>
[[gnu::always_inline]] inline typename ElasticDamage<Dim>::Stresses ElasticDamage<Dim>::plane_stresses(
    const Plane& pr, double effective_zz, double stiffness) const {
  const double e0 = stiffness * this->elasticity().youngs_modulus, nu = this->elasticity().poisson_ratio;
  const double s1 = std::max(pr.largest(), effective_zz), s3 = std::min(pr.smallest(), effective_zz);
  const double s2 = pr.sum() + effective_zz - s1 - s3;
  return {pr, s1, s2, s3, (s1 - nu * (s2 + s3)) / e0, (s3 - nu * (s1 + s2)) / e0};
}

template <int Dim>
typename ElasticDamage<Dim>::Stresses ElasticDamage<Dim>::principal_stresses(const Mat<Dim>& effective,
                                                                             double effective_zz,
                                                                             double stiffness) const {
  if constexpr (Dim == 2) {
    return plane_stresses(Principal<2>(effective), effective_zz, stiffness);
  } else {
    // The values alone: the closed form is accurate for them, less so for
    // the axes of nearly equal ones.
    const double e0 = stiffness * this->elasticity().youngs_modulus, nu = this->elasticity().poisson_ratio;
    Eigen::SelfAdjointEigenSolver<Mat<3>> solver;
    solver.computeDirect(effective, Eigen::EigenvaluesOnly);
    const double s1 = solver.eigenvalues()[2], s2 = solver.eigenvalues()[1], s3 = solver.eigenvalues()[0];
    return {{}, s1, s2, s3, (s1 - nu * (s2 + s3)) / e0, (s3 - nu * (s1 + s2)) / e0};
  }
}

// The damage law in straight-line code, as Principal<2> is.
template <int Dim>
[[gnu::always_inline]] inline double ElasticDamage<Dim>::shear_damage(const Stresses& s, double scale,
                                                                      double stiffness) const {
  const auto& d = parameters_;
  const bool intact =
      0.5 * (s.s1 - s.s3) < scale * d.cohesion * cos_phi_ - 0.5 * (s.s1 + s.s3) * sin_phi_ || s.eps3 >= 0;
  const double crushed = 1 - d.residual_ratio * scale * ucs_ / (stiffness * this->elasticity().youngs_modulus * -s.eps3);
  return intact ? 0.0 : crushed;
}

template <int Dim>
double ElasticDamage<Dim>::damage(double previous, const Mat<Dim>& effective, double effective_zz, double scale,
                                  double stiffness) const {
  return damage(previous, principal_stresses(effective, effective_zz, stiffness), scale, stiffness);
}

template <int Dim>
double ElasticDamage<Dim>::damage(double previous, const Stresses& st, double scale, double stiffness) const {
  return parameters_.fracture_energy ? damage<true>(previous, st, scale, stiffness)
                                     : damage<false>(previous, st, scale, stiffness);
}

// Band: a crack band's law, else the paper's. A template parameter, since
// GCC vectorises no choice between them by a flag it must load.
template <int Dim>
template <bool Band>
[[gnu::always_inline]] inline double ElasticDamage<Dim>::damage(double previous, const Stresses& st, double scale,
                                                                double stiffness) const {
  const auto& d = parameters_;
  const double e0 = stiffness * this->elasticity().youngs_modulus;
  const double s1 = st.s1, eps1 = st.eps1;
  // The paper's law keeps the residual share of E0 eps_1. A crack band
  // instead carries a share of f_t that falls linearly in eps_1 from the
  // onset, the strain at which this stress state reached f_t (eps_1 f_t /
  // sigma~_1 under proportional loading), to nothing at eps_tu: the area
  // under the curve is f_t eps_tu / 2 = G_f / w whatever holds the band's
  // sides. (In E0 eps_1, the paper's form carries (lambda + 2G) / E0 times
  // more under lateral constraint, and a fixed onset f_t / E0 adds a plateau
  // at f_t: both make the band dissipate more.) Where it is chosen (sigma~_1
  // >= f_t, eps_1 < eps_tu), onset <= eps1 < ultimate: the band's
  // denominator is positive.
  const double ultimate = scale / stiffness * ultimate_strain_;
  double softened;
  if constexpr (Band) {
    const double onset = eps1 * scale * d.tensile_strength / s1;
    softened = 1 - (ultimate - eps1) / (ultimate - onset) * scale * d.tensile_strength / s1;
  } else {
    softened = 1 - d.residual_ratio * scale * d.tensile_strength / (e0 * eps1);
  }
  const double tensile = eps1 < ultimate ? softened : 1.0;
  const double damage = s1 >= scale * d.tensile_strength ? std::max(previous, tensile) : previous;
  return std::min(std::max(std::max(damage, shear_damage(st, scale, stiffness)), 0.0), 1.0);
}

template <int Dim>
double ElasticDamage<Dim>::driving_strain(const Mat<Dim>& effective, double effective_zz, double scale,
                                          double stiffness) const {
  const double at_strength = scale * parameters_.tensile_strength / (stiffness * this->elasticity().youngs_modulus);
  return std::clamp(principal_stresses(effective, effective_zz, stiffness).eps1 / at_strength, 0.0,
                    parameters_.ultimate_ratio);
}

template <int Dim>
double ElasticDamage<Dim>::nonlocal_tensile_damage(double averaged) const {
  const double eta = parameters_.ultimate_ratio;
  if (averaged <= 1) return 0;
  if (averaged >= eta) return 1;
  return 1 - (eta - averaged) / ((eta - 1) * averaged);
}

template <int Dim>
double ElasticDamage<Dim>::strength_scale(const Particles<Dim>& p, int i) const {
  return parameters_.heterogeneity ? p.strength_scale[i] : 1.0;
}

template <int Dim>
double ElasticDamage<Dim>::modulus_scale(const Particles<Dim>& p, int i) const {
  return parameters_.heterogeneity ? p.modulus_scale[i] : 1.0;
}

template <int Dim>
void ElasticDamage<Dim>::trial(Particles<Dim>& p, std::span<const int> members, double dt,
                               const double* gradients) const {
  // lambda and G scale with E
  deform_and_trial(p, members, dt, this->lame_lambda(), this->shear_modulus(),
                   parameters_.heterogeneity ? &p.modulus_scale : nullptr, p.effective_stress,
                   p.effective_stress_zz, gradients);
}

// The acting stress at damage d, what the growth of damage took, and the
// friction of compressive states.
template <int Dim>
Dissipation ElasticDamage<Dim>::settle(Particles<Dim>& p, int i, double d, const Stresses& st) const {
  const double stiffness = modulus_scale(p, i);
  const double g = stiffness * this->shear_modulus();
  const double bulk = stiffness * this->lame_lambda() + 2.0 / 3.0 * g;
  Dissipation dissipated;
  Mat<Dim>& effective = p.effective_stress[i];
  double none = 0;
  double& effective_zz = out_of_plane<Dim>(p.effective_stress_zz, i, none);
  const double previous = p.damage[i];
  p.damage[i] = d;
  // The stress acting: open cracks carry no share of tension. Intact 3D coal
  // (d = 0, and no less before) acts with its undamaged stress as it is: a
  // decomposition and recomposition would move it by roundoff every step.
  const bool intact = Dim == 3 && d == 0;
  std::optional<Principal<Dim>> pr;
  if constexpr (Dim == 2)
    pr.emplace(st.principal);
  else if (!intact)
    pr.emplace(effective);
  Mat<Dim> s = intact ? effective : pr->cracked(1 - d);
  double s_zz = crack(effective_zz, 1 - d);
  if (d > previous) {
    // Y dD: the energy the cracks take at the strain they opened at.
    const Mat<Dim> before = pr->cracked(1 - previous);
    const double before_zz = crack(effective_zz, 1 - previous);
    dissipated.damage = 0.5 * p.volume[i] *
                        (this->compliance_product(before, before_zz, effective, effective_zz) -
                         this->compliance_product(s, s_zz, effective, effective_zz)) /
                        stiffness;
  }
  // Friction bounds compressive states, with the cohesion the cracks leave;
  // tension is the damage law's to soften (a cone there would cap the elastic
  // strain the damage is read from).
  double work = 0;
  const bool compressive = s.trace() + s_zz < 0;
  if (const double multiplier =
          compressive ? drucker_prager_return<Dim>(alpha_, (1 - d) * strength_scale(p, i) * k0_, 0.0, g, bulk, s, s_zz, &work)
                      : 0.0;
      multiplier > 0) {
    p.plastic_strain[i] += multiplier / std::sqrt(3.0);  // no dilation: sqrt(2/3 |dg/dsigma|^2) = 1/sqrt(3)
    dissipated.plastic = p.volume[i] * work;
    // Carry the return back to the undamaged stress (same principal axes).
    if (intact) {
      effective = s;
    } else {
      const Principal<Dim> back(s);
      const double open = d < 1 ? 1 / (1 - d) : 0.0;
      effective = back.cracked(open);
      effective_zz = crack(s_zz, open);
    }
  }
  p.stress[i] = s;
  if constexpr (Dim == 2) p.stress_zz[i] = s_zz;
  if (d >= 1) p.volume[i] = std::min(p.volume[i], parameters_.bulking_factor * p.volume0[i]);
  return dissipated;
}

template <int Dim>
Dissipation ElasticDamage<Dim>::update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                                             const double* gradients) const {
  if (!pointwise()) throw std::logic_error("nonlocal damage updates a material's particles together (update_stress)");
  trial(p, members, dt, gradients);
  if constexpr (Dim == 2) {
    // The solver's chunks are chunk_size long; a longer call in pieces of it,
    // the lanes' verdicts' length.
    Dissipation total;
    for (std::size_t first = 0; first < members.size(); first += chunk_size) {
      const auto part = members.subspan(first, std::min<std::size_t>(chunk_size, members.size() - first));
      total += by_position(part, [&](auto index) {
        const auto with_band = [&]<bool Drawn>() {
          return parameters_.fracture_energy ? settle_plane<Drawn, true>(p, part, index)
                                             : settle_plane<Drawn, false>(p, part, index);
        };
        return parameters_.heterogeneity ? with_band.template operator()<true>()
                                         : with_band.template operator()<false>();
      });
    }
    return total;
  } else {
    return each_member(members, [&](int i) { return update_alone(p, i); });
  }
}

template <int Dim>
Dissipation ElasticDamage<Dim>::update_alone(Particles<Dim>& p, int i) const {
  const double stiffness = modulus_scale(p, i), zz = Dim == 2 ? p.effective_stress_zz[i] : 0.0;
  const Stresses st = principal_stresses(p.effective_stress[i], zz, stiffness);
  return settle(p, i, damage(p.damage[i], st, strength_scale(p, i), stiffness), st);
}

namespace {

// settle's friction for one lane of settle_plane: drucker_prager_return with
// no dilation, as written there (Eigen's deviator s - mean I and stress mean
// I + ratio deviator entry by entry, and the squared norm's pairs as its
// packets sum them), of the acting stress s (Eigen's column-major order)
// with moduli g and bulk and the cone's alpha and cohesion.
struct PlaneReturn {
  double sum, f;                     // the trial's I1 and yield function
  double r00, r10, r01, r11, r_zz;   // the stress returned to the cone
  double work, multiplier;           // plastic work density, plastic multiplier
};

[[gnu::always_inline]] inline PlaneReturn plane_friction_return(double s0, double s1, double s2, double s3,
                                                                double s_zz, double g, double bulk, double alpha,
                                                                double cohesion) {
  const double sum = s0 + s3 + s_zz, mean = sum / 3;
  const double d00 = s0 - mean * 1.0, d10 = s1 - mean * 0.0, d01 = s2 - mean * 0.0, d11 = s3 - mean * 1.0;
  const double d_zz = s_zz - mean;
  const double squared = (d00 * d00 + d01 * d01) + (d10 * d10 + d11 * d11);
  const double sqrt_j2 = std::sqrt(0.5 * (squared + d_zz * d_zz));
  const double f = alpha * mean + sqrt_j2 - cohesion;
  const double along = f / (g + bulk * alpha * 0.0);
  const double shrunk = sqrt_j2 - g * along;
  // A return that overshoots the cone's tip ends at the tip, as
  // drucker_prager_return's does (without friction, at the mean stress).
  const double tip = alpha > 0 ? cohesion / alpha : mean;
  const double to_mean = shrunk < 0 ? tip : mean - bulk * 0.0 * along;
  const double to_sqrt_j2 = shrunk < 0 ? 0.0 : shrunk;
  const double multiplier = shrunk < 0 ? sqrt_j2 / g : along;
  const double quotient = to_sqrt_j2 / sqrt_j2, ratio = sqrt_j2 > 0 ? quotient : 0.0;
  const double r00 = to_mean * 1.0 + ratio * d00, r10 = to_mean * 0.0 + ratio * d10,
               r01 = to_mean * 0.0 + ratio * d01, r11 = to_mean * 1.0 + ratio * d11;
  const double r_zz = to_mean + ratio * d_zz;
  const double work = to_sqrt_j2 * (sqrt_j2 - to_sqrt_j2) / g + to_mean * (mean - to_mean) / bulk;
  return {sum, f, r00, r10, r01, r11, r_zz, work, multiplier};
}

}  // namespace

// Most of the coal, most of the time, does not crack further: settling then
// sets its acting stress, returns a compressive one that lies beyond the
// friction cone to it (the sliding of broken coal) and caps a broken
// particle's bulking. All but the cap is done for a chunk at once over SIMD
// lanes, each particle's arithmetic settle's and drucker_prager_return's
// written out in their order (Eigen's, for the deviator's squared norm), so
// that the lanes move no result where the compiler fuses no products of its
// own (-DOUTBURST_NO_FP_CONTRACTION=ON; with its fused multiply-adds, placed
// apart in vector and scalar code, an ulp). settle itself runs after for the
// particles whose damage grew, the cap for the others, and the dissipation
// is summed in the members' order. The cap is kept out of the lanes: its
// load of the initial volume, made only where the damage is full, would
// need a masked load in them, which GCC 12 refused for the 128-bit vectors
// of its Zen 1 tuning, and the whole loop stayed scalar there
// (docs/performance/mpm.md#compiler-flags).
template <int Dim>
template <bool Drawn, bool Band, class Index>
Dissipation ElasticDamage<Dim>::settle_plane(Particles<Dim>& p, std::span<const int> members, Index index) const {
  static_assert(Dim == 2);
  const int n = static_cast<int>(members.size());
  assert(n <= chunk_size);
  // Every field by a local pointer, as deform_and_trial's.
  double* const effective = p.effective_stress.data()->data();
  double* const effective_zz = p.effective_stress_zz.data();
  const double* const damaged = p.damage.data();
  const double* const strength = Drawn ? p.strength_scale.data() : nullptr;
  const double* const modulus = Drawn ? p.modulus_scale.data() : nullptr;
  double* const acting = p.stress.data()->data();
  double* const acting_zz = p.stress_zz.data();
  double* const volume = p.volume.data();
  const double* const volume0 = p.volume0.data();
  double* const plastic_strain = p.plastic_strain.data();
  const double bulking = parameters_.bulking_factor, shear = this->shear_modulus(), lame = this->lame_lambda();
  const double alpha = alpha_, k0 = k0_;
  // Per member: 0 where damage grew (settle's), 1 where the stress held, 2
  // where it slid, with the plastic work that took. Doubles, chosen by
  // nested selects: GCC 12 vectorises no mask combined by && or stored as
  // bool here.
  double verdict[chunk_size], plastic[chunk_size];
#pragma omp simd
  for (int k = 0; k < n; ++k) {
    const std::ptrdiff_t i = index(k);
    double* const e = effective + 4 * i;
    const double x0 = e[0], x1 = e[1], x2 = e[2], x3 = e[3];
    const double zz = effective_zz[i], previous = damaged[i];
    const double scale = Drawn ? strength[i] : 1.0, stiffness = Drawn ? modulus[i] : 1.0;
    const Principal<2> pr(x0, x3, x2);
    const Stresses st = plane_stresses(pr, zz, stiffness);
    const double d = damage<Band>(previous, st, scale, stiffness);
    double s0, s1, s2, s3;  // Eigen's column-major order
    pr.cracked(1 - d, s0, s1, s2, s3);
    const double s_zz = crack(zz, 1 - d);
    const double g = stiffness * shear, bulk = stiffness * lame + 2.0 / 3.0 * g;
    const double cohesion = (1 - d) * scale * k0;
    const PlaneReturn r = plane_friction_return(s0, s1, s2, s3, s_zz, g, bulk, alpha, cohesion);
    // The undamaged stress the return carries back to (same principal axes).
    const Principal<2> back(r.r00, r.r11, r.r01);
    const double inverse = 1 / (1 - d), open = d < 1 ? inverse : 0.0;
    double e0, e1, e2, e3;
    back.cracked(open, e0, e1, e2, e3);
    const double slides = d == previous ? (r.sum < 0 ? (r.f > 0 ? 1.0 : 0.0) : 0.0) : 0.0;
    verdict[k] = d == previous ? 1.0 + slides : 0.0;
    plastic[k] = slides != 0 ? volume[i] * r.work : 0.0;
    plastic_strain[i] = slides != 0 ? plastic_strain[i] + r.multiplier / std::sqrt(3.0) : plastic_strain[i];
    double* const a = acting + 4 * i;
    a[0] = slides != 0 ? r.r00 : s0;
    a[1] = slides != 0 ? r.r10 : s1;
    a[2] = slides != 0 ? r.r01 : s2;
    a[3] = slides != 0 ? r.r11 : s3;
    acting_zz[i] = slides != 0 ? r.r_zz : s_zz;
    e[0] = slides != 0 ? e0 : x0;
    e[1] = slides != 0 ? e1 : x1;
    e[2] = slides != 0 ? e2 : x2;
    e[3] = slides != 0 ? e3 : x3;
    const double back_zz = crack(r.r_zz, open);
    effective_zz[i] = slides != 0 ? back_zz : zz;
  }
  Dissipation total;
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<int>(index(k));
    if (verdict[k] == 0) {
      total += update_alone(p, i);
    } else {
      if (verdict[k] == 2) total += Dissipation{plastic[k], 0.0};
      if (damaged[i] >= 1) volume[i] = std::min(volume[i], bulking * volume0[i]);
    }
  }
  return total;
}

template <int Dim>
Dissipation ElasticDamage<Dim>::update_stress(Particles<Dim>& p, const std::vector<int>& members, double dt) const {
  if (pointwise()) return Material<Dim>::update_stress(p, members, dt);
  require_velocity_gradients(p, members);
  // Nonlocal: every member's trial stress and driving strain first, then
  // their averages over the internal length, then the damage.
  over_chunks(members, [&](std::span<const int> part) {
    trial(p, part, dt, nullptr);
    return each_member(part, [&](int i) {
      const double zz = Dim == 2 ? p.effective_stress_zz[i] : 0.0;
      p.nonlocal_strain[i] = driving_strain(p.effective_stress[i], zz, strength_scale(p, i), modulus_scale(p, i));
      return Dissipation{};
    });
  });
  std::vector<double> local(members.size()), weight(members.size());
  for (std::size_t k = 0; k < members.size(); ++k) {
    const int i = members[k];
    local[k] = p.nonlocal_strain[i];
    weight[k] = p.damage[i] < 1 ? p.volume[i] : 0.0;
  }
  const std::vector<double> averaged = nonlocal_average(p.x, members, weight, local, *parameters_.internal_length);
  const int n = static_cast<int>(members.size());
  double plastic = 0, damaged = 0;
#pragma omp parallel for schedule(static) reduction(+ : plastic, damaged)
  for (int k = 0; k < n; ++k) {
    const int i = members[k];
    p.nonlocal_strain[i] = averaged[k];
    const double stiffness = modulus_scale(p, i);
    const Stresses st = principal_stresses(p.effective_stress[i], Dim == 2 ? p.effective_stress_zz[i] : 0.0, stiffness);
    const double d = std::clamp(std::max({p.damage[i], nonlocal_tensile_damage(averaged[k]),
                                          shear_damage(st, strength_scale(p, i), stiffness)}),
                                0.0, 1.0);
    const Dissipation r = settle(p, i, d, st);
    plastic += r.plastic;
    damaged += r.damage;
  }
  return {plastic, damaged};
}

template <int Dim>
double ElasticDamage<Dim>::strain_energy(const Particles<Dim>& p, const std::vector<int>& members) const {
  return sum_over(members, [&](int i) {
    const double zz = Dim == 2 ? p.stress_zz[i] : 0.0, effective_zz = Dim == 2 ? p.effective_stress_zz[i] : 0.0;
    return 0.5 * p.volume[i] * this->compliance_product(p.stress[i], zz, p.effective_stress[i], effective_zz) /
           modulus_scale(p, i);
  });
}

template class ElasticDamage<2>;
template class ElasticDamage<3>;

}  // namespace outburst::mpm
