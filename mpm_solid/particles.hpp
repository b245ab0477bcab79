#pragma once
// Material points as a structure of arrays: each field is one contiguous
// vector, so the kernels stream through memory and no particle owns heap data.

#include <algorithm>
#include <cstdint>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "common/checkpoint.hpp"
#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

template <int Dim>
struct Particles {
  std::vector<Vec<Dim>> x;                  // position [m]
  std::vector<Vec<Dim>> x0;                 // initial position [m]
  std::vector<Vec<Dim>> v;                  // velocity [m/s]
  std::vector<double> mass;                 // [kg; per m of depth in 2D]
  std::vector<double> volume;               // current [m^3; m^2 in 2D]
  std::vector<double> volume0;              // initial
  std::vector<double> half_width;           // initial half-width in cells (GIMP)
  std::vector<Mat<Dim>> stress;             // Cauchy, tension positive [Pa]
  std::vector<double> stress_zz;            // out-of-plane stress (plane strain; 3D: absent)
  std::vector<Mat<Dim>> deformation;        // F
  std::vector<std::int32_t> material;       // index into the scene's materials
  std::vector<std::int32_t> id;             // stable identity (tracers, output)

  // Fields only some scenes need: empty unless created (by need_*, at their
  // initial values) for a material, a load, a transfer or another program
  // that uses them; a scene that names none of those carries none of them.

  // L = grad v [1/s] of the last step, for the steps that store it: the split
  // passes (MUSL, USL, smoothed dilatation, nonlocal damage). USF's fused pass
  // keeps each chunk's in SIMD lanes instead (chunk_size, material.hpp).
  std::vector<Mat<Dim>> velocity_gradient;
  std::vector<Mat<Dim>> affine;             // APIC's B matrix
  std::vector<Vec<Dim>> external_force;     // set by another program [N; N per m in 2D]
  std::vector<Vec<Dim>> surface_force;      // boundary tractions of the scene [N; N per m in 2D]
  // Isotropic pressure another program adds to the total stress (alpha p of a
  // pore fluid) [Pa].
  std::vector<double> pore_pressure;
  std::vector<double> plastic_strain;       // equivalent plastic strain (accumulated)
  std::vector<double> damage;               // D in [0, 1], irreversible (damage materials)
  std::vector<Mat<Dim>> effective_stress;   // undamaged stress sigma~ (damage materials)
  std::vector<double> effective_stress_zz;
  // Factors on a heterogeneous material's strengths and on its elastic
  // moduli, drawn per particle (1 elsewhere).
  std::vector<double> strength_scale;
  std::vector<double> modulus_scale;
  // The damage-driving strain over the strain at f_t, averaged over a
  // material's internal length (nonlocal damage).
  std::vector<double> nonlocal_strain;

