#include "mpm_solid/materials/elastic.hpp"

namespace outburst::mpm {

Dissipation LinearElastic::update_chunk(Particles<2>& p, std::span<const int> members, double dt) const {
  const double lambda = lame_lambda(), shear = shear_modulus();
  return each_member(p, members, dt, [&](int i) {
    elastic_trial(lambda, shear, p.velocity_gradient[i], dt, p.stress[i], p.stress_zz[i]);
    return Dissipation{};
  });
}

namespace {

std::unique_ptr<Material> read(const scene::Table&, const MaterialContext& c) {
  return std::make_unique<LinearElastic>(c.name, c.elasticity);
}

[[maybe_unused]] const bool registered = register_material({"elastic", "Jaumann rate", read});

}  // namespace

}  // namespace outburst::mpm
