#pragma once
// Material points as a structure of arrays: each field is one contiguous
// vector, so the kernels stream through memory and no particle owns heap data.

#include <cstdint>
#include <vector>

#include "common/checkpoint.hpp"
#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

template <int Dim>
struct Particles {
  std::vector<Vec<Dim>> x;                  // position [m]
  std::vector<Vec<Dim>> x0;                 // initial position [m]
  std::vector<Vec<Dim>> v;                  // velocity [m/s]
  std::vector<double> mass;                 // [kg per m of depth in 2D]
  std::vector<double> volume;               // current [m^3 per m]
  std::vector<double> volume0;              // initial
  std::vector<double> half_width;           // initial half-width in cells (GIMP)
  std::vector<Mat<Dim>> stress;             // Cauchy, tension positive [Pa]
  std::vector<double> stress_zz;            // out-of-plane stress (plane strain)
  std::vector<Mat<Dim>> velocity_gradient;  // L = grad v of the last step [1/s]
  std::vector<Mat<Dim>> deformation;        // F
  std::vector<Mat<Dim>> affine;             // APIC's B matrix
  std::vector<std::int32_t> material;       // index into the scene's materials
  std::vector<std::int32_t> id;             // stable identity (tracers, output)

  // Fields only some scenes need: empty unless created (by need_*, at their
  // initial values) for a material, a load or another program that uses them;
  // a scene that names none of those carries none of them.
  std::vector<Vec<Dim>> external_force;     // set by another program [N per m]
  std::vector<Vec<Dim>> surface_force;      // boundary tractions of the scene [N per m]
  // Isotropic pressure another program adds to the total stress (alpha p of a
  // pore fluid) [Pa].
  std::vector<double> pore_pressure;
  std::vector<double> plastic_strain;       // equivalent plastic strain (accumulated)
  std::vector<double> damage;               // D in [0, 1], irreversible (damage materials)
  std::vector<Mat<Dim>> effective_stress;   // undamaged stress sigma~ (damage materials)
  std::vector<double> effective_stress_zz;

  void need_loads() {
    external_force.resize(size(), Vec<Dim>::Zero());
    surface_force.resize(size(), Vec<Dim>::Zero());
  }
  void need_pore_pressure() { pore_pressure.resize(size(), 0.0); }
  void need_plastic_strain() { plastic_strain.resize(size(), 0.0); }
  // Damage starts at zero, the undamaged stress at the stress.
  void need_damage() {
    if (damage.size() == size()) return;
    damage.assign(size(), 0.0);
    effective_stress = stress;
    effective_stress_zz = stress_zz;
  }

  std::size_t size() const { return x.size(); }

  // Every field, to and from a checkpoint; optional fields as present.
  void save(checkpoint::Out out) const {
    out.matrices("x", x);
    out.matrices("x0", x0);
    out.matrices("v", v);
    out.numbers("mass", mass);
    out.numbers("volume", volume);
    out.numbers("volume0", volume0);
    out.numbers("half_width", half_width);
    out.matrices("stress", stress);
    out.numbers("stress_zz", stress_zz);
    out.matrices("velocity_gradient", velocity_gradient);
    out.matrices("deformation", deformation);
    out.matrices("affine", affine);
    out.counts("material", material);
    out.counts("id", id);
    const auto optional = out.group("optional");
    if (!external_force.empty()) {
      optional.matrices("external_force", external_force);
      optional.matrices("surface_force", surface_force);
    }
    if (!pore_pressure.empty()) optional.numbers("pore_pressure", pore_pressure);
    if (!plastic_strain.empty()) optional.numbers("plastic_strain", plastic_strain);
    if (!damage.empty()) {
      optional.numbers("damage", damage);
      optional.matrices("effective_stress", effective_stress);
      optional.numbers("effective_stress_zz", effective_stress_zz);
    }
  }
  void load(const checkpoint::In& in) {
    x = in.matrices<Dim, 1>("x");
    const std::size_t n = x.size();
    x0 = in.matrices<Dim, 1>("x0", n);
    v = in.matrices<Dim, 1>("v", n);
    mass = in.numbers("mass", n);
    volume = in.numbers("volume", n);
    volume0 = in.numbers("volume0", n);
    half_width = in.numbers("half_width", n);
    stress = in.matrices<Dim, Dim>("stress", n);
    stress_zz = in.numbers("stress_zz", n);
    velocity_gradient = in.matrices<Dim, Dim>("velocity_gradient", n);
    deformation = in.matrices<Dim, Dim>("deformation", n);
    affine = in.matrices<Dim, Dim>("affine", n);
    material = in.counts<std::int32_t>("material", n);
    id = in.counts<std::int32_t>("id", n);
    const auto optional = in.group("optional");
    const bool loads = optional.has("external_force");
    external_force = loads ? optional.matrices<Dim, 1>("external_force", n) : std::vector<Vec<Dim>>{};
    surface_force = loads ? optional.matrices<Dim, 1>("surface_force", n) : std::vector<Vec<Dim>>{};
    pore_pressure = optional.has("pore_pressure") ? optional.numbers("pore_pressure", n) : std::vector<double>{};
    plastic_strain = optional.has("plastic_strain") ? optional.numbers("plastic_strain", n) : std::vector<double>{};
    const bool damaged = optional.has("damage");
    damage = damaged ? optional.numbers("damage", n) : std::vector<double>{};
    effective_stress = damaged ? optional.matrices<Dim, Dim>("effective_stress", n) : std::vector<Mat<Dim>>{};
    effective_stress_zz = damaged ? optional.numbers("effective_stress_zz", n) : std::vector<double>{};
  }

