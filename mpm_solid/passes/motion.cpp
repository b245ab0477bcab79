// Pass 6, grid to particles: each particle's new velocity (the FLIP/PIC
// blend, or APIC) and position from its stencil's nodes, the transfer's and
// the loads' energy books, and under USF the census of the moved particles
// and the mapping of the next step's mass and momentum, while the chunk is in
// cache. USL and MUSL defer the move (move_particles) to after their stress
// update.
#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <type_traits>

#include "mpm_solid/gathers.hpp"
#include "mpm_solid/passes/census.hpp"
#include "mpm_solid/passes/instantiate.hpp"
#include "mpm_solid/passes/loops.hpp"
#include "mpm_solid/passes/map_lanes.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

using namespace passes;

namespace {

// The new velocities and positions of particles start .. start + lanes - 1
// from what their stencils gathered, lane by lane (v_pic, dv and, under
// APIC, affine), and the transfer's and the loads' energy books. Move: the
// particles move now (USF); else their displacements wait for the stress
// update. The calling thread's sums are passed in: made outside the
// parallel region, a lambda would capture the shared ones rather than the
// thread's reduction copies.
template <int Dim, bool Apic, bool Move>
struct MotionUpdate {
  Particles<Dim>& p;
  double* displacement;  // of each particle over the step, when not Move
  double flip, dt;
  bool loads;

  // Over SIMD lanes, the sums then taken particle by particle, in order.
  template <int Width>
  [[gnu::always_inline]] void operator()(int start, int lanes, const double (&v_pic)[Dim][Width],
                                         const double (&dv)[Dim][Width], const double* affine, double& lost,
                                         double& work) const {
    static_assert(Width <= chunk_lanes, "count() books at most chunk_lanes particles");
    alignas(64) double loss[Width], blend[Width], load_work[Width];
    double *x = p.x.data()->data(), *v = p.v.data()->data();
    const auto over_lanes = [&](auto loaded) __attribute__((always_inline)) {
#pragma omp simd
      for (int lane = 0; lane < lanes; ++lane) {
        const std::ptrdiff_t i = start + lane;
        const double m = p.mass[i];
        // Pure FLIP hands each particle the grid's change, interpolated: its
        // kinetic energy gains m (v . dv + |dv|^2 / 2), short of the grid's
        // share m ((v + affine) . dv + sum w |dv_i|^2 / 2) by the increment's
        // spread over the stencil (summed over the nodes: grid_update) less
        // m |dv|^2 / 2 (and under APIC the affine term). It keeps what the
        // grid cannot hold (sub-cell velocity differences); the PIC share,
        // and APIC, replace that with the grid's field. All of it is what the
        // transfer takes.
        double v_flip[Dim], v_new[Dim];
#pragma GCC unroll 3
        for (int e = 0; e < Dim; ++e) {
          v_flip[e] = v[Dim * i + e] + dv[e][lane];
          v_new[e] = Apic ? v_pic[e][lane] : flip * v_flip[e] + (1 - flip) * v_pic[e][lane];
          v[Dim * i + e] = v_new[e];
        }
        const double change = sum_of_squares<Dim>([&](int e) { return dv[e][lane]; }),
                     before = sum_of_squares<Dim>([&](int e) { return v_flip[e]; }),
                     after = sum_of_squares<Dim>([&](int e) { return v_new[e]; });
        loss[lane] = -0.5 * m * change;
        if constexpr (Apic) loss[lane] += m * affine[lane];
        blend[lane] = 0.5 * m * (before - after);
        // The external force works along the way the particle went, at the
        // grid's velocity halfway through the step (the grid's kinetic energy
        // changes by f (v + v_new) dt / 2), not its own FLIP-blended one.
        if constexpr (decltype(loaded)::value) {
          const double *force = p.external_force[i].data(), *surface = p.surface_force[i].data();
          double worked = (force[0] + surface[0]) * (dt * (v_pic[0][lane] - 0.5 * dv[0][lane]));
#pragma GCC unroll 2
          for (int e = 1; e < Dim; ++e) worked += (force[e] + surface[e]) * (dt * (v_pic[e][lane] - 0.5 * dv[e][lane]));
          load_work[lane] = worked;
        }
#pragma GCC unroll 3
        for (int e = 0; e < Dim; ++e) {
          if constexpr (Move)
            x[Dim * i + e] += dt * v_pic[e][lane];
          else
            displacement[Dim * i + e] = dt * v_pic[e][lane];
        }
      }
    };
    if (loads) {
      over_lanes(std::true_type{});
      for (int lane = 0; lane < lanes; ++lane) work += load_work[lane];
    } else {
      over_lanes(std::false_type{});
    }
    for (int lane = 0; lane < lanes; ++lane) {
      lost += loss[lane];
      lost += blend[lane];
    }
  }
};

// What APIC gathers at one particle from its stencil's nodes.
template <int Dim>
struct AffineSums {
  double v_pic[Dim][1], dv[Dim][1];
  Mat<Dim> b = Mat<Dim>::Zero();
  Vec<Dim> d = Vec<Dim>::Zero();  // diagonal of D = sum w (x_i - x_p)(x_i - x_p)^T
  double affine = 0;              // sum w (C (x_i - x_p)) . dv_i
};

template <int Dim, class Shape>
[[gnu::always_inline]] inline AffineSums<Dim> affine_sums(const Stencil<Dim, Shape>& s, const Mat<Dim>& c,
                                                          const std::vector<Vec<Dim>>& velocity,
                                                          const std::vector<Vec<Dim>>& velocity_new) {
  AffineSums<Dim> sums;
  Vec<Dim> v_pic = Vec<Dim>::Zero(), dv = Vec<Dim>::Zero();
  for (int k = 0; k < s.count; ++k) {
    const auto node = s.node[k];
    const Vec<Dim> change = velocity_new[node] - velocity[node];
    v_pic += s.weight[k] * velocity_new[node];
    dv += s.weight[k] * change;
    sums.b += s.weight[k] * velocity_new[node] * s.offset[k].transpose();
    sums.d += s.weight[k] * s.offset[k].cwiseProduct(s.offset[k]);
    // The affine share of the momentum this particle mapped, which its own
    // velocity does not carry, worked by the update.
    sums.affine += s.weight[k] * (c * s.offset[k]).dot(change);
  }
  for (int e = 0; e < Dim; ++e) {
    sums.v_pic[e][0] = v_pic[e];
    sums.dv[e][0] = dv[e];
  }
  return sums;
}

}  // namespace

