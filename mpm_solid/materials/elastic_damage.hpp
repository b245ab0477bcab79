#pragma once
#include <cstdint>

#include "mpm_solid/material.hpp"

namespace outburst::mpm {

// The elastic-damage law of RFPA-type models (model-notes section 3, paper
// eqs. 10-14), made to leave fragmented coal behind rather than nothing:
//  - the undamaged (effective) stress sigma~ follows Jaumann-rate elasticity
//    with E0; damage is read from its principal stresses and strains;
//  - tensile damage once the largest principal stress reaches f_t:
//    D = 1 - f_tr / (E0 eps_1) up to eps_1 = eta f_t / E0, then D = 1 (or
//    the crack band below);
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
  // Crack band (Bazant & Oh 1983): with a fracture energy G_f [J/m2] the
  // tensile stress carried falls linearly in eps_1 from f_t at the onset (the
  // strain at which the stress state reached f_t) to nothing at
  // eps_tu = 2 G_f / (f_t band_width): a band band_width [m] wide dissipates
  // f_t eps_tu / 2 per unit volume, G_f per unit crack area, whatever the
  // resolution and whatever holds the band's sides. A band too wide for that
  // under uniaxial stress (its peak alone, f_t^2 / (2 E0) per unit volume,
  // would dissipate more: a snap-back) is refused when the scene is read
  // (largest_band_width); a state that stores more at its peak (lateral
  // compression) breaks at once.
  std::optional<double> fracture_energy;
  double band_width = 0;
  // Nonlocal damage (Pijaudier-Cabot & Bazant 1987), the other regularised
  // law: tensile damage is driven by the largest principal strain over the
  // particle's strain at f_t, eps_1 E0 / f_t, averaged over the particles
  // within the internal length R [m] (mpm_solid/nonlocal.hpp), and softens
  // linearly in that average from f_t at 1 to nothing at eta:
  // D = 1 - (eta - e) / ((eta - 1) e). The crack then spreads over a zone a
  // few R wide whatever the cell, so the energy it takes converges as the
  // cells shrink (the zone widens as it softens). A point's own value is
  // capped at eta, and a fully damaged point drops out of its neighbours'
  // averages: a crack ends the interaction across it, where the opening of
  // broken points would drive their neighbours' damage on. (Weighting by
  // 1 - D instead delocalises: a softening point then pulls its neighbours'
  // averages down, and the damage spreads over the whole bar.) Shear damage
  // stays local.
  std::optional<double> internal_length = std::nullopt;
  // Largest volume of fully damaged material over its initial volume. Broken
  // coal bulks to a loose heap; beyond that its fragments part and the gaps are
  // no part of any particle. Without the cap a fragment's volume grows with
  // the separation, its density (and the force it exerts per unit mass on
  // recontact) with it, and the stable step shrinks without bound.
  double bulking_factor = 1.5;
  // Heterogeneous coal (RFPA's approach: Tang 1997; Xu, Tang et al. 2006): each
  // particle's strengths f_t and c scaled by a factor s_f, and its elastic
  // moduli by a factor s_E, drawn independently from Weibull distributions of
  // mean 1 and shapes m and m_E (the homogeneity indices; m_E = m unless
  // given). The draws are hashes of the seed and the particle's id: the same
  // seed gives the same coal whatever the threads or the particle order.
  // The ultimate strain scales as the strain at f_t does, by s_f / s_E; under
  // a crack band G_f then scales by s_f^2 / s_E, so every particle keeps the
  // characteristic length E G_f / f_t^2 and the band's snap-back limit holds
  // for all alike.
  // Each particle draws its own factors unless a grain size is given: the
  // random field's correlation length is then the particle spacing, so a
  // finer grid makes another, finer-grained coal. With a grain size g [m]
  // the particles whose initial positions lie in one g x g square (a cube in 3D) of a grid
  // through the origin share its draw (the square's indices replace the
  // particle's id in the hash), and every resolution finer than g sees the
  // same coal.
  struct Heterogeneity {
    double homogeneity_index;
    std::uint64_t seed;
    std::optional<double> modulus_homogeneity_index = std::nullopt;
    std::optional<double> grain_size = std::nullopt;
    double modulus_index() const { return modulus_homogeneity_index.value_or(homogeneity_index); }
    // What the draws of a particle of this id, at x0 at t = 0, are hashed from.
    template <int Dim>
    std::int64_t key(std::int64_t id, const Vec<Dim>& x0) const;
  };
  std::optional<Heterogeneity> heterogeneity = std::nullopt;
};

