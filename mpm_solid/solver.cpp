// The solver's construction, the kernel it picks, and the step that runs
// the passes (passes/) in the order its scheme gives them; the settling
// stage before t = 0.
#include "mpm_solid/solver.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "common/interval.hpp"
#include "mpm_solid/passes/census.hpp"
#include "mpm_solid/shape.hpp"

namespace outburst::mpm {

using passes::p_moduli;

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
  create_grid_fields();
  double total_mass = 0;
  for (double m : particles_.mass) total_mass += m;
  empty_node_mass_ = settings_.empty_node_mass_fraction * total_mass / static_cast<double>(particles_.size());
  rebuild_material_groups();
  for (std::size_t m = 0; m < materials_.size(); ++m) materials_[m]->create_fields(particles_, members_[m]);
  find_obstacle_nodes();
  find_platen_nodes();
  platen_displacement_.assign(settings_.platens.size(), 0.0);
  platen_force_.assign(settings_.platens.size(), 0.0);
  for (const auto& m : materials_) wave_speed_squared_.push_back(std::pow(m->elasticity().p_wave_speed(), 2));
  p_modulus_ = p_moduli(materials_);
  pointwise_ = !settings_.smooth_dilatation &&
               std::all_of(materials_.begin(), materials_.end(), [](const auto& m) { return m->pointwise(); });
  create_transfer_fields();
  kernel_ = pick_kernel();
}


// The nodal arrays (and the threads' copies of the scattered ones), each
// node's grid coordinates, and which nodes' mass counts once.
template <int Dim>
void Solver<Dim>::create_grid_fields() {
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
}

template <int Dim>
void Solver<Dim>::find_platen_nodes() {
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
}

// One kernel per (shape, scheme, transfer), chosen once per solver.
template <int Dim>
auto Solver<Dim>::pick_kernel() const -> Kernel {
  const auto with_transfer = [&]<class Shape, Scheme S>() -> Kernel {
    return settings_.apic ? &Solver::template step_kernel<Shape, S, true>
                          : &Solver::template step_kernel<Shape, S, false>;
  };
  const auto pick = [&]<class Shape>() -> Kernel {
    switch (settings_.scheme) {
      case Scheme::usf: return with_transfer.template operator()<Shape, Scheme::usf>();
      case Scheme::usl: return with_transfer.template operator()<Shape, Scheme::usl>();
      case Scheme::musl: return with_transfer.template operator()<Shape, Scheme::musl>();
    }
    return nullptr;
  };
  switch (settings_.shape) {
    case ShapeKind::linear: return pick.template operator()<Linear>();
    case ShapeKind::gimp: return pick.template operator()<Gimp>();
    case ShapeKind::bspline: return pick.template operator()<Bspline>();
  }
  return nullptr;
}

// The fields only some transfers use: the velocity gradients the split
// passes store (USF's fused pass keeps them in lanes) and APIC's B.
template <int Dim>
void Solver<Dim>::create_transfer_fields() {
  if (settings_.scheme != Scheme::usf || !pointwise_) particles_.need_velocity_gradients();
  if (settings_.apic) particles_.need_affine();
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
void Solver<Dim>::remove_supports() {
  std::erase_if(settings_.obstacles, [](const Obstacle<Dim>& o) { return o.support; });
  find_obstacle_nodes();
  settled_ = true;
}

template class Solver<2>;
template class Solver<3>;
template std::vector<std::vector<int>> material_members(const Particles<2>&, std::size_t);
template std::vector<std::vector<int>> material_members(const Particles<3>&, std::size_t);

}  // namespace outburst::mpm
