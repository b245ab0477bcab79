#pragma once
#include "mpm_solid/material.hpp"

namespace outburst::mpm {

// Linear elasticity with the Jaumann stress rate, plane strain.
class LinearElastic final : public Material {
 public:
  using Material::Material;
  Dissipation update_chunk(Particles<2>& p, std::span<const int> members, double dt) const override;
};

}  // namespace outburst::mpm
