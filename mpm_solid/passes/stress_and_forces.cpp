// Passes 3 and 4, the stresses and the forces: the velocity gradients
// gathered at the particles, the materials' stress update, and the internal
// and body forces scattered to the nodes. Under USF with pointwise materials
// the three run fused, a chunk at a time (update_and_scatter); otherwise as
// split passes, with the nodal dilatation smoothing between them if asked.
#include <omp.h>

#include <algorithm>
#include <span>

#include "mpm_solid/gathers.hpp"
#include "mpm_solid/passes/census.hpp"
#include "mpm_solid/passes/instantiate.hpp"
#include "mpm_solid/passes/loops.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

using namespace passes;

namespace {

// What a step's nodal forces take from the particles, decided once per pass:
// a scene without gravity or loads skips the body-force term altogether.
template <int Dim>
struct ForceTerms {
  Vec<Dim> gravity;
  const double* pore;  // alpha p, or null
  bool loads, body_forces;
};

template <int Dim>
ForceTerms<Dim> force_terms(const Particles<Dim>& p, const Settings<Dim>& settings) {
  const Vec<Dim> g = settings.gravity;
  const bool loads = !p.external_force.empty();
  return {g, p.pore_pressure.empty() ? nullptr : p.pore_pressure.data(), loads, loads || g.squaredNorm() > 0};
}

// Adds the internal and body forces of the particles of a chunk's lanes
// [from, to), on one stencil (StencilLanes::run_end), to its nodes, as
// map_lanes adds their masses; lane `lane` is particle(lane).
template <int Dim, class Shape, int Width, class Particle>
[[gnu::always_inline]] inline void add_forces(const Particles<Dim>& p, const ForceTerms<Dim>& t, Particle particle,
                                              const StencilLanes<Dim, Shape, Width>& s, int from, int to,
                                              std::vector<Vec<Dim>>& f) {
  using Lanes = StencilLanes<Dim, Shape, Width>;
  // add(k, force) at node k of the lane's stencil.
  const auto each_node = [&](int lane, auto&& add) __attribute__((always_inline)) {
    const auto i = particle(lane);
    Mat<Dim> vs = p.volume[i] * p.stress[i];
    if (t.pore) vs.diagonal().array() -= p.volume[i] * t.pore[i];
    if (!t.body_forces) {
      s.for_each_node([&](int k, const std::array<int, Dim>& a) {
        Vec<Dim> internal = vs.col(0) * s.gradient(0, a, lane);
        for (int d = 1; d < Dim; ++d) internal += vs.col(d) * s.gradient(d, a, lane);
        add(k, Vec<Dim>(-internal));
      });
      return;
    }
    const Vec<Dim> body = t.loads ? Vec<Dim>(p.mass[i] * t.gravity + p.external_force[i] + p.surface_force[i])
                                  : Vec<Dim>(p.mass[i] * t.gravity);
    s.for_each_node([&](int k, const std::array<int, Dim>& a) {
      Vec<Dim> total = s.weight(a, lane) * body;
      for (int d = 0; d < Dim; ++d) total -= vs.col(d) * s.gradient(d, a, lane);
      add(k, total);
    });
  };
  Vec<Dim>* at = f.data() + s.first[from];
  if constexpr (Lanes::runs) {
    Vec<Dim> sum[Lanes::count];
    for (auto& v : sum) v.setZero();
    for (int lane = from; lane < to; ++lane) each_node(lane, [&](int k, const Vec<Dim>& force) { sum[k] += force; });
    for (int k = 0; k < Lanes::count; ++k) at[s.offset[k]] += sum[k];
  } else {
    for (int lane = from; lane < to; ++lane)
      each_node(lane, [&](int k, const Vec<Dim>& force) { at[s.offset[k]] += force; });
  }
}

// add_forces over a chunk's lanes 0 .. lanes - 1, a run of them at a time.
template <int Dim, class Shape, int Width, class Particle>
[[gnu::always_inline]] inline void add_chunk_forces(const Particles<Dim>& p, const ForceTerms<Dim>& t,
                                                    Particle particle, const StencilLanes<Dim, Shape, Width>& s,
                                                    int lanes, std::vector<Vec<Dim>>& f) {
  for (int lane = 0; lane < lanes;) {
    const int end = s.run_end(lane, lanes);
    add_forces(p, t, particle, s, lane, end, f);
    lane = end;
  }
}

}  // namespace

