#include "mpm_solid/materials/drucker_prager.hpp"

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

template <int Dim>
Dissipation DruckerPrager<Dim>::update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                                             const double* gradients) const {
  // Equivalent plastic strain per unit multiplier: sqrt(2/3 |dg/dsigma|^2).
  const double strain_per_multiplier = std::sqrt(2.0 / 3.0 * (0.5 + alpha_dilation_ * alpha_dilation_ / 3));
  deform_and_trial(p, members, dt, this->lame_lambda(), this->shear_modulus(), nullptr, p.stress, p.stress_zz,
                   gradients);
  return each_member(members, [&](int i) {
    double none = 0;
    double& zz = out_of_plane<Dim>(p.stress_zz, i, none);
    double work = 0;
    const double multiplier = return_map(p.stress[i], zz, &work);
    if (multiplier == 0) return Dissipation{};
    p.plastic_strain[i] += strain_per_multiplier * multiplier;
    return Dissipation{p.volume[i] * work, 0};
  });
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
