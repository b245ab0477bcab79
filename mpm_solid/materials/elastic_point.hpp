#pragma once
// Linear elasticity with the Jaumann stress rate written for one material
// point (material_point.hpp): the same law as LinearElastic (elastic.hpp),
// which runs it over SIMD lanes, and the example to start a new law from.
// The two agree to round-off (tests/test_mpm_materials.cpp); what the
// per-point form costs is measured by mpm-benchmark --material elastic_point.
// Not registered: a scene names "elastic".
#include "mpm_solid/material_point.hpp"

namespace outburst::mpm {

template <int Dim>
struct ElasticPointLaw {
  double lambda, shear;  // Lame constants [Pa]

  // sigma += lambda tr(de) I + 2 G de (plane strain: de_zz = 0, and the
  // out-of-plane stress takes lambda tr(de)).
  Dissipation update(MaterialPoint<Dim>& point, Particles<Dim>&) const {
    const double volumetric = lambda * point.strain_increment.trace();
    point.stress += volumetric * Mat<Dim>::Identity() + 2 * shear * point.strain_increment;
    if constexpr (Dim == 2) point.stress_zz += volumetric;
    return {};
  }
};

template <int Dim>
std::unique_ptr<Material<Dim>> elastic_point(std::string name, const Elasticity& elasticity) {
  return std::make_unique<PointMaterial<Dim, ElasticPointLaw<Dim>>>(
      std::move(name), elasticity, ElasticPointLaw<Dim>{elasticity.lame_lambda(), elasticity.shear_modulus()});
}

}  // namespace outburst::mpm
