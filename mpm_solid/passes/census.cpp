// The census's verdict and the next step: the stable time step from the
// fastest signal, and the particles the census found wrong (a clear error
// naming particle and field), running away (the energy exploding) or gone
// off the grid (removed, with the energy they carry off booked).
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "mpm_solid/passes/census.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

using namespace passes;

template <int Dim>
double stable_time_step(const std::vector<std::unique_ptr<Material<Dim>>>& materials,
                        const Particles<Dim>& particles, double h, double courant) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(particles.size());
  if (n == 0) return std::numeric_limits<double>::infinity();
  double fastest = 0;
  const std::vector<double> p_modulus = p_moduli(materials);
  const Speeds speeds(p_modulus, nullptr, particles);
  const double* velocity = particles.v.data()->data();
  with_draws(particles, [&](auto drawn) {
#pragma omp parallel for simd schedule(static) reduction(max : fastest)
    for (std::ptrdiff_t i = 0; i < n; ++i) {
      const double squared = sum_of_squares<Dim>([&](int e) { return velocity[Dim * i + e]; });
      fastest = std::max(fastest, speeds.signal<decltype(drawn)::value>(i, squared));
    }
  });
  return courant * h / fastest;
}

template <int Dim>
double Solver<Dim>::stable_time_step() const {
  if (fastest_ > 0) return settings_.courant * grid_.h / fastest_;
  return mpm::stable_time_step(materials_, particles_, grid_.h, settings_.courant);
}

template <int Dim>
[[gnu::always_inline]] inline double Solver<Dim>::runaway_speed_squared(int i) const {
  const Speeds speeds(p_modulus_, wave_speed_squared_.data(), particles_);
  return particles_.modulus_scale.empty() ? speeds.runaway_squared<false>(i) : speeds.runaway_squared<true>(i);
}

// Whether every entry is finite. Eigen's allFinite() compares x - x with
// itself, and grown with the dimension's templates it was no longer inlined
// into the move: a call per particle, and the move 10 % slower.
namespace {
template <class M>
[[gnu::always_inline]] inline bool finite(const M& m) {
  bool all = true;
  for (int k = 0; k < m.size(); ++k) all = all && std::isfinite(m.data()[k]);
  return all;
}
}  // namespace

template <int Dim>
void Solver<Dim>::remove_escaped(const Census& census, StepInfo& info) {
  auto& p = particles_;
  const int n = static_cast<int>(p.size());
  const long bad = census.bad + census.bad_stresses, escaped = census.escaped, runaway = census.runaway;
  // Material outrunning its own P wave is beyond what an explicit step can carry:
  // the energy is exploding. Stop before it turns into NaN.
  if (runaway > 0 && bad == 0)
    for (int i = 0; i < n; ++i) {
      if (p.v[i].squaredNorm() <= runaway_speed_squared(i)) continue;
      throw SimulationError(fmt::format(
          "mpm: step {} (t = {:.6g} s): the energy is exploding: particle {} (material \"{}\") has a velocity "
          "of {:.3g} m/s, above its P-wave speed {:.3g} m/s; the time step may exceed the stable one, or a load "
          "is out of range",
          steps_ + 1, time_, p.id[i], materials_[p.material[i]]->name(), p.v[i].norm(),
          std::sqrt(runaway_speed_squared(i))));
    }
  // A non-finite stress the USF update wrote went wrong first, whatever else
  // did: the particles' positions, velocities and the grid were finite then,
  // and its forces carried it into the velocities and positions around.
  // Under USL and MUSL the update comes last, and reads velocities that may
  // have gone wrong before it (the census counts their stresses as bad).
  const bool stress_first = census.bad_stresses > 0;
  if (bad > 0)
    for (int i = 0; i < n; ++i) {
      const bool at = finite(p.x[i]), moving = finite(p.v[i]), stressed = finite(p.stress[i]);
      if (stress_first ? stressed : at && moving && stressed) continue;
      const char* field = stress_first || (at && moving) ? "stress" : !at ? "position" : "velocity";
      throw SimulationError(fmt::format(
          "mpm: step {} (t = {:.6g} s): particle {} (material \"{}\") has a non-finite {}; the time "
          "step may exceed the stable one, or a material parameter is out of range",
          steps_ + 1, time_, p.id[i], materials_[p.material[i]]->name(), field));
    }
  if (escaped == 0) return;
  if (escaped == n) throw SimulationError(fmt::format("mpm: step {}: every particle has left the grid", steps_ + 1));
  std::vector<char> keep(p.size());
  for (int i = 0; i < n; ++i) keep[i] = grid_.inside(p.x[i]);
  // The energy they carry off leaves the books with them.
  std::vector<std::vector<int>> leaving(materials_.size());
  for (int i = 0; i < n; ++i)
    if (!keep[i]) {
      leaving[p.material[i]].push_back(i);
      const double kinetic = 0.5 * p.mass[i] * p.v[i].squaredNorm();
      dissipated_.left += kinetic - p.mass[i] * settings_.gravity.dot(p.x[i] - grid_.lower);
      dissipated_.left_kinetic += kinetic;
    }
  for (std::size_t m = 0; m < materials_.size(); ++m)
    if (!leaving[m].empty()) dissipated_.left += materials_[m]->strain_energy(p, leaving[m]);
  p.keep(keep);
  discard_mapping();
  info.removed = static_cast<std::size_t>(escaped);
  removed_ += info.removed;
  rebuild_material_groups();
}

template double stable_time_step(const std::vector<std::unique_ptr<Material<2>>>&, const Particles<2>&, double,
                                 double);
template double stable_time_step(const std::vector<std::unique_ptr<Material<3>>>&, const Particles<3>&, double,
                                 double);
template double Solver<2>::stable_time_step() const;
template double Solver<3>::stable_time_step() const;
template void Solver<2>::remove_escaped(const Census&, StepInfo&);
template void Solver<3>::remove_escaped(const Census&, StepInfo&);

}  // namespace outburst::mpm
