// The energy books: the energies the particles store now, the run's
// dissipated, numerical and external totals, the balance they close, and
// its audit over a run (docs/theory/energies.md).
#include "mpm_solid/energy_books.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

void Energies::save(checkpoint::Out out, const std::string& name) const {
  out.numbers(name, std::vector<double>{kinetic, strain, gravity, plastic, damage, damping, walls, transfer,
                                        integration, left, external, grid_work, left_kinetic, stored_start});
}

Energies Energies::load(const checkpoint::In& in, const std::string& name) {
  const auto v = in.numbers(name, 14);
  return {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13]};
}

template <int Dim>
double Solver<Dim>::kinetic_energy() const {
  const auto& p = particles_;
  const int n = static_cast<int>(p.size());
  double kinetic = 0;
#pragma omp parallel for schedule(static) reduction(+ : kinetic)
  for (int i = 0; i < n; ++i) kinetic += 0.5 * p.mass[i] * p.v[i].squaredNorm();
  return kinetic;
}

template <int Dim>
double Solver<Dim>::gravitational_energy() const {
  const auto& p = particles_;
  const int n = static_cast<int>(p.size());
  const Vec<Dim> g = settings_.gravity;
  double gravity = 0;
#pragma omp parallel for schedule(static) reduction(+ : gravity)
  for (int i = 0; i < n; ++i) gravity -= p.mass[i] * g.dot(p.x[i] - grid_.lower);
  return gravity;
}

template <int Dim>
double Solver<Dim>::strain_energy() const {
  double strain = 0;
  for (std::size_t m = 0; m < materials_.size(); ++m) strain += materials_[m]->strain_energy(particles_, members_[m]);
  return strain;
}

template <int Dim>
Energies Solver<Dim>::energies() const {
  Energies e = dissipated_;
  e.strain = strain_energy();
  e.kinetic = kinetic_energy();
  e.gravity = gravitational_energy();
  // Had the step been exact, the grid's work would equal what the stored,
  // dissipated and external energies lost; the difference is the step's.
  if (steps_ > 0)
    e.integration = -(e.grid_work + e.strain + e.gravity - e.stored_start + e.plastic + e.damage + e.damping +
                      e.walls + e.left - e.left_kinetic - e.external);
  return e;
}

void EnergyAudit::save(checkpoint::Out out) const {
  out.flag("started", first_.has_value());
  if (first_) first_->save(out, "first");
  out.numbers("measures",
              std::vector<double>{largest_term_, worst_error_, worst_time_, last_error_, worst_integration_});
}

void EnergyAudit::load(const checkpoint::In& in) {
  first_.reset();
  if (in.flag("started")) first_ = Energies::load(in, "first");
  const auto m = in.numbers("measures", 5);
  largest_term_ = m[0];
  worst_error_ = m[1];
  worst_time_ = m[2];
  last_error_ = m[3];
  worst_integration_ = m[4];
}

void EnergyAudit::record(const Energies& e, double time) {
  if (!first_) first_ = e;
  const Energies& f = *first_;
  for (double term : {e.kinetic - f.kinetic, e.strain - f.strain, e.gravity - f.gravity, e.plastic, e.damage,
                      e.damping, e.walls, e.transfer, e.left, e.external})
    largest_term_ = std::max(largest_term_, std::abs(term));
  worst_integration_ = std::max(worst_integration_, std::abs(e.integration - f.integration));
  last_error_ = std::abs(e.total() - f.total());
  if (const double error = last_error_; error > worst_error_) {
    worst_error_ = error;
    worst_time_ = time;
  }
}

#define INSTANTIATE(Dim)                                      \
  template double Solver<Dim>::kinetic_energy() const;        \
  template double Solver<Dim>::gravitational_energy() const;  \
  template double Solver<Dim>::strain_energy() const;         \
  template Energies Solver<Dim>::energies() const;
INSTANTIATE(2)
INSTANTIATE(3)
#undef INSTANTIATE

}  // namespace outburst::mpm
