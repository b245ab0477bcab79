#include "mpm_solid/solver.hpp"

#include <omp.h>

#include <algorithm>
#include <cassert>
#include <numeric>
#include <cmath>
#include <limits>
#include <type_traits>

#include <fmt/format.h>

#include "common/interval.hpp"
#include "mpm_solid/gathers.hpp"
#include "mpm_solid/shape.hpp"
#include "mpm_solid/stencil.hpp"

namespace outburst::mpm {

namespace {

using Runs = std::vector<NodeRun>;

// Runs f(i) over the nodes of the runs, in parallel.
template <class F>
void over_nodes(const Runs& runs, F&& f) {
  const int n = static_cast<int>(runs.size());
#pragma omp parallel for schedule(static)
  for (int r = 0; r < n; ++r)
    for (std::size_t i = runs[r].first, end = i + static_cast<std::size_t>(runs[r].count); i < end; ++i) f(i);
}

// The sum of f(i) over the nodes of the runs, in parallel.
template <class F>
double sum_over_nodes(const Runs& runs, F&& f) {
  const int n = static_cast<int>(runs.size());
  double sum = 0;
#pragma omp parallel for schedule(static) reduction(+ : sum)
  for (int r = 0; r < n; ++r)
    for (std::size_t i = runs[r].first, end = i + static_cast<std::size_t>(runs[r].count); i < end; ++i) sum += f(i);
  return sum;
}

template <class T>
T zero() {
  if constexpr (std::is_arithmetic_v<T>)
    return T(0);
  else
    return T::Zero();
}

// Scattering without locks: thread 0 adds straight into the grid field, the
// others into private copies that gather() adds in afterwards, over the
// active nodes (nothing is scattered elsewhere). buffer(t) is where thread t
// writes.
template <class T>
struct Scatter {
  std::vector<std::vector<T>>& others;  // threads 1, 2, ...
  std::vector<T>& total;
  const Runs& runs;