// Move means this is the step's last transfer: the particles move right away
// and are counted (one pass less); otherwise their displacements wait.
template <int Dim>
template <class Shape, bool Apic, bool Move>
void Solver<Dim>::gather_motion(double dt) {
  Census census;
  double lost = 0, work = 0;
  if constexpr (Apic)
    gather_affine_motion<Shape, Move>(dt, census, lost, work);
  else
    gather_blended_motion<Shape, Move>(dt, census, lost, work);
  if constexpr (Move) census_ = census;
  dissipated_.transfer += lost;
  dissipated_.external += work;
}

// APIC, a particle at a time: the velocity and B from the stencil's nodes.
template <int Dim>
template <class Shape, bool Move>
void Solver<Dim>::gather_affine_motion(double dt, Census& census, double& lost, double& work) {
  auto& p = particles_;
  const int n = static_cast<int>(p.size());
  const MotionUpdate<Dim, true, Move> update{p, Move ? nullptr : displacement_.data()->data(),
                                             settings_.flip_fraction, dt, !p.external_force.empty()};
#pragma omp parallel reduction(merge : census) reduction(+ : lost, work)
  {
    const Lattice<Dim> lattice(grid_);
    Stencil<Dim, Shape> s;
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      s.template compute<true>(lattice, p.x[i], p.half_width[i]);
      const AffineSums<Dim> sums = affine_sums(s, p.affine[i], velocity_, velocity_new_);
      update(i, 1, sums.v_pic, sums.dv, &sums.affine, lost, work);
      if constexpr (Move) count<false>(i, 1, dt, census);  // USF: the update checked the stresses
      // D is diagonal for tensor-product shapes that reproduce linear fields;
      // a particle on a linear-shape node has D = 0 along that axis (and B too).
      for (int c = 0; c < Dim; ++c)
        p.affine[i].col(c) = sums.d[c] > 1e-12 * grid_.h * grid_.h ? Vec<Dim>(sums.b.col(c) / sums.d[c])
                                                                   : Vec<Dim>::Zero();
    }
  }
}

