#include "mpm_solid/materials/drucker_prager.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <tuple>

namespace outburst::mpm {

template <int Dim>
DruckerPrager<Dim>::DruckerPrager(std::string name, Elasticity elasticity, double cohesion, double friction_angle,
                                  double dilation_angle, DruckerPragerFit::Kind fit)
    : Material<Dim>(std::move(name), elasticity) {
  std::tie(alpha_, k_) = DruckerPragerFit::coefficients(fit, cohesion, friction_angle);
  alpha_dilation_ = DruckerPragerFit::coefficients(fit, 0.0, dilation_angle).first;
}

template <int Dim>
double DruckerPrager<Dim>::yield(const Mat<Dim>& s, double s_zz) const {
  const auto inv = invariants<Dim>(s, s_zz);
  return alpha_ * inv.mean + inv.sqrt_j2 - k_;
}

template <int Dim>
double DruckerPrager<Dim>::return_map(Mat<Dim>& s, double& s_zz, double* work_density) const {
  const double g = this->shear_modulus();
  return drucker_prager_return<Dim>(alpha_, k_, alpha_dilation_, g, this->lame_lambda() + 2.0 / 3.0 * g, s, s_zz,
                                    work_density);
}

// A return that reaches the apex from a purely hydrostatic trial has a zero
// multiplier and still does plastic work (the mean stress drops to k /
// alpha): the work is counted wherever the trial lies outside the cone.
template <int Dim>
Dissipation DruckerPrager<Dim>::update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                                             const double* gradients) const {
  deform_and_trial(p, members, dt, this->lame_lambda(), this->shear_modulus(), nullptr, p.stress, p.stress_zz,
                   gradients);
  // Equivalent plastic strain per unit multiplier: sqrt(2/3 |dg/dsigma|^2).
  const double per_multiplier = std::sqrt(2.0 / 3.0 * (0.5 + alpha_dilation_ * alpha_dilation_ / 3));
  const auto return_one = [&](int i) {
    double none = 0;
    double& zz = out_of_plane<Dim>(p.stress_zz, i, none);
    double work = 0;
    p.plastic_strain[i] += per_multiplier * return_map(p.stress[i], zz, &work);
    // Unconditional: the product fuses into the caller's sum where the CPU
    // fuses, as it did before the screen, and a select in between moved
    // the cohesionless collapse's energy balance by an ulp.
    return Dissipation{p.volume[i] * work, 0};
  };
  if constexpr (Dim == 2) {
    // In pieces of chunk_size, the screen's length. A particle the screen
    // passes would add nothing: its stress stays, its strain grows by 0, its
    // work is 0.
    Dissipation total;
    for (std::size_t first = 0; first < members.size(); first += chunk_size) {
      const auto part = members.subspan(first, std::min<std::size_t>(chunk_size, members.size() - first));
      double outside[chunk_size];
      by_position(part, [&](auto index) { screen_plane(p, static_cast<int>(part.size()), index, outside); });
      for (std::size_t j = 0; j < part.size(); ++j)
        if (outside[j] != 0) total += return_one(part[j]);
    }
    return total;
  } else {
    return each_member(members, return_one);
  }
}

// Most particles, most steps, lie inside the cone, and return_map found so
// one at a time through a division and a square root: a seventh of a linear
// Drucker-Prager step under GCC's Zen 1 tuning, which vectorises two doubles
// at a time (docs/performance/index.md#hosts). Lanes
// decide the same for a chunk with neither: f <= 0 is sqrt(J2) <= r = k -
// alpha mean, so J2 <= r^2 for r >= 0. The lanes' mean (a product by 1/3,
// not a division) and sums differ from return_map's by tens of ulps of S (1
// + alpha) + k, S the largest stress entry; a margin of 1e-12 (S + |k|) on
// r, thousands of ulps, leaves every particle it cannot clear to
// return_map, which decides again as before. So does a reach below 2^-450
// or above 2^450, whose square would leave the normal numbers (a subnormal
// square rounds coarser than the margin; an infinite one passes an infinite
// J2), and NaN. So the screen moves no result.
template <int Dim>
template <class Index>
void DruckerPrager<Dim>::screen_plane(const Particles<Dim>& p, int n, Index index, double* outside) const {
  static_assert(Dim == 2);
  assert(n <= chunk_size);
  const double* const stress = p.stress.data()->data();
  const double* const stress_zz = p.stress_zz.data();
  const double alpha = alpha_, k = k_, third = 1.0 / 3;
#pragma omp simd
  for (int m = 0; m < n; ++m) {
    const std::ptrdiff_t i = index(m);
    const double* const s = stress + 4 * i;
    const double s0 = s[0], s1 = s[1], s2 = s[2], s3 = s[3], zz = stress_zz[i];
    const double mean = (s0 + s3 + zz) * third;
    const double d00 = s0 - mean, d11 = s3 - mean, d_zz = zz - mean;
    const double j2 = 0.5 * (d00 * d00 + d11 * d11 + d_zz * d_zz + s1 * s1 + s2 * s2);
    // By value: std::max's references became masked loads, which GCC 12
    // does not vectorise for two-double vectors.
    const auto wider = [](double a, double b) { return a < b ? b : a; };
    const double largest =
        wider(wider(wider(std::abs(s0), std::abs(s1)), wider(std::abs(s2), std::abs(s3))), std::abs(zz));
    const double reach = k - alpha * mean - 1e-12 * (largest + std::abs(k));
    const double normal = reach > 0x1p-450 ? (reach < 0x1p+450 ? 1.0 : 0.0) : 0.0;
    outside[m] = normal != 0 ? (j2 <= reach * reach ? 0.0 : 1.0) : 1.0;
  }
}

template class DruckerPrager<2>;
template class DruckerPrager<3>;

namespace {

using scene::Range;

template <int Dim>
std::unique_ptr<Material<Dim>> read(const scene::Table& m, const MaterialContext& context) {
  const double c = m.quantity({"cohesion", "Mohr-Coulomb cohesion c", "", Range::non_negative()}, units::pressure);
  const double phi = m.quantity({"friction_angle", "Mohr-Coulomb friction angle", "",
                                 Range{0.0, 1.5, true, false}},
                                units::angle);
  const double psi = m.quantity({"dilation_angle", "dilation angle of the plastic potential (0: no volume "
                                                   "change in plastic flow)",
                                 "0 deg", Range::non_negative()},
                                units::angle);
  if (psi > phi) m.fail("dilation_angle", "must not exceed the friction angle");
  const auto kind = m.choice<DruckerPragerFit::Kind>(
      {"fit", "Drucker-Prager cone fitted to Mohr-Coulomb: \"outer\" (compression corners, the paper's), "
              "\"inner\" or \"plane_strain\"",
       "outer"},
      {{"outer", DruckerPragerFit::Kind::outer},
       {"inner", DruckerPragerFit::Kind::inner},
       {"plane_strain", DruckerPragerFit::Kind::plane_strain}});
  if (Dim == 3 && kind == DruckerPragerFit::Kind::plane_strain)
    m.fail("fit", "\"plane_strain\" matches Mohr-Coulomb's collapse load in plane strain; a 3D scene takes "
                  "\"outer\" or \"inner\"");
  return std::make_unique<DruckerPrager<Dim>>(context.name, context.elasticity, c, phi, psi, kind);
}

[[maybe_unused]] const bool registered = register_material({"drucker_prager", "perfectly plastic", read<2>, read<3>});

}  // namespace

}  // namespace outburst::mpm
