#pragma once
#include "mpm_solid/material.hpp"

namespace outburst::mpm {

// Linear elasticity with the Jaumann stress rate (plane strain in 2D).
template <int Dim>
class LinearElastic final : public Material<Dim> {
 public:
  using Material<Dim>::Material;
  Dissipation update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                           const double* gradients) const override;
};

}  // namespace outburst::mpm