// The FLIP/PIC blend, a chunk of lanes at a time. Under Move the particles
// just moved map their mass and momentum for the next step as well
// (docs/theory/mpm.md): the chunk's positions and velocities are still in
// registers and cache, and a pass over the particles and a parallel region a
// step are saved.
template <int Dim>
template <class Shape, bool Move>
void Solver<Dim>::gather_blended_motion(double dt, Census& census, double& lost, double& work) {
  auto& p = particles_;
  using Lanes = StencilLanes<Dim, Shape>;
  const MotionUpdate<Dim, false, Move> update{p, Move ? nullptr : displacement_.data()->data(),
                                              settings_.flip_fraction, dt, !p.external_force.empty()};
  const double *now = velocity_.data()->data(), *next = velocity_new_.data()->data();
  Scatter<double> masses{thread_mass_, mass_, active_.runs()};
  Scatter<Vec<Dim>> momenta{thread_vector_, momentum_, active_.runs()};
  long outside = 0;
#pragma omp parallel num_threads(threads_) reduction(merge : census) reduction(+ : lost, work, outside)
  {
    const Lattice<Dim> lattice(grid_);
    Lanes s(lattice), ahead(lattice);
    double* m = nullptr;
    Vec<Dim>* mv = nullptr;
    std::uint8_t* reached = nullptr;
    const auto strides = active_.strides();
    if constexpr (Move) {
      clear_sums();  // the step's sums were last read by grid_update
      m = masses.buffer(omp_get_thread_num()).data();
      mv = momenta.buffer(omp_get_thread_num()).data();
      reached = active_.marks(omp_get_thread_num());
    }
    over_chunks(s, p, [&](int start, int lanes) __attribute__((always_inline)) {
      alignas(64) double v_pic[Dim][Lanes::width], dv[Dim][Lanes::width];
      gathers::motion_sums<gather_pairs>(now, next, s, lanes, v_pic, dv);
      const long troubled = census.bad + census.runaway;
      update(start, lanes, v_pic, dv, nullptr, lost, work);
      if constexpr (Move) {
        count<false>(start, lanes, dt, census);  // USF: the update checked the stresses
        // A chunk the census found a non-finite or runaway particle in is
        // not mapped (its positions may lie beyond int's range, where the
        // stencils' floor is undefined): the step throws, and a caller
        // that steps on maps afresh.
        if (census.bad + census.runaway > troubled) {
          outside += lanes;
        } else {
          ahead.compute(p.x.data(), p.half_width.data(), [start](int lane) { return start + lane; }, lanes);
          outside += map_lanes(p, ahead, start, lanes, m, mv, reached, strides);
        }
      }
    });
  }
  if constexpr (Move) {
    active_.collect();
    clear_dropped();
    mapped_ahead_ = true;
    // A particle beyond the ghost nodes has left the grid (the census
    // counted it, and its removal maps the rest again) or gone wrong.
    if (outside > 0) discard_mapping();
  }
}

// USL and MUSL: the displacements gather_motion left, taken once the stress
// update has read the positions the step started from, and counted.
template <int Dim>
Census Solver<Dim>::move_particles(double dt) {
  auto& p = particles_;
  constexpr int width = chunk_lanes;
  const int n = static_cast<int>(p.size()), chunks = (n + width - 1) / width;
  Census census;
#pragma omp parallel for schedule(static) reduction(merge : census)
  for (int c = 0; c < chunks; ++c) {
    const int start = c * width, end = std::min(n, start + width);
    for (int i = start; i < end; ++i) p.x[i] += displacement_[i];
    count<true>(start, end - start, dt, census);
  }
  return census;
}

#define INSTANTIATE(Dim, Shape)                                               \
  template void Solver<Dim>::gather_motion<Shape, false, false>(double);     \
  template void Solver<Dim>::gather_motion<Shape, false, true>(double);      \
  template void Solver<Dim>::gather_motion<Shape, true, false>(double);      \
  template void Solver<Dim>::gather_motion<Shape, true, true>(double);
OUTBURST_MPM_EACH_SHAPE(INSTANTIATE)
#undef INSTANTIATE

template Census Solver<2>::move_particles(double);
template Census Solver<3>::move_particles(double);

}  // namespace outburst::mpm
