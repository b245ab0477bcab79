#pragma once
// What the census of a step reads and checks, over SIMD lanes: the
// particles' signal and runaway speeds, finite stresses, and the census
// itself (Solver::count), which the move runs on the particles it moved
// (motion.cpp) and whose verdict census.cpp acts on. Not for use outside the
// solver.

#include <cassert>
#include <cmath>
#include <cstddef>
#include <memory>
#include <type_traits>
#include <vector>

#include "mpm_solid/solver.hpp"
#include "mpm_solid/stencil.hpp"

namespace outburst::mpm::passes {

// Each material's P-wave modulus lambda + 2 G, by which the signal speed
// and the stable step go.
template <int Dim>
std::vector<double> p_moduli(const std::vector<std::unique_ptr<Material<Dim>>>& materials) {
  std::vector<double> m;
  for (const auto& material : materials) m.push_back(material->lame_lambda() + 2 * material->shear_modulus());
  return m;
}

// v . v of a Dim-vector, summed left to right as Eigen's squaredNorm() does,
// entry(e) its e-th entry: one order for every loop over lanes that sums
// squares (the signal and runaway speeds, the energy books).
template <int Dim, class Entry>
[[gnu::always_inline]] inline double sum_of_squares(Entry entry) {
  double sum = entry(0) * entry(0);
#pragma GCC unroll 2
  for (int e = 1; e < Dim; ++e) sum += entry(e) * entry(e);
  return sum;
}

// What a particle's signal and runaway speeds read, by local pointers: read
// through the particles' vectors inside a loop over lanes, the vectors' ends
// were loaded again after every store, and GCC ran the loop's scalar copy
// (the census, a third of the motion gather). Drawn: whether scale holds a
// heterogeneous material's draws of the moduli (with_draws below).
struct Speeds {
  const double *p_modulus, *wave_squared, *mass, *volume, *scale;
  const int* material;

  // wave_squared: per material, or null where no runaway is checked.
  template <int Dim>
  Speeds(const std::vector<double>& p_modulus, const double* wave_squared, const Particles<Dim>& p)
      : p_modulus(p_modulus.data()),
        wave_squared(wave_squared),
        mass(p.mass.data()),
        volume(p.volume.data()),
        scale(p.modulus_scale.data()),
        material(p.material.data()) {}

  // The fastest signal at particle i: its P wave, which speeds up as the
  // material compresses (density rises) and with the draw of the moduli,
  // plus its own speed, whose square is given. Two divisions and two square
  // roots, which one particle at a time held the motion gather on the
  // divider for a fifth of its time (perf, linear elastic). One function for
  // the stable step's pass and the move's census, so the two agree.
  template <bool Drawn>
  [[gnu::always_inline]] double signal(std::ptrdiff_t i, double speed_squared) const {
    const double density = mass[i] / volume[i];
    double stiffness = p_modulus[material[i]];
    if constexpr (Drawn) stiffness *= scale[i];
    return std::sqrt(stiffness / density) + std::sqrt(speed_squared);
  }

  // The square of the speed beyond which particle i's energy is exploding:
  // its material's P wave. A stiff draw carries a faster wave; a soft one is
  // still stepped at the stiffest particle's step, so it is held to its
  // material's speed.
  template <bool Drawn>
  [[gnu::always_inline]] double runaway_squared(std::ptrdiff_t i) const {
    const double limit = wave_squared[material[i]];
    return Drawn ? std::max(1.0, scale[i]) * limit : limit;
  }
};

// f(std::bool_constant<Drawn>{}), Drawn whether the particles carry a
// heterogeneous material's draws of the moduli: the lanes' loops are
// compiled for either, with no test inside.
template <int Dim, class F>
[[gnu::always_inline]] inline void with_draws(const Particles<Dim>& p, F&& f) {
  if (p.modulus_scale.empty())
    f(std::false_type{});
  else
    f(std::true_type{});
}

// Whether particle i's stress (Dim x Dim entries at stress) is finite, by
// entry-wise tests that vectorise over lanes.
template <int Dim>
[[gnu::always_inline]] inline bool stress_finite(const double* stress, std::ptrdiff_t i) {
  bool finite = true;
#pragma GCC unroll 9
  for (int e = 0; e < Dim * Dim; ++e) finite &= std::isfinite(stress[Dim * Dim * i + e]);
  return finite;
}

// How many of the particles particle(0 .. lanes - 1) have a non-finite stress.
template <int Dim, class Particle>
[[gnu::always_inline]] inline long non_finite_stresses(const Particles<Dim>& p, Particle particle, int lanes) {
  const double* stress = p.stress.data()->data();
  long bad = 0;
#pragma omp simd reduction(+ : bad)
  for (int lane = 0; lane < lanes; ++lane) bad += !stress_finite<Dim>(stress, particle(lane));
  return bad;
}

}  // namespace outburst::mpm::passes