  // The field table: every field above once, with its checkpoint name and,
  // for an optional one, the effect that creates it and the field it starts
  // as when created or grown (zero if none); a scalar field written with the
  // snapshots names its unit and when it is written. add, keep, resize, the
  // checkpoint and the snapshots' scalar fields run over it; a field missing
  // here fails to compile (below).
  enum class Written {
    never,
    when_present,  // only in runs whose scene names its effect
    always,        // its fill value where the scene lacks the effect, so readers find it in every run
  };
  template <class T>
  struct Field {
    const char* name;
    std::vector<T> Particles::*values;
    const char* effect = nullptr;              // null: every scene carries it
    std::vector<T> Particles::*starts_as = nullptr;
    double fill = 0;                           // a created scalar field's value, without starts_as
    Written written = Written::never;
    const char* unit = "";                     // of a written field
    // Plane strain's out-of-plane stress: a 3D stress matrix holds it, and
    // 3D particles have no such field.
    bool plane_only = false;
    bool optional() const { return effect != nullptr; }
    bool present() const { return Dim == 2 || !plane_only; }
  };
  static constexpr auto fields() {
    using P = Particles;
    return std::make_tuple(
        Field<Vec<Dim>>{"x", &P::x}, Field<Vec<Dim>>{"x0", &P::x0}, Field<Vec<Dim>>{"v", &P::v},
        Field<double>{"mass", &P::mass}, Field<double>{"volume", &P::volume},
        Field<double>{"volume0", &P::volume0}, Field<double>{"half_width", &P::half_width},
        Field<Mat<Dim>>{"stress", &P::stress},
        Field<double>{.name = "stress_zz", .values = &P::stress_zz, .plane_only = true},
        Field<Mat<Dim>>{"deformation", &P::deformation},
        Field<std::int32_t>{.name = "material", .values = &P::material, .written = Written::always},
        Field<std::int32_t>{.name = "id", .values = &P::id, .written = Written::always},
        Field<Mat<Dim>>{"velocity_gradient", &P::velocity_gradient, "stored velocity gradients"},
        Field<Mat<Dim>>{"affine", &P::affine, "apic"},
        Field<Vec<Dim>>{"external_force", &P::external_force, "loads"},
        Field<Vec<Dim>>{"surface_force", &P::surface_force, "loads"},
        Field<double>{"pore_pressure", &P::pore_pressure, "pore pressure"},
        Field<double>{.name = "plastic_strain", .values = &P::plastic_strain, .effect = "plasticity",
                      .written = Written::always},
        Field<double>{.name = "damage", .values = &P::damage, .effect = "damage", .written = Written::always},
        Field<Mat<Dim>>{"effective_stress", &P::effective_stress, "damage", &P::stress},
        Field<double>{.name = "effective_stress_zz", .values = &P::effective_stress_zz, .effect = "damage",
                      .starts_as = &P::stress_zz, .plane_only = true},
        Field<double>{.name = "strength_scale", .values = &P::strength_scale, .effect = "heterogeneity",
                      .fill = 1.0, .written = Written::when_present},
        Field<double>{.name = "modulus_scale", .values = &P::modulus_scale, .effect = "heterogeneity",
                      .fill = 1.0, .written = Written::when_present},
        Field<double>{.name = "nonlocal_strain", .values = &P::nonlocal_strain, .effect = "nonlocal damage",
                      .written = Written::when_present});
  }
  // f(field, values) over the fields of this dimension.
  template <class F>
  void for_each_field(F&& f) {
    std::apply([&](const auto&... field) { ((field.present() ? (void)f(field, this->*field.values) : void()), ...); },
               fields());
  }
  template <class F>
  void for_each_field(F&& f) const {
    std::apply([&](const auto&... field) { ((field.present() ? (void)f(field, this->*field.values) : void()), ...); },
               fields());
  }

  // Creates the optional fields of an effect, at their initial values, if
  // they are not there yet. Among no particles a created field is as empty
  // as an absent one, and add() does not grow it: create fields once the
  // particles are there.
  void need(const char* effect) {
    for_each_field([&](const auto& field, auto& values) {
      if (!field.optional() || std::string_view(field.effect) != effect || values.size() == size()) return;
      if (field.starts_as)
        values = this->*field.starts_as;
      else
        values.assign(size(), initial(field));
    });
  }
  void need_loads() { need("loads"); }
  void need_pore_pressure() { need("pore pressure"); }
  void need_plastic_strain() { need("plasticity"); }
  void need_damage() { need("damage"); }
  void need_velocity_gradients() { need("stored velocity gradients"); }
  void need_affine() { need("apic"); }

  std::size_t size() const { return x.size(); }

  // Every field, to and from a checkpoint; optional fields as present.
  void save(checkpoint::Out out) const {
    const auto optional = out.group("optional");
    for_each_field([&](const auto& field, const auto& values) {
      if (!field.optional())
        write(out, field.name, values);
      else if (!values.empty())
        write(optional, field.name, values);
    });
  }
  void load(const checkpoint::In& in) {
    const auto optional = in.group("optional");
    x = in.matrices<Dim, 1>("x");
    const std::size_t n = x.size();
    for_each_field([&](const auto& field, auto& values) {
      if (static_cast<const void*>(&values) == static_cast<const void*>(&x)) return;
      if (!field.optional())
        read(in, field.name, n, values);
      else if (optional.has(field.name))
        read(optional, field.name, n, values);
      else
        values.clear();
    });
    check_restored(in);
    // An effect's fields come and go together (the kernels test one of them).
    for_each_field([&](const auto& field, const auto& values) {
      if (!field.optional()) return;
      for_each_field([&](const auto& other, const auto& others) {
        if (other.optional() && std::string_view(other.effect) == field.effect && others.empty() != values.empty())
          optional.fail(field.name, fmt::format("\"{}\" without \"{}\" of the same effect ({})",
                                                values.empty() ? other.name : field.name,
                                                values.empty() ? field.name : other.name, field.effect));
      });
    });
  }

