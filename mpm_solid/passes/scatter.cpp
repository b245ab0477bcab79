// Pass 1, particles to grid: the particles' mass and momentum scattered to
// the nodes of the active blocks they reach, and the nodal sums kept zero
// wherever no particle maps (the invariant the grid's passes rely on).
#include <omp.h>

#include <algorithm>
#include <cstdint>

#include <fmt/format.h>

#include "mpm_solid/passes/instantiate.hpp"
#include "mpm_solid/passes/loops.hpp"
#include "mpm_solid/passes/map_lanes.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

using namespace passes;

template <int Dim>
template <class Shape, bool Apic>
void Solver<Dim>::scatter_mass_momentum() {
  if (mapped_ahead_) {  // by the last step's move (gather_motion)
    mapped_ahead_ = false;
    return;
  }
  const auto& p = particles_;
  const int n = static_cast<int>(p.size());
  Scatter<double> masses{thread_mass_, mass_, active_.runs()};
  Scatter<Vec<Dim>> momenta{thread_vector_, momentum_, active_.runs()};
  long outside = 0;
#pragma omp parallel num_threads(threads_) reduction(+ : outside)
  {
    clear_sums();  // over the runs of the mapping before, ending at a barrier
    double* m = masses.buffer(omp_get_thread_num()).data();
    Vec<Dim>* mv = momenta.buffer(omp_get_thread_num()).data();
    std::uint8_t* reached = active_.marks(omp_get_thread_num());
    const auto strides = active_.strides();
    const Lattice<Dim> lattice(grid_);
    if constexpr (!Apic) {
      StencilLanes<Dim, Shape> s(lattice);
      // Particles leave the grid at the end of a step; one beyond its ghost
      // nodes here came from outside (a solver built with it there).
      over_chunks(s, p, [&](int start, int lanes) { outside += map_lanes(p, s, start, lanes, m, mv, reached, strides); });
    } else {
      Stencil<Dim, Shape> s;
#pragma omp for schedule(static)
      for (int i = 0; i < n; ++i) {
        if (!s.template compute<Apic>(lattice, p.x[i], p.half_width[i])) {
          ++outside;
          continue;
        }
        ActiveBlocks<Dim>::template set_reached<Shape::support>(reached, strides, s.base);
        // Read once: the compiler cannot tell the nodal sums from the
        // particle's fields, and would load these again after every store.
        const double mass = p.mass[i];
        const Vec<Dim> v = p.v[i];
        for (int k = 0; k < s.count; ++k) {
          const double wm = s.weight[k] * mass;
          m[s.node[k]] += wm;
          mv[s.node[k]] += wm * (v + p.affine[i] * s.offset[k]);
        }
      }
    }
  }
  active_.collect();
  clear_dropped();
  if (outside > 0)
    throw SimulationError(fmt::format("mpm: step {}: {} particles lie beyond the grid's ghost nodes", steps_ + 1,
                                      outside));
}

template <int Dim>
std::size_t Solver<Dim>::stray_nodal_values() const {
  std::vector<char> active(mass_.size(), 0);
  for (const auto& r : active_.runs()) std::fill_n(active.begin() + static_cast<std::ptrdiff_t>(r.first), r.count, 1);
  std::size_t stray = 0;
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    if (!active[i])
      stray += (mass_[i] != 0) + (momentum_[i] != Vec<Dim>::Zero()) + (force_[i] != Vec<Dim>::Zero()) +
               (velocity_[i] != Vec<Dim>::Zero()) + (velocity_new_[i] != Vec<Dim>::Zero());
    // Mapped ahead, the threads' copies hold the next step's sums until
    // grid_velocities adds them in: only on the active nodes.
    if (!mapped_ahead_ || !active[i]) {
      for (const auto& t : thread_mass_) stray += t[i] != 0;
      for (const auto& t : thread_vector_) stray += t[i] != Vec<Dim>::Zero();
    }
  }
  return stray;
}

// The grid's velocities are written at every active node before they are
// read: they are cleared only where the mapping no longer reaches
// (clear_dropped), and the sums here.
template <int Dim>
void Solver<Dim>::clear_sums() {
  const Runs& runs = active_.runs();
  const int n = static_cast<int>(runs.size());
#pragma omp for schedule(static)
  for (int r = 0; r < n; ++r) {
    const auto [first, count] = runs[static_cast<std::size_t>(r)];
    const auto from = static_cast<std::ptrdiff_t>(first);
    std::fill_n(mass_.begin() + from, count, 0.0);
    for (auto* field : {&momentum_, &force_}) std::fill_n(field->begin() + from, count, Vec<Dim>::Zero());
  }
}

template <int Dim>
void Solver<Dim>::discard_mapping() {
  if (!mapped_ahead_) return;
  mapped_ahead_ = false;
  over_nodes(active_.runs(), [&](std::size_t i) {
    mass_[i] = 0;
    momentum_[i] = Vec<Dim>::Zero();
    for (auto& t : thread_mass_) t[i] = 0;
    for (auto& t : thread_vector_) t[i] = Vec<Dim>::Zero();
  });
}

template <int Dim>
void Solver<Dim>::clear_dropped() {
  for (const NodeRun& r : active_.dropped()) {
    const auto from = static_cast<std::ptrdiff_t>(r.first);
    for (auto* field : {&velocity_, &velocity_new_}) std::fill_n(field->begin() + from, r.count, Vec<Dim>::Zero());
  }
}

#define INSTANTIATE(Dim, Shape)                                         \
  template void Solver<Dim>::scatter_mass_momentum<Shape, false>();     \
  template void Solver<Dim>::scatter_mass_momentum<Shape, true>();
OUTBURST_MPM_EACH_SHAPE(INSTANTIATE)
#undef INSTANTIATE

template std::size_t Solver<2>::stray_nodal_values() const;
template std::size_t Solver<3>::stray_nodal_values() const;
template void Solver<2>::clear_sums();
template void Solver<3>::clear_sums();
template void Solver<2>::discard_mapping();
template void Solver<3>::discard_mapping();
template void Solver<2>::clear_dropped();
template void Solver<3>::clear_dropped();

}  // namespace outburst::mpm
