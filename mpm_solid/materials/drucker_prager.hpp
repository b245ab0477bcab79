#pragma once
#include "mpm_solid/material.hpp"

namespace outburst::mpm {

// Drucker-Prager perfect plasticity fitted to Mohr-Coulomb (paper eqs. 36-37):
//   f = alpha I1/3 + sqrt(J2) - k,   tension positive,
// with a plastic potential of the same form using the dilation angle (0 by
// default: plastic flow keeps the volume). Return mapping to the cone, or to
// its apex when the cone return would overshoot it (hydrostatic tension).
template <int Dim>
class DruckerPrager final : public Material<Dim> {
 public:
  DruckerPrager(std::string name, Elasticity elasticity, double cohesion, double friction_angle,
                double dilation_angle, DruckerPragerFit::Kind fit);
  void create_fields(Particles<Dim>& p, const std::vector<int>&) const override { p.need_plastic_strain(); }
  Dissipation update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                           const double* gradients) const override;

  double alpha() const { return alpha_; }
  double k() const { return k_; }
  // The yield function of a stress state (s_zz: plane strain's, ignored in 3D).
  double yield(const Mat<Dim>& stress, double stress_zz = 0) const;
  // Return the trial stress to the yield surface; returns the plastic multiplier
  // and, if asked, the plastic work density of the return [J/m^3].
  double return_map(Mat<Dim>& stress, double& stress_zz, double* work_density = nullptr) const;

 private:
  // In the plane, outside[k] = 0 for a chunk member whose trial surely lies
  // inside the cone, 1 for one that may not.
  template <class Index>
  void screen_plane(const Particles<Dim>& p, int n, Index index, double* outside) const;

  double alpha_, k_, alpha_dilation_;
};

}  // namespace outburst::mpm