  void add(const Vec<Dim>& position, const Vec<Dim>& velocity, double particle_mass,
           double particle_volume, double half_width_cells, const Mat<Dim>& initial_stress,
           double initial_stress_zz, int material_index) {
    x.push_back(position);
    x0.push_back(position);
    v.push_back(velocity);
    mass.push_back(particle_mass);
    volume.push_back(particle_volume);
    volume0.push_back(particle_volume);
    half_width.push_back(half_width_cells);
    stress.push_back(initial_stress);
    stress_zz.push_back(initial_stress_zz);
    velocity_gradient.push_back(Mat<Dim>::Zero());
    deformation.push_back(Mat<Dim>::Identity());
    affine.push_back(Mat<Dim>::Zero());
    material.push_back(material_index);
    id.push_back(static_cast<std::int32_t>(id.size()));
    // Optional fields present already grow with the particles.
    if (!external_force.empty()) need_loads();
    if (!pore_pressure.empty()) need_pore_pressure();
    if (!plastic_strain.empty()) need_plastic_strain();
    if (!damage.empty()) {
      damage.push_back(0.0);
      effective_stress.push_back(initial_stress);
      effective_stress_zz.push_back(initial_stress_zz);
    }
  }

  // Keep the particles whose flag is set, in order.
  void keep(const std::vector<char>& flag) {
    std::size_t to = 0;
    for (std::size_t from = 0; from < size(); ++from) {
      if (!flag[from]) continue;
      if (to != from) {
        x[to] = x[from];
        x0[to] = x0[from];
        v[to] = v[from];
        mass[to] = mass[from];
        volume[to] = volume[from];
        volume0[to] = volume0[from];
        half_width[to] = half_width[from];
        stress[to] = stress[from];
        stress_zz[to] = stress_zz[from];
        velocity_gradient[to] = velocity_gradient[from];
        deformation[to] = deformation[from];
        affine[to] = affine[from];
        if (!external_force.empty()) {
          external_force[to] = external_force[from];
          surface_force[to] = surface_force[from];
        }
        if (!pore_pressure.empty()) pore_pressure[to] = pore_pressure[from];
        if (!plastic_strain.empty()) plastic_strain[to] = plastic_strain[from];
        if (!damage.empty()) {
          damage[to] = damage[from];
          effective_stress[to] = effective_stress[from];
          effective_stress_zz[to] = effective_stress_zz[from];
        }
        material[to] = material[from];
        id[to] = id[from];
      }
      ++to;
    }
    resize(to);
  }

 private:
  void resize(std::size_t n) {
    x.resize(n);
    x0.resize(n);
    v.resize(n);
    mass.resize(n);
    volume.resize(n);
    volume0.resize(n);
    half_width.resize(n);
    stress.resize(n);
    stress_zz.resize(n);
    velocity_gradient.resize(n);
    deformation.resize(n);
    affine.resize(n);
    if (!external_force.empty()) {
      external_force.resize(n);
      surface_force.resize(n);
    }
    if (!pore_pressure.empty()) pore_pressure.resize(n);
    if (!plastic_strain.empty()) plastic_strain.resize(n);
    if (!damage.empty()) {
      damage.resize(n);
      effective_stress.resize(n);
      effective_stress_zz.resize(n);
    }
    material.resize(n);
    id.resize(n);
  }
};

}  // namespace outburst::mpm
