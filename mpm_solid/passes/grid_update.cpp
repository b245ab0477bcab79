// Passes 2 and 5, on the grid: the nodal velocities from the mapped momenta,
// and the update of the velocities by the nodal forces, with the damping, the
// platens and the walls (walls.cpp) applied, and the grid's share of the
// energy books.
#include <cmath>

#include "mpm_solid/passes/ghosts.hpp"
#include "mpm_solid/passes/loops.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

using namespace passes;

// The threads' copies of the mass and momentum summed, and the velocities
// taken, in one pass; the ghost folds then change the nodes they fold into,
// whose velocities are taken again.
template <int Dim>
void Solver<Dim>::grid_velocities() {
  Scatter<double> masses{thread_mass_, mass_, active_.runs()};
  Scatter<Vec<Dim>> momenta{thread_vector_, momentum_, active_.runs()};
  const auto velocity = [&](std::size_t i) {
    velocity_[i] = mass_[i] > empty_node_mass_ ? Vec<Dim>(momentum_[i] / mass_[i]) : Vec<Dim>::Zero();
  };
  over_nodes(active_.runs(), [&](std::size_t i) {
    masses.gather(i);
    momenta.gather(i);
    velocity(i);
  });
  fold_ghosts(&mass_, momentum_, velocity);
  apply_platens(velocity_, 0, 0);
  apply_walls(velocity_);
}

// A massless plate moves with the momentum of the nodes it holds plus its
// force's impulse, shared over their mass, or at its set speed, with the force
// that takes; it moves them all with it.
template <int Dim>
void Solver<Dim>::apply_platens(std::vector<Vec<Dim>>& velocity, double impulse, double dt) {
  for (std::size_t k = 0; k < platen_nodes_.size(); ++k) {
    const Platen<Dim>& platen = settings_.platens[k];
    double mass = 0, momentum = 0;
    for (std::size_t i : platen_nodes_[k])
      if (mass_[i] > empty_node_mass_) {
        mass += mass_[i];
        momentum += mass_[i] * velocity[i][platen.axis];
      }
    if (mass == 0) continue;
    const double v = platen.velocity ? *platen.velocity : (momentum + impulse * platen.force) / mass;
    for (std::size_t i : platen_nodes_[k])
      if (mass_[i] > empty_node_mass_) velocity[i][platen.axis] = v;
    if (dt == 0) continue;  // the step's start: no force has acted yet
    platen_force_[k] = platen.velocity ? (mass * v - momentum) / dt : platen.force;
    platen_displacement_[k] += v * dt;
    dissipated_.external += platen_force_[k] * v * dt;
  }
}

// The threads' copies of the force are summed first. Without local damping
// (which reads the summed forces) that pass takes the updated velocities too,
// and the nodes the ghost folds change take theirs again.
template <int Dim>
void Solver<Dim>::grid_update(double dt) {
  const Runs& runs = active_.runs();
  Scatter<Vec<Dim>> forces{thread_vector_, force_, runs};
  // v_new = (v + dt f / m) / (1 + c dt): the viscous force -c m v_new.
  const double c = settings_.viscous_damping, shrink = 1 / (1 + c * dt);
  const auto update = [&](std::size_t i) {
    velocity_new_[i] =
        mass_[i] > empty_node_mass_ ? Vec<Dim>(shrink * (velocity_[i] + dt * force_[i] / mass_[i])) : Vec<Dim>::Zero();
  };
  if (const double alpha = settings_.local_damping; alpha > 0) {
    forces.gather();
    fold_ghosts(nullptr, force_, [](std::size_t) {});
    dissipated_.damping += sum_over_nodes(runs, [&](std::size_t i) {
      double work = 0;
      for (int d = 0; d < Dim; ++d)
        if (velocity_[i][d] != 0) {
          const double damping = alpha * std::abs(force_[i][d]);
          force_[i][d] -= damping * std::copysign(1.0, velocity_[i][d]);
          // Ghosts beyond a fixed or roller wall mirror a node inside: their
          // work is that node's, booked once.
          if (counted_[i]) work += damping * std::abs(velocity_[i][d]) * dt;
        }
      return work;
    });
    over_nodes(runs, update);
  } else {
    over_nodes(runs, [&](std::size_t i) {
      forces.gather(i);
      update(i);
    });
    fold_ghosts(nullptr, force_, update);
  }
  apply_platens(velocity_new_, shrink * dt, dt);  // before the walls: the ghost nodes mirror the plate's motion
  dissipated_.walls += apply_walls(velocity_new_);
  // The grid's work on pure FLIP particles is sum_i p_i . dv_i, with the
  // momenta p_i they mapped, plus sum_p m_p sum_i w_ip |dv_i|^2 / 2
  // (Solver::energies). Walls and platens changed p_i to m_i v_i before the
  // update: that change, worked by the update, is theirs. The second sum,
  // the increment's spread, is the nodes' sum_i m_i |dv_i|^2 / 2: the nodal
  // masses are the particles' mapped with the same weights, a ghost's folded
  // into its mirror, whose |dv| it shares (as the first sum takes its p_i;
  // apply_walls leaves every ghost its mirror's motion, where a friction wall
  // meets a fixed one too). Taken particle by particle, over each
  // stencil's nodes, it cost the step 4-5 % (docs/performance/log.md); it is
  // also all the transfer keeps, less sum_p m_p |dv_p|^2 / 2 (gather_motion;
  // docs/theory/energies.md#3-the-transfer-book).
  double work = 0, projected = 0, spread = 0;
  const int nr = static_cast<int>(runs.size());
#pragma omp parallel for schedule(static) reduction(+ : work, projected, spread)
  for (int r = 0; r < nr; ++r)
    for (std::size_t i = runs[r].first, end = i + static_cast<std::size_t>(runs[r].count); i < end; ++i)
      if (counted_[i]) {
        const Vec<Dim> change = velocity_new_[i] - velocity_[i];
        work += mass_[i] * velocity_[i].dot(change);
        projected += (momentum_[i] - mass_[i] * velocity_[i]).dot(change);
        spread += mass_[i] * change.squaredNorm();
      }
  dissipated_.grid_work += work + projected + 0.5 * spread;
  dissipated_.transfer += 0.5 * spread;
  dissipated_.walls -= projected;
  if (c > 0) {
    // The damping force -c m v_new works along the way the nodes carry the
    // particles, v_new dt (after the walls: what a wall stops does not move),
    // as the external forces are booked.
    dissipated_.damping += sum_over_nodes(runs, [&](std::size_t i) {
      return counted_[i] ? c * dt * mass_[i] * velocity_new_[i].squaredNorm() : 0.0;
    });
  }
}

#define INSTANTIATE(Dim)                                                                      \
  template void Solver<Dim>::grid_velocities();                                               \
  template void Solver<Dim>::apply_platens(std::vector<Vec<Dim>>&, double, double);           \
  template void Solver<Dim>::grid_update(double);
INSTANTIATE(2)
INSTANTIATE(3)
#undef INSTANTIATE

}  // namespace outburst::mpm