  // initial_stress_zz: plane strain's out-of-plane stress (ignored in 3D).
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
    if constexpr (Dim == 2) stress_zz.push_back(initial_stress_zz);
    deformation.push_back(Mat<Dim>::Identity());
    material.push_back(material_index);
    id.push_back(static_cast<std::int32_t>(id.size()));
    // Optional fields present already grow with the particles.
    for_each_field([&](const auto& field, auto& values) {
      if (!field.optional() || values.empty()) return;
      if (field.starts_as)
        values.push_back((this->*field.starts_as).back());
      else
        values.push_back(initial(field));
    });
  }

  // Keep the particles whose flag is set, in order.
  void keep(const std::vector<char>& flag) {
    const std::size_t n = size();
    for_each_field([&](const auto&, auto& values) {
      if (values.empty()) return;
      std::size_t to = 0;
      for (std::size_t from = 0; from < n; ++from)
        if (flag[from]) values[to++] = values[from];
      values.resize(to);
    });
  }

 private:
  // Refuses restored values no run holds (the numbers are finite already,
  // checkpoint::In): an id that is negative or given twice would stand for
  // two particles in every later snapshot; a mass, volume or width of zero or
  // less divides the step's transfers by it.
  void check_restored(const checkpoint::In& in) const {
    const auto refuse = [&](const char* name, std::size_t i, const std::string& what) {
      in.fail(name, fmt::format("particle {} (row {}) {}, which no run holds: the checkpoint is damaged", id[i], i, what));
    };
    for (std::size_t i = 0; i < size(); ++i) {
      if (id[i] < 0) refuse("id", i, "has a negative id");
      if (!(mass[i] > 0)) refuse("mass", i, fmt::format("has the mass {}", mass[i]));
      if (!(volume[i] > 0)) refuse("volume", i, fmt::format("has the volume {}", volume[i]));
      if (!(volume0[i] > 0)) refuse("volume0", i, fmt::format("has the initial volume {}", volume0[i]));
      if (!(half_width[i] > 0)) refuse("half_width", i, fmt::format("has the half-width {}", half_width[i]));
    }
    std::vector<std::size_t> by_id(size());
    for (std::size_t i = 0; i < by_id.size(); ++i) by_id[i] = i;
    std::sort(by_id.begin(), by_id.end(), [&](std::size_t a, std::size_t b) { return id[a] < id[b]; });
    for (std::size_t k = 1; k < by_id.size(); ++k)
      if (id[by_id[k]] == id[by_id[k - 1]])
        refuse("id", std::max(by_id[k], by_id[k - 1]), fmt::format("has the id of row {} too", std::min(by_id[k], by_id[k - 1])));
    for (std::size_t i = 0; i < damage.size(); ++i)
      if (!(damage[i] >= 0 && damage[i] <= 1)) refuse("optional/damage", i, fmt::format("has the damage {}", damage[i]));
  }

  template <class T>
  static T initial(const Field<T>& field) {
    if constexpr (std::is_arithmetic_v<T>)
      return static_cast<T>(field.fill);
    else
      return T::Zero();
  }
  template <class T>
  static void write(checkpoint::Out out, const char* name, const std::vector<T>& values) {
    if constexpr (std::is_same_v<T, double>)
      out.numbers(name, values);
    else if constexpr (std::is_integral_v<T>)
      out.counts(name, values);
    else
      out.matrices(name, values);
  }
  template <class T>
  static void read(const checkpoint::In& in, const char* name, std::size_t n, std::vector<T>& values) {
    if constexpr (std::is_same_v<T, double>)
      values = in.numbers(name, n);
    else if constexpr (std::is_integral_v<T>)
      values = in.counts<T>(name, n);
    else
      values = in.matrices<T::RowsAtCompileTime, T::ColsAtCompileTime>(name, n);
  }
};

// Every member is a field of the table: a vector added to Particles but not to
// fields() would be left out of keep (misaligning it after removals) and of
// checkpoints.
static_assert(sizeof(Particles<2>) ==
              std::tuple_size_v<decltype(Particles<2>::fields())> * sizeof(std::vector<double>));
static_assert(sizeof(Particles<3>) ==
              std::tuple_size_v<decltype(Particles<3>::fields())> * sizeof(std::vector<double>));

}  // namespace outburst::mpm