template <int Dim>
template <class Shape>
void Solver<Dim>::gather_velocity_gradient() {
  auto& p = particles_;
#pragma omp parallel
  {
    const Lattice<Dim> lattice(grid_);
    StencilLanes<Dim, Shape> s(lattice);
    over_chunks(s, p, [&](int start, int lanes) {
      alignas(64) double l[Dim][Dim][decltype(s)::width];
      gathers::velocity_gradients<gather_pairs>(velocity_.data()->data(), s, lanes, l);
      for (int lane = 0; lane < lanes; ++lane) {
        Mat<Dim>& out = p.velocity_gradient[start + lane];
        for (int b = 0; b < Dim; ++b)
          for (int d = 0; d < Dim; ++d) out(b, d) = l[d][b][lane];
      }
    });
  }
}

template <int Dim>
template <class Shape>
void Solver<Dim>::smooth_dilatation() {
  auto& p = particles_;
  const int n = static_cast<int>(p.size());
  // Scatter V tr(L) and V into the first two components of force_, which is
  // free until scatter_forces rebuilds it.
  Scatter<Vec<Dim>> sums{thread_vector_, force_, active_.runs()};
  sums.clear();
#pragma omp parallel num_threads(threads_)
  {
    auto& weighted = sums.buffer(omp_get_thread_num());
    const Lattice<Dim> lattice(grid_);
    Stencil<Dim, Shape> s;
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      s.compute(lattice, p.x[i], p.half_width[i]);
      Vec<Dim> value = Vec<Dim>::Zero();
      value[0] = p.volume[i] * p.velocity_gradient[i].trace();
      value[1] = p.volume[i];
      for (int k = 0; k < s.count; ++k) weighted[s.node[k]] += s.weight[k] * value;
    }
  }
  sums.gather();
#pragma omp parallel
  {
    const Lattice<Dim> lattice(grid_);
    Stencil<Dim, Shape> s;
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      s.compute(lattice, p.x[i], p.half_width[i]);
      double smoothed = 0;
      for (int k = 0; k < s.count; ++k) {
        const Vec<Dim>& node = force_[s.node[k]];
        if (node[1] > 0) smoothed += s.weight[k] * node[0] / node[1];
      }
      Mat<Dim>& l = p.velocity_gradient[i];
      l.diagonal().array() += (smoothed - l.trace()) / Dim;
    }
  }
}

template <int Dim>
void Solver<Dim>::update_stresses(double dt) {
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    const Dissipation d = materials_[m]->update_stress(particles_, members_[m], dt);
    dissipated_.plastic += d.plastic;
    dissipated_.damage += d.damage;
  }
}

template <int Dim>
template <class Shape, bool Check>
long Solver<Dim>::scatter_forces() {
  const auto& p = particles_;
  const ForceTerms<Dim> terms = force_terms(p, settings_);
  Scatter<Vec<Dim>> forces{thread_vector_, force_, active_.runs()};
  forces.clear();
  long broken = 0;
#pragma omp parallel num_threads(threads_) reduction(+ : broken)
  {
    auto& f = forces.buffer(omp_get_thread_num());
    const Lattice<Dim> lattice(grid_);
    StencilLanes<Dim, Shape> s(lattice);
    over_chunks(s, p, [&](int start, int lanes) {
      const auto particle = [start](int lane) { return start + lane; };
      if constexpr (Check) broken += non_finite_stresses(p, particle, lanes);
      add_chunk_forces(p, terms, particle, s, lanes, f);
    });
  }
  return broken;
}

