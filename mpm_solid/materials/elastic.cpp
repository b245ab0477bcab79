#include "mpm_solid/materials/elastic.hpp"

namespace outburst::mpm {

template <int Dim>
Dissipation LinearElastic<Dim>::update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                                             const double* gradients) const {
  deform_and_trial(p, members, dt, this->lame_lambda(), this->shear_modulus(), nullptr, p.stress, p.stress_zz,
                   gradients);
  return {};
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
