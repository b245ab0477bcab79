#pragma once
// Constitutive models. A material updates the stress of its own particles from
// their velocity gradient over one step; the solver calls it once per material
// and step, never per particle, so the particle loop has no virtual call.

#include <memory>
#include <string>
#include <vector>

#include "mpm_solid/particles.hpp"

namespace outburst::mpm {

struct Elasticity {
  double density;          // [kg/m^3]
  double youngs_modulus;   // [Pa]
  double poisson_ratio;

  double shear_modulus() const { return youngs_modulus / (2 * (1 + poisson_ratio)); }
  double lame_lambda() const {
    return youngs_modulus * poisson_ratio / ((1 + poisson_ratio) * (1 - 2 * poisson_ratio));
  }
  // Speed of the fastest (P) wave, which bounds the explicit time step.
  double p_wave_speed() const;
};

class Material {
 public:
  virtual ~Material() = default;
  explicit Material(std::string name, Elasticity elasticity)
      : name_(std::move(name)), elasticity_(elasticity) {}

  const std::string& name() const { return name_; }
  const Elasticity& elasticity() const { return elasticity_; }

  // Update the stresses of particles `members` over a step dt from their
  // velocity gradients (objective: Jaumann rate, paper eqs. 31-33).
  virtual void update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const = 0;

 private:
  std::string name_;
  Elasticity elasticity_;
};

// Linear elasticity with the Jaumann stress rate, plane strain.
class LinearElastic final : public Material {
 public:
  using Material::Material;
  void update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const override;
};

}  // namespace outburst::mpm