  void clear() {
    over_nodes(runs, [&](std::size_t i) { total[i] = zero<T>(); });
  }
  std::vector<T>& buffer(int t) { return t == 0 ? total : others[static_cast<std::size_t>(t - 1)]; }
  // Adds the other threads' copies into the total at node i, and clears them.
  void gather(std::size_t i) {
    for (auto& part : others) {
      total[i] += part[i];
      part[i] = zero<T>();
    }
  }
  void gather() {
    if (!others.empty()) over_nodes(runs, [&](std::size_t i) { gather(i); });
  }
};

// Which form the gathers' node loops take (mpm_solid/gathers.hpp; CMake's
// OUTBURST_GATHER picks it for the build).
#ifdef OUTBURST_GATHER_PAIRS
constexpr bool gather_pairs = true;
#else
constexpr bool gather_pairs = false;
#endif

// The helpers below run inside the particle loops (once per particle, or per
// chunk of them), and are forced inline: called, each returned or took its
// matrices through memory, and the loop stalled reloading them whole from
// halves just stored (a store is not forwarded to a wider load): 6 % of a
// B-spline step.

// f(start, lanes) over the particles in chunks of s's width, s computed for
// each: the threads of the enclosing parallel region share the chunks.
template <int Dim, class Shape, int Width, class F>
[[gnu::always_inline]] inline void over_chunks(StencilLanes<Dim, Shape, Width>& s, const Particles<Dim>& p, F&& f) {
  const int n = static_cast<int>(p.size()), chunks = (n + Width - 1) / Width;
#pragma omp for schedule(static)
  for (int c = 0; c < chunks; ++c) {
    const int start = c * Width, lanes = std::min(Width, n - start);
    s.compute(p.x.data(), p.half_width.data(), [start](int lane) { return start + lane; }, lanes);
    f(start, lanes);
  }
}

// Scatters the mass and momentum of particles start .. start + lanes - 1,
// whose stencils s holds, into m and mv, and marks the blocks they reach;
// returns how many lie beyond the ghost nodes (not mapped). A run of lanes
// on one stencil (StencilLanes::runs) is summed in registers, then added;
// elsewhere each lane adds straight into the nodes, as before the runs.
template <int Dim, class Shape, int Width>
[[gnu::always_inline]] inline long map_lanes(const Particles<Dim>& p, const StencilLanes<Dim, Shape, Width>& s,
                                             int start, int lanes, double* m, Vec<Dim>* mv, std::uint8_t* reached,
                                             const std::array<int, Dim - 1>& strides) {
  using Lanes = StencilLanes<Dim, Shape, Width>;
  // add(k, w m, w m v) at node k of the lane's stencil.
  const auto each_node = [&](int lane, auto&& add) __attribute__((always_inline)) {
    const int i = start + lane;
    const double mass = p.mass[i];
    const Vec<Dim> v = p.v[i];
    s.for_each_node([&](int k, const std::array<int, Dim>& a) {
      const double wm = s.weight(a, lane) * mass;
      add(k, wm, Vec<Dim>(wm * v));
    });
  };
  long outside = 0;
  for (int lane = 0; lane < lanes;) {
    if (!s.inside(lane)) {
      ++outside;
      ++lane;
      continue;
    }
    ActiveBlocks<Dim>::template set_reached<Shape::support>(reached, strides, s.lowest(lane));
    double* m_at = m + s.first[lane];
    Vec<Dim>* mv_at = mv + s.first[lane];
    if constexpr (Lanes::runs) {
      double mass_sum[Lanes::count] = {};
      Vec<Dim> momentum_sum[Lanes::count];
      for (auto& v : momentum_sum) v.setZero();
      for (const int end = s.run_end(lane, lanes); lane < end; ++lane)
        each_node(lane, [&](int k, double wm, const Vec<Dim>& wmv) {
          mass_sum[k] += wm;
          momentum_sum[k] += wmv;
        });
      for (int k = 0; k < Lanes::count; ++k) {
        m_at[s.offset[k]] += mass_sum[k];
        mv_at[s.offset[k]] += momentum_sum[k];
      }
    } else {
      each_node(lane++, [&](int k, double wm, const Vec<Dim>& wmv) {
        m_at[s.offset[k]] += wm;
        mv_at[s.offset[k]] += wmv;
      });
    }
  }
  return outside;
}

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

// Fixed and roller walls mirror their ghost nodes (fold_ghosts, apply_walls).
bool mirrors(Wall::Type type) { return type == Wall::Type::fixed || type == Wall::Type::roller; }

// A wall condition at one node; n is the unit normal pointing into the wall.
// Friction walls act only on nodes moving into them: the normal velocity is
// removed and the tangential one reduced by mu times that change. Returns the
// work done by friction (fixed and roller walls do none: the wall does not move).
template <int Dim>
double constrain(Vec<Dim>& v, const Vec<Dim>& n, const Wall& wall, double mass) {
  const double vn = v.dot(n);
  switch (wall.type) {
    case Wall::Type::fixed: v.setZero(); return 0;
    case Wall::Type::roller: v -= vn * n; return 0;
    case Wall::Type::friction: {
      if (vn <= 0) return 0;  // separating
      const Vec<Dim> vt = v - vn * n;
      const double slip = vt.norm();
      const double reduced = std::max(slip - wall.friction * vn, 0.0);
      v = slip > 0 ? Vec<Dim>(vt * (reduced / slip)) : Vec<Dim>::Zero();
      // Work of the friction impulse m (|v_t| - reduced) against the sliding.
      return mass * (slip - reduced) * reduced;
    }
    case Wall::Type::open: return 0;
  }
  return 0;
}

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

}  // namespace

template <int Dim>
Solver<Dim>::Solver(Grid<Dim> grid, std::vector<std::unique_ptr<Material<Dim>>> materials,
                    Particles<Dim> particles, Settings<Dim> settings)
    : grid_(grid),
      materials_(std::move(materials)),
      particles_(std::move(particles)),
      settings_(settings),
      active_(grid_,
              [&] {
                std::array<bool, 2 * Dim> mirrored{};
                for (int side = 0; side < 2 * Dim; ++side) mirrored[side] = mirrors(settings.walls[side].type);
                return mirrored;
              }(),
              omp_get_max_threads()) {
  if (particles_.size() == 0) throw std::invalid_argument("the scene creates no particles");
  const std::size_t n = grid_.num_nodes();
  mass_.assign(n, 0.0);
  for (auto* v : {&momentum_, &force_, &velocity_, &velocity_new_}) v->assign(n, Vec<Dim>::Zero());
  threads_ = omp_get_max_threads();
  thread_mass_.assign(static_cast<std::size_t>(threads_ - 1), std::vector<double>(n, 0.0));
  thread_vector_.assign(static_cast<std::size_t>(threads_ - 1), std::vector<Vec<Dim>>(n, Vec<Dim>::Zero()));
  node_ij_.resize(n);
  for (std::size_t flat = 0; flat < n; ++flat) {
    std::size_t rest = flat;
    for (int d = 0; d < Dim; ++d) {
      const auto along = static_cast<std::size_t>(grid_.nodes_along(d));
      node_ij_[flat][d] = static_cast<int>(rest % along);
      rest /= along;
    }
  }
  counted_.assign(n, 1);
  for (int side = 0; side < 2 * Dim; ++side) {
    if (!mirrors(settings_.walls[side].type)) continue;
    const int axis = side / 2, g = Grid<Dim>::ghost;
    const int wall_row = side % 2 == 0 ? g : g + grid_.cells[axis];
    for (std::size_t i = 0; i < n; ++i)
      if (side % 2 == 0 ? node_ij_[i][axis] < wall_row : node_ij_[i][axis] > wall_row) counted_[i] = 0;
  }

  double total_mass = 0;
  for (double m : particles_.mass) total_mass += m;
  empty_node_mass_ = settings_.empty_node_mass_fraction * total_mass / static_cast<double>(particles_.size());
  rebuild_material_groups();
  for (std::size_t m = 0; m < materials_.size(); ++m) materials_[m]->create_fields(particles_, members_[m]);
  find_obstacle_nodes();
  for (const Platen<Dim>& platen : settings_.platens) {
    if (!(platen.upper.array() > platen.lower.array()).all())
      throw std::invalid_argument("a platen's upper corner must lie above and right of its lower corner");
    // Not the ghosts beyond a fixed or roller wall: their mass is folded into
    // the nodes inside (counted twice in the plate's momentum otherwise), and
    // the walls set their motion by mirroring.
    auto& nodes = platen_nodes_.emplace_back();
    for (std::size_t i = 0; i < node_ij_.size(); ++i) {
      const Vec<Dim> x = grid_.node_position(node_ij_[i]);
      if (counted_[i] && (x.array() >= platen.lower.array()).all() && (x.array() <= platen.upper.array()).all())
        nodes.push_back(i);
    }
    if (nodes.empty()) throw std::invalid_argument("a platen's box holds no grid node");
  }
  platen_displacement_.assign(settings_.platens.size(), 0.0);
  platen_force_.assign(settings_.platens.size(), 0.0);
  for (const auto& m : materials_) wave_speed_squared_.push_back(std::pow(m->elasticity().p_wave_speed(), 2));
  p_modulus_ = p_moduli(materials_);
  pointwise_ = !settings_.smooth_dilatation &&
               std::all_of(materials_.begin(), materials_.end(), [](const auto& m) { return m->pointwise(); });
  create_transfer_fields();

  // One kernel per (shape, scheme), chosen here once.
  const auto with_transfer = [&]<class Shape, Scheme S>() -> void (Solver::*)(double) {
    return settings_.apic ? &Solver::template step_kernel<Shape, S, true>
                          : &Solver::template step_kernel<Shape, S, false>;
  };
  const auto pick = [&]<class Shape>() -> void (Solver::*)(double) {
    switch (settings_.scheme) {
      case Scheme::usf: return with_transfer.template operator()<Shape, Scheme::usf>();
      case Scheme::usl: return with_transfer.template operator()<Shape, Scheme::usl>();
      case Scheme::musl: return with_transfer.template operator()<Shape, Scheme::musl>();
    }
    return nullptr;
  };
  switch (settings_.shape) {
    case ShapeKind::linear: kernel_ = pick.template operator()<Linear>(); break;
    case ShapeKind::gimp: kernel_ = pick.template operator()<Gimp>(); break;
    case ShapeKind::bspline: kernel_ = pick.template operator()<Bspline>(); break;
  }
}

// The fields only some transfers use: the velocity gradients the split
// passes store (USF's fused pass keeps them in lanes) and APIC's B.
template <int Dim>
void Solver<Dim>::create_transfer_fields() {
  if (settings_.scheme != Scheme::usf || !pointwise_) particles_.need_velocity_gradients();
  if (settings_.apic) particles_.need_affine();
}

template <int Dim>
void Solver<Dim>::find_obstacle_nodes() {
  const double tolerance = 1e-9 * grid_.h;
  obstacle_nodes_.assign(settings_.obstacles.size(), {});
  for (std::size_t k = 0; k < settings_.obstacles.size(); ++k) {
    const Obstacle<Dim>& o = settings_.obstacles[k];
    if (!(o.upper.array() > o.lower.array()).all())
      throw std::invalid_argument("an obstacle's upper corner must lie above and right of its lower corner");
    for (std::size_t i = 0; i < node_ij_.size(); ++i) {
      const Vec<Dim> x = grid_.node_position(node_ij_[i]);
      if ((x.array() < o.lower.array() - tolerance).any() || (x.array() > o.upper.array() + tolerance).any())
        continue;
      // Distances to the faces (left, right, bottom, top, and in 3D back,
      // front); the nearest sets the normal, and an edge or a corner (two or
      // three nearest) takes their diagonal.
      std::array<double, 2 * Dim> distance;
      for (int d = 0; d < Dim; ++d) {
        distance[2 * d] = x[d] - o.lower[d];
        distance[2 * d + 1] = o.upper[d] - x[d];
      }
      const double nearest = *std::min_element(distance.begin(), distance.end());
      Vec<Dim> n = Vec<Dim>::Zero();
      for (int f = 0; f < 2 * Dim; ++f)
        if (distance[f] <= nearest + tolerance) n += (f % 2 == 0 ? 1.0 : -1.0) * Vec<Dim>::Unit(f / 2);
      if (n.squaredNorm() == 0) continue;  // the centre of a square obstacle: no material reaches it
      obstacle_nodes_[k].push_back({i, n.normalized()});
    }
  }
}

template <int Dim>
std::vector<std::vector<int>> material_members(const Particles<Dim>& particles, std::size_t materials) {
  std::vector<std::vector<int>> members(materials);
  for (std::size_t p = 0; p < particles.size(); ++p)
    members[static_cast<std::size_t>(particles.material[p])].push_back(static_cast<int>(p));
  return members;
}

template <int Dim>
void Solver<Dim>::rebuild_material_groups() { members_ = material_members(particles_, materials_.size()); }

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
// It measured faster under quadratic B-splines from the start
// (mpm_solid/benchmark/compare-c88bc1c-fused.csv) and under linear shapes,
// whose stencils cost little to compute again, once the materials' trial ran
// over lanes (compare-fused-linear-b53d828.csv; before, no faster:
// compare-lanes-fused-linear.csv). The chunk's velocity gradients stay in
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
          // in 3D (README.md, "The census's stress check in the update").
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
  // meets a fixed one too). Taken particle by
  // particle, over each stencil's nodes, it cost the step 4-5 % (README.md,
  // "The transfer's spread over the nodes"); it is also all the transfer
  // keeps, less sum_p m_p |dv_p|^2 / 2 (gather_motion).
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

// What particles scatter to ghost nodes beyond a fixed or roller wall belongs,
// by symmetry, to their mirror images inside: an image particle beyond the wall
// would give the inside node exactly what the real one gives the ghost node,
// reflected. Without this the nodes next to a wall miss their images' share and
// wide shape functions (B-splines reach 1.5 cells) lose an order of accuracy.
template <int Dim>
template <class F>
void Solver<Dim>::over_layer(int axis, int row, F&& f) const {
  std::array<int, Dim> ij{};
  ij[axis] = row;
  const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;  // the other axes (b: 3D only)
  const int layers = Dim == 2 ? 1 : grid_.nodes_along(b), along = grid_.nodes_along(a);
  const std::ptrdiff_t step = grid_.stride(a);
  constexpr int size = ActiveBlocks<Dim>::size;
  for (int l = 0; l < layers; ++l) {
    if constexpr (Dim == 3) ij[b] = l;
    for (int from = 0; from < along; from += size) {
      ij[a] = from;
      if (!active_.holds(ij)) continue;
      auto i = static_cast<std::ptrdiff_t>(grid_.index(ij));
      for (int k = from; k < std::min(from + size, along); ++k, i += step) f(static_cast<std::size_t>(i));
    }
  }
}

template <int Dim>
template <class F>
void Solver<Dim>::over_ghost_layer(int side, int depth, F&& f) const {
  const int g = Grid<Dim>::ghost, axis = side / 2;
  const int outward = side % 2 == 0 ? -1 : 1;  // wall normal, out of the domain
  const int wall_row = outward < 0 ? g : g + grid_.cells[axis];
  const std::ptrdiff_t inward = -2 * depth * outward * grid_.stride(axis);
  over_layer(axis, wall_row + depth * outward, [&](std::size_t node) { f(node, node + inward); });
}

namespace {
// A vector at a node reflected across a fixed or roller wall normal to
// `axis`: the normal component odd, the tangential ones odd at a fixed wall
// (no slip) and even at a roller.
template <int Dim>
Vec<Dim> reflected(const Vec<Dim>& v, int axis, Wall::Type type) {
  Vec<Dim> r;
  for (int d = 0; d < Dim; ++d) r[d] = d == axis || type == Wall::Type::fixed ? -v[d] : v[d];
  return r;
}
}  // namespace

template <int Dim>
template <class F>
void Solver<Dim>::fold_ghosts(std::vector<double>* mass, std::vector<Vec<Dim>>& vectors, F&& refresh) const {
  for (int side = 0; side < 2 * Dim; ++side) {
    const Wall::Type type = settings_.walls[side].type;
    if (!mirrors(type)) continue;
    for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth)
      over_ghost_layer(side, depth, [&](std::size_t from, std::size_t to) {
        if (mass) (*mass)[to] += (*mass)[from];
        vectors[to] += reflected<Dim>(vectors[from], side / 2, type);
        refresh(to);
      });
  }
}

