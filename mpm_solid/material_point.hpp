#pragma once
// A constitutive law written for one material point, as CB-Geo's interface
// has it (the stress from the strain increment and the point's state), run
// by a generic adapter inside the solver's chunk of lanes. The law knows
// nothing of lanes or chunks: the adapter does, over the chunk's SIMD lanes
// as the lane-wise laws do, the kinematics every law shares (F, the volume)
// and the objective part of the Jaumann rate (the stress turned with the
// material's spin), then takes each member in turn and hands the law what is
// left: the stress increment from the strain increment, and any return to a
// yield surface.
//
// A law is a class with
//   Dissipation update(MaterialPoint<Dim>& point, Particles<Dim>& p) const;
// which updates point.stress (and point.stress_zz in plane strain) and may
// read and write its own fields of particle point.index in p; and optionally
//   void create_fields(Particles<Dim>& p, const std::vector<int>& members) const;
// PointMaterial<Dim, Law> makes it a Material a scene can name
// (register_material, as materials/*.cpp do). materials/elastic_point.hpp is
// the elastic law written so, beside the lane-wise LinearElastic; the
// adapter's cost is the gap between the two in mpm-benchmark
// (docs/performance/index.md).

#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "mpm_solid/material.hpp"

namespace outburst::mpm {

// What a law sees at one material point over one step.
template <int Dim>
struct MaterialPoint {
  // In: the stress at the step's start, turned with the material over the
  // step (sigma + dt (W sigma - sigma W)). Out: the new stress. Plane
  // strain's out-of-plane normal stress beside it (no spin turns it); 0 in
  // 3D. [Pa]
  Mat<Dim> stress;
  double stress_zz;
  Mat<Dim> strain_increment;  // dt D, D the symmetric part of the velocity gradient (plane strain: d_zz = 0)
  double volume;              // at the step's end [m^3; m^2 in 2D, per metre of depth]
  double stiffness;           // the particle's draw of the moduli (heterogeneous material), else 1
  int index;                  // the particle, for the law's own fields
};

template <int Dim, class Law>
class PointMaterial final : public Material<Dim> {
 public:
  PointMaterial(std::string name, Elasticity elasticity, Law law)
      : Material<Dim>(std::move(name), elasticity), law_(std::move(law)) {}

  const Law& law() const { return law_; }

  void create_fields(Particles<Dim>& p, const std::vector<int>& members) const override {
    if constexpr (requires { law_.create_fields(p, members); }) law_.create_fields(p, members);
  }

  // gradients: a chunk's velocity gradients, member k's entry e = r + Dim c
  // at gradients[e * chunk_size + k] (material.hpp, chunk_size); null: each
  // particle's own.
  Dissipation update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                           const double* gradients) const override {
    // The kinematics and the spin's turn over SIMD lanes, as the lane-wise
    // laws take them: deform_and_trial with no moduli adds dt (W s - s W)
    // alone.
    deform_and_trial(p, members, dt, 0.0, 0.0, nullptr, p.stress, p.stress_zz, gradients);
    Dissipation total;
    for (std::size_t k = 0; k < members.size(); ++k) {
      const int i = members[k];
      Mat<Dim> l;
      if (gradients)
        for (int e = 0; e < Dim * Dim; ++e) l.data()[e] = gradients[e * chunk_size + static_cast<int>(k)];
      else
        l = p.velocity_gradient[i];
      total += update_point(p, i, Mat<Dim>(0.5 * dt * (l + l.transpose())));
    }
    return total;
  }

 private:
  Dissipation update_point(Particles<Dim>& p, int i, const Mat<Dim>& strain_increment) const {
    double none = 0;
    double& zz = out_of_plane<Dim>(p.stress_zz, i, none);
    MaterialPoint<Dim> point{p.stress[i], zz, strain_increment, p.volume[i],
                             p.modulus_scale.empty() ? 1.0 : p.modulus_scale[i], i};
    const Dissipation dissipated = law_.update(point, p);
    p.stress[i] = point.stress;
    zz = point.stress_zz;
    return dissipated;
  }

  Law law_;
};

}  // namespace outburst::mpm