namespace outburst::mpm {

// Books the moved particles start .. start + lanes - 1: the work of a pore
// pressure on them (where the step stored their velocity gradients: the
// fused pass, which keeps them in lanes, books it itself), whether they went
// wrong or left, and the fastest signal among those that moved well (finite,
// on the grid and below their runaway speed), which sets the next step. Over
// SIMD lanes, the work then summed particle by particle, in order; the other
// books are counts and a maximum, which no order changes.
template <int Dim>
template <bool Stresses>
[[gnu::always_inline]] inline void Solver<Dim>::count(int start, int lanes, double dt, Census& census) const {
  const auto& p = particles_;
  constexpr int most = chunk_lanes;
  assert(lanes <= most);
  alignas(64) double pore_work[most];
  long bad = 0, escaped = 0, runaway = 0;
  double fastest = census.fastest;
  // Locals, as Speeds holds its fields.
  const double *x = p.x.data()->data(), *v = p.v.data()->data(), *stress = p.stress.data()->data(),
               *gradient = p.velocity_gradient.empty() ? nullptr : p.velocity_gradient.data()->data(),
               *pore_pressure = p.pore_pressure.data(), *volume = p.volume.data();
  const passes::Speeds speeds(p_modulus_, wave_speed_squared_.data(), p);
  const Vec<Dim> lower = grid_.lower, upper = grid_.upper;
  const auto over_lanes = [&](auto pore, auto drawn) __attribute__((always_inline)) {
#pragma omp simd reduction(+ : bad, escaped, runaway) reduction(max : fastest)
    for (int lane = 0; lane < lanes; ++lane) {
      const std::ptrdiff_t i = start + lane;
      // A pore pressure does work on the skeleton as it dilates.
      if constexpr (decltype(pore)::value) {
        double dilatation = gradient[Dim * Dim * i];
#pragma GCC unroll 2
        for (int e = 1; e < Dim; ++e) dilatation += gradient[Dim * Dim * i + e * (Dim + 1)];
        pore_work[lane] = pore_pressure[i] * volume[i] * dilatation * dt;
      }
      bool finite = true, inside = true;
#pragma GCC unroll 3
      for (int e = 0; e < Dim; ++e) {
        const double at = x[Dim * i + e];
        finite &= std::isfinite(at) & std::isfinite(v[Dim * i + e]);
        inside &= (at >= lower[e]) & (at <= upper[e]);
      }
      if constexpr (Stresses) finite &= passes::stress_finite<Dim>(stress, i);
      const double squared = passes::sum_of_squares<Dim>([&](int e) { return v[Dim * i + e]; });
      const bool fast = squared > speeds.runaway_squared<decltype(drawn)::value>(i);
      bad += !finite;
      escaped += finite & !inside;
      runaway += finite & inside & fast;
      const double speed = speeds.signal<decltype(drawn)::value>(i, squared);
      // A NaN speed (a particle turned inside out: negative volume) is
      // passed over, as std::max passed it over.
      if (finite & inside & !fast & (speed > fastest)) fastest = speed;
    }
  };
  const bool pore = !p.pore_pressure.empty() && !p.velocity_gradient.empty();
  passes::with_draws(p, [&](auto drawn) __attribute__((always_inline)) {
    if (pore)
      over_lanes(std::true_type{}, drawn);
    else
      over_lanes(std::false_type{}, drawn);
  });
  if (pore)
    for (int lane = 0; lane < lanes; ++lane) census.external_work += pore_work[lane];
  census.bad += bad;
  census.escaped += escaped;
  census.runaway += runaway;
  census.fastest = fastest;
}

#pragma omp declare reduction(merge : Census : omp_out += omp_in)

}  // namespace outburst::mpm