// Walls sit on the physical domain's edges, on a row of nodes. The wall node
// takes the condition; ghost nodes beyond it mirror the node inside, with the
// constrained components reflected oddly, so the interpolated velocity meets the
// condition at the wall itself and not half a cell inside (which costs wide
// shape functions a whole order of accuracy). Obstacles act between the wall
// rows and the ghost rows: a ghost mirrors an obstacle's node as the obstacle
// leaves it (read before, its velocity changed where no energy book saw it).
// Only the active blocks, as this step's mapping collected them, are visited.
// Returns the work done by friction.
template <int Dim>
double Solver<Dim>::apply_walls(std::vector<Vec<Dim>>& velocity) const {
  double friction_work = 0;
  // The wall's condition at a node of its own motion: a wall row's, or a
  // ghost's beyond a friction wall, which keeps its own mass.
  const auto condition = [&](int side) {
    const Wall& wall = settings_.walls[side];
    Vec<Dim> normal = Vec<Dim>::Zero();
    normal[side / 2] = side % 2 == 0 ? -1 : 1;
    return [&wall, normal, &velocity, &friction_work, this](std::size_t i, std::size_t) {
      const double work = constrain(velocity[i], normal, wall, mass_[i]);
      // A ghost beyond a fixed or roller wall takes its mirror's motion
      // next, and its mass is folded into that node's: its work is not its own.
      if (counted_[i]) friction_work += work;
    };
  };
  // On the wall rows friction acts last: where a friction wall meets another
  // in 3D, the other's normal velocity is not slip along the friction wall
  // (in the plane the order makes no difference there).
  std::array<int, 2 * Dim> friction_last;
  std::iota(friction_last.begin(), friction_last.end(), 0);
  std::stable_partition(friction_last.begin(), friction_last.end(),
                        [&](int side) { return settings_.walls[side].type != Wall::Type::friction; });
  for (const int side : friction_last)
    if (settings_.walls[side].type != Wall::Type::open) over_ghost_layer(side, 0, condition(side));
  // Most of an obstacle's nodes lie deep in the rock, where no particle
  // reaches: outside the active runs, at rest, which every contact leaves
  // at rest. Both lists are in node order (find_obstacle_nodes goes along
  // the nodes), so a walk along the runs from the obstacle's first node
  // visits its active nodes in the order the full list would.
  const auto& runs = active_.runs();
  for (std::size_t k = 0; k < obstacle_nodes_.size(); ++k) {
    const Wall& contact = settings_.obstacles[k].contact;
    auto o = obstacle_nodes_[k].cbegin();
    const auto end = obstacle_nodes_[k].cend();
    if (o == end) continue;
    // The first run that ends beyond the obstacle's first node.
    auto run = std::upper_bound(runs.begin(), runs.end(), o->node, [](std::size_t i, const NodeRun& r) {
      return i < r.first + static_cast<std::size_t>(r.count);
    });
    for (; run != runs.end() && o != end; ++run) {
      o = std::lower_bound(o, end, run->first, [](const ObstacleNode& a, std::size_t i) { return a.node < i; });
      for (; o != end && o->node < run->first + static_cast<std::size_t>(run->count); ++o)
        if (const Vec<Dim>& v = velocity[o->node]; (v.array() != 0).any()) {
          const double work = constrain(velocity[o->node], o->normal, contact, mass_[o->node]);
          if (counted_[o->node]) friction_work += work;
        }
    }
  }
  // Then the ghost rows: those beyond friction walls first, then those beyond
  // fixed and roller walls, row by row outward, so that every mirror is final
  // when it is read. Thin domains mirror one wall's ghosts in the other's;
  // where a fixed wall meets a friction one, the corner's ghosts mirror ghosts
  // beyond the friction wall, into which fold_ghosts put their masses, and
  // with which the energy books take them to share |dv| (grid_update).
  // Constrained in turn with the mirrors, depth by depth, a corner ghost
  // could copy a friction wall's ghost before friction slowed it, and
  // friction then constrained the copy as a node of its own, whose normal
  // velocity a fixed wall's reflection had turned: either way not its
  // mirror's reflection. (A roller's reflection keeps the normal velocity
  // and the slip's length: friction commutes with it.)
  for (int side = 0; side < 2 * Dim; ++side)
    if (settings_.walls[side].type == Wall::Type::friction)
      for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth) over_ghost_layer(side, depth, condition(side));
  for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth)
    for (int side = 0; side < 2 * Dim; ++side)
      if (const Wall::Type type = settings_.walls[side].type; mirrors(type))
        over_ghost_layer(side, depth, [&](std::size_t ghost, std::size_t mirror) {
          velocity[ghost] = reflected<Dim>(velocity[mirror], side / 2, type);
        });
  return friction_work;
}