// The factors of particle `id` on the strengths and on the moduli: Weibull,
// mean 1, drawn independently of each other.
double weibull_strength_scale(const DamageParameters::Heterogeneity& h, std::int64_t id);
double weibull_modulus_scale(const DamageParameters::Heterogeneity& h, std::int64_t id);

// The widest crack band a fracture energy allows with elasticity e: the one
// whose peak alone, f_t^2 / (2 E0) per unit volume, dissipates G_f [m]
// (then eps_tu = eps_t0).
double largest_band_width(const DamageParameters& d, const Elasticity& e);

// The plane forms read the principal stresses of the in-plane matrix and the
// out-of-plane stress; the 3D ones those of the whole matrix.
template <int Dim>
class ElasticDamage final : public Material<Dim> {
 public:
  ElasticDamage(std::string name, Elasticity elasticity, DamageParameters damage);
  void create_fields(Particles<Dim>& p, const std::vector<int>& members) const override;
  Dissipation update_stress(Particles<Dim>& p, const std::vector<int>& members, double dt) const override;
  Dissipation update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                           const double* gradients) const override;
  // Nonlocal damage reads the neighbours' strains.
  bool pointwise() const override { return !parameters_.internal_length; }
  // Damage of one particle, given its history value, effective stress
  // (effective_zz: plane strain's, ignored in 3D) and factors on the
  // strengths and the moduli.
  double damage(double previous, const Mat<Dim>& effective, double effective_zz, double scale = 1.0,
                double stiffness = 1.0) const;
  const DamageParameters& parameters() const { return parameters_; }
  double strain_energy(const Particles<Dim>& p, const std::vector<int>& members) const override;

 private:
  DamageParameters parameters_;
  double ultimate_strain_;  // eps_tu: from eta, or from G_f and the band width
  double alpha_, k0_;       // Drucker-Prager friction cone (outer fit), intact cohesion
  double sin_phi_, cos_phi_, ucs_;  // of the Mohr-Coulomb shear criterion

  double strength_scale(const Particles<Dim>& p, int i) const;  // s_f, 1 unless heterogeneous
  double modulus_scale(const Particles<Dim>& p, int i) const;   // s_E
  // The step's kinematics and the elastic trial of the members' undamaged
  // stresses over dt.
  void trial(Particles<Dim>& p, std::span<const int> members, double dt, const double* gradients) const;
  // Ordered principal stresses, with the strains they hold, and in the
  // plane the decomposition of the effective stress they came from.
  struct Stresses;
  Stresses principal_stresses(const Mat<Dim>& effective, double effective_zz, double stiffness) const;
  // The same from the in-plane matrix's decomposition (a Principal<2>).
  template <class Plane>
  Stresses plane_stresses(const Plane& in_plane, double effective_zz, double stiffness) const;
  // Sets particle i's damage to d (no less than it had) and its acting
  // stress, and returns what that dissipated; in the plane it reads the
  // decomposition in st, its effective stress's.
  Dissipation settle(Particles<Dim>& p, int i, double d, const Stresses& st) const;
  // Particle i's pointwise update after the trial, one particle at a time:
  // its decomposition, the damage law and settle.
  Dissipation update_alone(Particles<Dim>& p, int i) const;
  // The plane's pointwise update of a chunk of members after the trial,
  // member k particle index(k): over SIMD lanes where damage does not grow
  // (the acting stress, friction's return, the bulking cap), by settle
  // elsewhere.
  template <bool Drawn, bool Band, class Index>
  Dissipation settle_plane(Particles<Dim>& p, std::span<const int> members, Index index) const;
  double damage(double previous, const Stresses& st, double scale, double stiffness) const;
  template <bool Band>
  double damage(double previous, const Stresses& st, double scale, double stiffness) const;
  double shear_damage(const Stresses& s, double scale, double stiffness) const;
  // The local driver of nonlocal damage: eps_1 over the strain at f_t, in
  // [0, eta].
  double driving_strain(const Mat<Dim>& effective, double effective_zz, double scale, double stiffness) const;
  // Tensile damage of nonlocal damage from the averaged driving strain.
  double nonlocal_tensile_damage(double averaged) const;
};

}  // namespace outburst::mpm
