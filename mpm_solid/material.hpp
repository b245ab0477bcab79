#pragma once
// Constitutive models. A material updates the stress of its own particles from
// their velocity gradient over one step; the solver calls it once per material
// and step, never per particle, so the particle loop has no virtual call.

#include <memory>
#include <optional>
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

// Energy a stress update turns into heat and cracks [J per m of depth].
struct Dissipation {
  double plastic = 0;  // plastic work
  double damage = 0;   // strain energy released as damage grows, Y dD
  Dissipation& operator+=(const Dissipation& o) {
    plastic += o.plastic;
    damage += o.damage;
    return *this;
  }
};

class Material {
 public:
  virtual ~Material() = default;
  explicit Material(std::string name, Elasticity elasticity)
      : name_(std::move(name)), elasticity_(elasticity) {}

  const std::string& name() const { return name_; }
  const Elasticity& elasticity() const { return elasticity_; }

  // Creates the optional particle fields the model keeps (plastic strain,
  // damage); the solver calls it before the first step.
  virtual void create_fields(Particles<2>&) const {}

  // Update the stresses of particles `members` over a step dt from their
  // velocity gradients (objective: Jaumann rate, paper eqs. 31-33), and carry
  // their deformation gradients and volumes over the step. Returns the energy
  // dissipated in the step.
  virtual Dissipation update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const = 0;

  // Strain energy stored in particles `members` [J per m of depth].
  virtual double strain_energy(const Particles<2>& p, const std::vector<int>& members) const;

  // a : C0^-1 : b for two plane-strain stress states (C0 the undamaged
  // stiffness); half of it with a = b is the elastic strain energy density.
  double compliance_product(const Mat<2>& a, double a_zz, const Mat<2>& b, double b_zz) const;

 private:
  std::string name_;
  Elasticity elasticity_;
};

// Linear elasticity with the Jaumann stress rate, plane strain.
class LinearElastic final : public Material {
 public:
  using Material::Material;
  Dissipation update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const override;
};

// The elastic trial step shared by the elastic-plastic models: Jaumann-rate
// linear elasticity over dt, in place.
void elastic_trial(const Elasticity& e, const Mat<2>& velocity_gradient, double dt, Mat<2>& stress,
                   double& stress_zz);

// Drucker-Prager perfect plasticity fitted to Mohr-Coulomb (paper eqs. 36-37):
//   f = alpha I1/3 + sqrt(J2) - k,   tension positive,
// with a plastic potential of the same form using the dilation angle (0 by
// default: plastic flow keeps the volume). Return mapping to the cone, or to
// its apex when the cone return would overshoot it (hydrostatic tension).
struct DruckerPragerFit {
  enum class Kind { outer, inner, plane_strain };
  // alpha and k of f = alpha I1/3 + sqrt(J2) - k.
  static std::pair<double, double> coefficients(Kind kind, double cohesion, double friction_angle);
};

// Return a trial stress to the cone f = alpha I1/3 + sqrt(J2) - k (or its apex)
// with the potential's alpha_dilation; G and K the elastic moduli. Returns the
// plastic multiplier and, if asked, the plastic work density [J/m^3].
double drucker_prager_return(double alpha, double k, double alpha_dilation, double shear_modulus,
                             double bulk_modulus, Mat<2>& stress, double& stress_zz, double* work_density);

class DruckerPrager final : public Material {
 public:
  DruckerPrager(std::string name, Elasticity elasticity, double cohesion, double friction_angle,
                double dilation_angle, DruckerPragerFit::Kind fit);
  void create_fields(Particles<2>& p) const override {
    p.need_plastic_strain();
  }
  Dissipation update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const override;

  double alpha() const { return alpha_; }
  double k() const { return k_; }
  // The yield function of a plane-strain stress state.
  double yield(const Mat<2>& stress, double stress_zz) const;
  // Return the trial stress to the yield surface; returns the plastic multiplier
  // and, if asked, the plastic work density of the return [J/m^3].
  double return_map(Mat<2>& stress, double& stress_zz, double* work_density = nullptr) const;

 private:
  double alpha_, k_, alpha_dilation_;
};

// The elastic-damage law of RFPA-type models (model-notes section 3, paper
// eqs. 10-14), made to leave fragmented coal behind rather than nothing:
//  - the undamaged (effective) stress sigma~ follows Jaumann-rate elasticity
//    with E0; damage is read from its principal stresses and strains;
//  - tensile damage once the largest principal stress reaches f_t:
//    D = 1 - f_tr / (E0 eps_1) up to eps_1 = eta f_t / E0, then D = 1;
//  - shear damage once Mohr-Coulomb (c, phi) is reached:
//    D = 1 - f_cr / (E0 |eps_3|), f_cr the residual share of the UCS;
//  - D never decreases. The stress acting is sigma~ with its tensile principal
//    parts scaled by (1 - D) (open cracks carry no tension) and its compressive
//    parts kept (closed cracks carry compression); compressive states are
//    bounded by Drucker-Prager friction with cohesion (1 - D) c: fully damaged
//    coal is cohesionless, tension-free granular material that still piles up
//    and rubs.
// The energy stored is half the acting stress times the strain,
// sigma : C0^-1 : sigma~ / 2; what damage growth at fixed strain takes from it
// is booked as dissipated by damage.
struct DamageParameters {
  double cohesion;          // c [Pa]
  double friction_angle;    // phi [rad]
  double tensile_strength;  // f_t [Pa]
  double residual_ratio;    // f_tr / f_t = f_cr / f_c
  double ultimate_ratio;    // eta = eps_tu / eps_t0, unless a fracture energy is given
  // Crack band: with a fracture energy G_f [J/m2] the ultimate tensile strain
  // is set so that a band band_width [m] wide dissipates G_f per unit crack
  // area, whatever the resolution: band_width times the area under the
  // softening law, f_t eps_t0 / 2 + f_tr (eps_tu - eps_t0), equals G_f. A band
  // too wide for that (the peak alone would dissipate more) is refused when
  // the scene is read (largest_band_width).
  std::optional<double> fracture_energy;
  double band_width = 0;
  // Largest volume of fully damaged material over its initial volume. Broken
  // coal bulks to a loose heap; beyond that its fragments part and the gaps are
  // no part of any particle. Without the cap a fragment's volume grows with
  // the separation, its density (and the force it exerts per unit mass on
  // recontact) with it, and the stable step shrinks without bound.
  double bulking_factor = 1.5;
};

// The widest crack band a fracture energy allows with elasticity e: the one
// whose peak alone, f_t^2 / (2 E0) per unit volume, dissipates G_f [m].
double largest_band_width(const DamageParameters& d, const Elasticity& e);

class ElasticDamage final : public Material {
 public:
  ElasticDamage(std::string name, Elasticity elasticity, DamageParameters damage);
  void create_fields(Particles<2>& p) const override {
    p.need_plastic_strain();
    p.need_damage();
  }
  Dissipation update_stress(Particles<2>& p, const std::vector<int>& members, double dt) const override;
  // Damage of one particle, given its history value and effective stress.
  double damage(double previous, const Mat<2>& effective, double effective_zz) const;
  const DamageParameters& parameters() const { return parameters_; }
  double strain_energy(const Particles<2>& p, const std::vector<int>& members) const override;

 private:
  DamageParameters parameters_;
  double ultimate_strain_;  // eps_tu: from eta, or from G_f and the band width
  double alpha_, k0_;       // Drucker-Prager friction cone (outer fit), intact cohesion
  double sin_phi_, cos_phi_, ucs_;  // of the Mohr-Coulomb shear criterion
};

}  // namespace outburst::mpm