template <int Dim>
std::size_t Solver<Dim>::unmirrored_ghosts() const {
  std::size_t wrong = 0;
  for (int side = 0; side < 2 * Dim; ++side)
    if (const Wall::Type type = settings_.walls[side].type; mirrors(type))
      for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth)
        over_ghost_layer(side, depth, [&](std::size_t ghost, std::size_t mirror) {
          for (const auto* field : {&velocity_, &velocity_new_})
            if ((*field)[ghost] != reflected<Dim>((*field)[mirror], side / 2, type)) ++wrong;
        });
  return wrong;
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
  const Speeds speeds(p_modulus_, wave_speed_squared_.data(), p);
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
      if constexpr (Stresses) finite &= stress_finite<Dim>(stress, i);
      const double squared = sum_of_squares<Dim>([&](int e) { return v[Dim * i + e]; });
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
  with_draws(p, [&](auto drawn) __attribute__((always_inline)) {
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

// Move means this is the step's last transfer: the particles move right away
// and are counted (one pass less); otherwise their displacements wait.
template <int Dim>
template <class Shape, bool Apic, bool Move>
void Solver<Dim>::gather_motion(double dt) {
  auto& p = particles_;
  const int n = static_cast<int>(p.size());
  const double flip = settings_.flip_fraction;
  Census census;
  double lost = 0, work = 0;
  const bool loads = !p.external_force.empty();
  // The new velocities and positions of particles start .. start + lanes - 1
  // from what their stencils gathered (lane by lane: v_pic, dv and, under
  // APIC, affine), the energy books and, under Move, the census; the calling
  // thread's census and sums passed in, since a lambda made out here would
  // capture the shared ones rather than the thread's reduction copies. Over
  // SIMD lanes, the sums then taken particle by particle, in order.
  const auto finish = [&]<int Width>(int start, int lanes, const double(&v_pic)[Dim][Width],
                                     const double(&dv)[Dim][Width], const double* affine, Census& census,
                                     double& lost, double& work) __attribute__((always_inline)) {
    static_assert(Width <= chunk_lanes, "count() books at most chunk_lanes particles");
    alignas(64) double loss[Width], blend[Width], load_work[Width];
    double *x = p.x.data()->data(), *v = p.v.data()->data(), *displacement = Move ? nullptr : displacement_.data()->data();
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
    if constexpr (Move) count<false>(start, lanes, dt, census);  // USF: the update checked the stresses
  };
  if constexpr (Apic) {
#pragma omp parallel reduction(merge : census) reduction(+ : lost, work)
    {
      const Lattice<Dim> lattice(grid_);
      Stencil<Dim, Shape> s;
#pragma omp for schedule(static)
      for (int i = 0; i < n; ++i) {
        s.template compute<true>(lattice, p.x[i], p.half_width[i]);
        Vec<Dim> v_pic = Vec<Dim>::Zero(), dv = Vec<Dim>::Zero();
        Mat<Dim> b = Mat<Dim>::Zero();
        Vec<Dim> d = Vec<Dim>::Zero();  // diagonal of D = sum w (x_i - x_p)(x_i - x_p)^T
        double affine = 0;              // sum w (C (x_i - x_p)) . dv_i
        for (int k = 0; k < s.count; ++k) {
          const auto node = s.node[k];
          const Vec<Dim> change = velocity_new_[node] - velocity_[node];
          v_pic += s.weight[k] * velocity_new_[node];
          dv += s.weight[k] * change;
          b += s.weight[k] * velocity_new_[node] * s.offset[k].transpose();
          d += s.weight[k] * s.offset[k].cwiseProduct(s.offset[k]);
          // The affine share of the momentum this particle mapped, which
          // its own velocity does not carry, worked by the update.
          affine += s.weight[k] * (p.affine[i] * s.offset[k]).dot(change);
        }
        double pic[Dim][1], change[Dim][1];
        for (int e = 0; e < Dim; ++e) {
          pic[e][0] = v_pic[e];
          change[e][0] = dv[e];
        }
        finish(i, 1, pic, change, &affine, census, lost, work);
        // D is diagonal for tensor-product shapes that reproduce linear fields;
        // a particle on a linear-shape node has D = 0 along that axis (and B too).
        for (int c = 0; c < Dim; ++c)
          p.affine[i].col(c) = d[c] > 1e-12 * grid_.h * grid_.h ? Vec<Dim>(b.col(c) / d[c]) : Vec<Dim>::Zero();
      }
    }
  } else {
    using Lanes = StencilLanes<Dim, Shape>;
    const double *now = velocity_.data()->data(), *next = velocity_new_.data()->data();
    // Under Move the particles just moved map their mass and momentum for the
    // next step as well (README.md, The MPM solver): the chunk's positions
    // and velocities are still in registers and cache, and a pass over the
    // particles and a parallel region a step are saved.
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
        finish(start, lanes, v_pic, dv, nullptr, census, lost, work);
        if constexpr (Move) {
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
  if constexpr (Move) census_ = census;
  dissipated_.transfer += lost;
  dissipated_.external += work;
}

// Every transfer of a step uses the particles' positions at its start; they move
// at the end.
template <int Dim>
template <class Shape, Scheme S, bool Apic>
void Solver<Dim>::step_kernel(double dt) {
  if constexpr (S != Scheme::usf) displacement_.resize(particles_.size());
  double start = omp_get_wtime();
  const auto lap = [&](double& part) {
    const double now = omp_get_wtime();
    part += now - start;
    start = now;
  };
  scatter_mass_momentum<Shape, Apic>();
  lap(times_.map);
  grid_velocities();
  lap(times_.grid);
  long broken = 0;  // particles whose stress the update left non-finite (USF)
  if constexpr (S == Scheme::usf) {
    if (pointwise_) {
      broken = update_and_scatter<Shape>(dt);
    } else {
      gather_velocity_gradient<Shape>();
      if (settings_.smooth_dilatation) smooth_dilatation<Shape>();
      update_stresses(dt);
      broken = scatter_forces<Shape, true>();
    }
  } else {
    scatter_forces<Shape, false>();
  }
  lap(times_.stress);
  grid_update(dt);
  lap(times_.grid);
  gather_motion<Shape, Apic, S == Scheme::usf>(dt);
  if constexpr (S == Scheme::usf) census_.bad_stresses = broken;
  lap(times_.motion);
  if constexpr (S == Scheme::musl) {
    // Map the updated particle momentum back and take the velocity gradient of
    // that field: empty-ish nodes no longer carry the grid update's noise.
    scatter_mass_momentum<Shape, Apic>();
    lap(times_.map);
    grid_velocities();
    lap(times_.grid);
  }
  if constexpr (S != Scheme::usf) {
    if constexpr (S == Scheme::usl) velocity_.swap(velocity_new_);
    gather_velocity_gradient<Shape>();
    if (settings_.smooth_dilatation) smooth_dilatation<Shape>();
    update_stresses(dt);
    lap(times_.stress);
    census_ = move_particles(dt);
    lap(times_.motion);
  }
}

std::string describe(const StepTimes& t) {
  const double total = t.total();
  const auto share = [total](double part) { return total > 0 ? 100 * part / total : 0.0; };
  return fmt::format("particles to grid {:.0f} %, grid {:.0f} %, stresses and forces {:.0f} %, grid to particles "
                     "{:.0f} % of {:.3g} s",
                     share(t.map), share(t.grid), share(t.stress), share(t.motion), total);
}

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

template <int Dim>
StepInfo Solver<Dim>::step(double dt) {
  StepInfo info{dt};
  if (steps_ == 0) dissipated_.stored_start = stored_energy();  // the books open
  (this->*kernel_)(dt);
  dissipated_.external += census_.external_work;
  fastest_ = 0;  // unknown until the census is known to be the particles' (no error below)
  remove_escaped(census_, info);
  fastest_ = census_.fastest;
  time_ += dt;
  ++steps_;
  return info;
}

template <int Dim>
std::vector<Vec<Dim>>& Solver<Dim>::external_force() {
  particles_.need_loads();
  return particles_.external_force;
}

template <int Dim>
std::vector<double>& Solver<Dim>::pore_pressure() {
  particles_.need_pore_pressure();
  return particles_.pore_pressure;
}

template <int Dim>
void Solver<Dim>::shift_initial_stress(const std::vector<double>& per_particle) {
  if (steps_ > 0) throw std::logic_error("shift_initial_stress: the run has already started");
  if (per_particle.size() != particles_.size())
    throw std::invalid_argument(fmt::format("shift_initial_stress: {} values for {} particles", per_particle.size(),
                                            particles_.size()));
  auto& p = particles_;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double out_of_plane = 2 * materials_[p.material[i]]->elasticity().poisson_ratio * per_particle[i];
    p.stress[i].diagonal().array() += per_particle[i];
    if constexpr (Dim == 2) p.stress_zz[i] += out_of_plane;
    if (!p.damage.empty()) {
      p.effective_stress[i].diagonal().array() += per_particle[i];
      if constexpr (Dim == 2) p.effective_stress_zz[i] += out_of_plane;
    }
  }
}

template <int Dim>
std::optional<double> Solver<Dim>::settle(const Settling& stage, std::optional<double> fixed_step,
                                     const std::function<bool()>& pause) {
  if (settled_) throw std::logic_error("settle: the settling stage is over");
  const double scene_damping = settings_.local_damping;
  settings_.local_damping = stage.damping;
  while (!reached(time_, stage.duration, stage.duration)) {
    step(std::min(fixed_step ? *fixed_step : stable_time_step(), stage.duration - time_));
    settling_kinetic_ = kinetic_energy();
    settling_peak_ = std::max(settling_peak_, settling_kinetic_);
    if (pause && pause()) {
      settings_.local_damping = scene_damping;
      return std::nullopt;
    }
  }
  settings_.local_damping = scene_damping;
  remove_supports();
  for (auto& v : particles_.v) v.setZero();
  for (auto& b : particles_.affine) b.setZero();
  discard_mapping();
  fastest_ = 0;
  time_ = 0;
  steps_ = 0;
  times_ = {};
  dissipated_ = {};
  std::fill(platen_displacement_.begin(), platen_displacement_.end(), 0.0);
  return settling_peak_ > 0 ? settling_kinetic_ / settling_peak_ : 0.0;
}

template <int Dim>
void Solver<Dim>::save(checkpoint::Out out) const {
  particles_.save(out.group("particles"));
  out.number("time", time_);
  out.count("steps", steps_);
  out.count("removed", static_cast<std::int64_t>(removed_));
  dissipated_.save(out, "dissipated");
  out.numbers("platen_displacement", platen_displacement_);
  out.flag("settled", settled_);
  out.numbers("settling_kinetic", std::vector<double>{settling_peak_, settling_kinetic_});
}

template <int Dim>
void Solver<Dim>::load(const checkpoint::In& in) {
  const auto group = in.group("particles");
  Particles<Dim> p;
  p.load(group);
  for (const auto m : p.material)
    if (m < 0 || static_cast<std::size_t>(m) >= materials_.size())
      group.fail("material", fmt::format("material {} of a scene with {}", m, materials_.size()));
  particles_ = std::move(p);
  create_transfer_fields();
  discard_mapping();
  rebuild_material_groups();
  fastest_ = 0;
  time_ = in.number("time");
  steps_ = in.count("steps");
  removed_ = static_cast<std::size_t>(in.count("removed"));
  dissipated_ = Energies::load(in, "dissipated");
  platen_displacement_ = in.numbers("platen_displacement", settings_.platens.size());
  const auto settling = in.numbers("settling_kinetic", 2);
  settling_peak_ = settling[0];
  settling_kinetic_ = settling[1];
  if (in.flag("settled") && !settled_) remove_supports();
}

template <int Dim>
void Solver<Dim>::remove_supports() {
  std::erase_if(settings_.obstacles, [](const Obstacle<Dim>& o) { return o.support; });
  find_obstacle_nodes();
  settled_ = true;
}

void Energies::save(checkpoint::Out out, const std::string& name) const {
  out.numbers(name, std::vector<double>{kinetic, strain, gravity, plastic, damage, damping, walls, transfer,
                                        integration, left, external, grid_work, left_kinetic, stored_start});
}

Energies Energies::load(const checkpoint::In& in, const std::string& name) {
  const auto v = in.numbers(name, 14);
  return {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13]};
}

template <int Dim>
void Solver<Dim>::restore_state(const State& s) {
  dissipated_ = s.dissipated;
  time_ = s.time;
  steps_ = s.steps;
  removed_ = s.removed;
  platen_displacement_ = s.platen_displacement;
  const bool same_particles = s.particles.size() == particles_.size();
  particles_ = s.particles;
  discard_mapping();
  fastest_ = 0;
  if (!same_particles) rebuild_material_groups();
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
typename Solver<Dim>::Memory Solver<Dim>::memory() const {
  const auto bytes = [](const auto& v) { return v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type); };
  Memory m{0, 0};
  particles_.for_each_field([&](const auto&, const auto& values) { m.particles += bytes(values); });
  m.particles += bytes(displacement_);
  for (const auto& group : members_) m.particles += bytes(group);
  for (const auto* v : {&momentum_, &force_, &velocity_, &velocity_new_}) m.grid += bytes(*v);
  m.grid += bytes(mass_) + bytes(node_ij_) + bytes(counted_) + active_.bytes();
  for (const auto& t : thread_mass_) m.grid += bytes(t);
  for (const auto& t : thread_vector_) m.grid += bytes(t);
  return m;
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

template class Solver<2>;
template class Solver<3>;
template std::vector<std::vector<int>> material_members(const Particles<2>&, std::size_t);
template std::vector<std::vector<int>> material_members(const Particles<3>&, std::size_t);
template double stable_time_step(const std::vector<std::unique_ptr<Material<2>>>&, const Particles<2>&, double,
                                 double);
template double stable_time_step(const std::vector<std::unique_ptr<Material<3>>>&, const Particles<3>&, double,
                                 double);

}  // namespace outburst::mpm