// gather_velocity_gradient, update_stresses and scatter_forces in one pass, a
// chunk of each material's particles at a time: the chunk's stencils and
// fields are still in cache when its forces are scattered, where three
// passes would compute the stencils twice and stream the fields three times.
// It measures faster under quadratic B-splines and, since the materials'
// trial runs over lanes, under linear shapes too, whose stencils cost little
// to compute again (mpm_solid/benchmark/fused-pass-bspline.csv and
// fused-pass-linear.csv; docs/performance/mpm.md#the-fused-update-stress-first-pass).
// The chunk's velocity gradients stay in
// its lanes (see chunk_size), so the pore pressure's work, which reads them,
// is booked here rather than in the census.
template <int Dim>
template <class Shape>
long Solver<Dim>::update_and_scatter(double dt) {
  auto& p = particles_;
  const ForceTerms<Dim> terms = force_terms(p, settings_);
  // force_ is zero: clear_sums zeroed it (in this step's mapping, or the last
  // step's move when it mapped ahead), and the pointwise update runs without
  // smooth_dilatation, the one pass that borrows it before the forces.
  Scatter<Vec<Dim>> forces{thread_vector_, force_, active_.runs()};
  double plastic = 0, damage = 0, pore_work = 0;
  long broken = 0;
#pragma omp parallel num_threads(threads_) reduction(+ : plastic, damage, pore_work, broken)
  {
    auto& f = forces.buffer(omp_get_thread_num());
    const Lattice<Dim> lattice(grid_);
    StencilLanes<Dim, Shape, chunk_size> s(lattice);
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      const std::span<const int> members(members_[m]);
      const int n = static_cast<int>(members.size()), chunks = (n + chunk_size - 1) / chunk_size;
      // No barrier between materials: their particles and the threads' force
      // buffers are apart.
#pragma omp for schedule(static) nowait
      for (int c = 0; c < chunks; ++c) {
        const auto chunk = members.subspan(c * chunk_size, std::min(chunk_size, n - c * chunk_size));
        const int lanes = static_cast<int>(chunk.size());
        // Consecutive members by position: the lanes load the positions as
        // blocks; through the list they were gathers, the positions' gather
        // the pass's hottest instruction.
        by_position(chunk, [&](auto particle) __attribute__((always_inline)) {
          s.compute(p.x.data(), p.half_width.data(), particle, lanes);
          alignas(64) double l[Dim][Dim][chunk_size];
          gathers::velocity_gradients<gather_pairs>(velocity_.data()->data(), s, lanes, l);
          const Dissipation d = materials_[m]->update_chunk(p, chunk, dt, &l[0][0][0]);
          plastic += d.plastic;
          damage += d.damage;
          // The census's check of the stresses, here where they are still in
          // L1: the motion pass reads 32 B a particle less in the plane, 72 B
          // in 3D (docs/performance/log.md#the-mpm-kernel).
          broken += non_finite_stresses(p, particle, lanes);
          // A pore pressure does work on the skeleton as it dilates (at
          // the volume the update left, as the census books it).
          if (terms.pore)
            for (int lane = 0; lane < lanes; ++lane) {
              const auto i = particle(lane);
              double dilatation = l[0][0][lane];
              for (int e = 1; e < Dim; ++e) dilatation += l[e][e][lane];
              pore_work += terms.pore[i] * p.volume[i] * dilatation * dt;
            }
          add_chunk_forces(p, terms, particle, s, lanes, f);
        });
      }
    }
  }
  dissipated_.plastic += plastic;
  dissipated_.damage += damage;
  dissipated_.external += pore_work;
  return broken;
}

#define INSTANTIATE(Dim, Shape)                                      \
  template void Solver<Dim>::gather_velocity_gradient<Shape>();     \
  template void Solver<Dim>::smooth_dilatation<Shape>();            \
  template long Solver<Dim>::scatter_forces<Shape, false>();        \
  template long Solver<Dim>::scatter_forces<Shape, true>();         \
  template long Solver<Dim>::update_and_scatter<Shape>(double);
OUTBURST_MPM_EACH_SHAPE(INSTANTIATE)
#undef INSTANTIATE

template void Solver<2>::update_stresses(double);
template void Solver<3>::update_stresses(double);

}  // namespace outburst::mpm
