#include "mpm_solid/materials/elastic.hpp"

namespace outburst::mpm {

template <int Dim>
Dissipation LinearElastic<Dim>::update_chunk(Particles<Dim>& p, std::span<const int> members, double dt) const {
  const double lambda = this->lame_lambda(), shear = this->shear_modulus();
  return each_member(p, members, dt, [&](int i) {
    double none = 0;
    elastic_trial<Dim>(lambda, shear, p.velocity_gradient[i], dt, p.stress[i], out_of_plane<Dim>(p.stress_zz, i, none));
    return Dissipation{};
  });
}

template class LinearElastic<2>;
template class LinearElastic<3>;

namespace {

template <int Dim>
std::unique_ptr<Material<Dim>> read(const scene::Table&, const MaterialContext& c) {
  return std::make_unique<LinearElastic<Dim>>(c.name, c.elasticity);
}

[[maybe_unused]] const bool registered = register_material({"elastic", "Jaumann rate", read<2>, read<3>});

}  // namespace

}  // namespace outburst::mpm
