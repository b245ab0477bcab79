// The solver's state as a checkpoint holds it (a run continued by
// --restart), as a coupled run saves and restores it within a window, and
// the memory it takes.
#include <vector>

#include <fmt/format.h>

#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

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
  if (steps_ < 0) in.fail("steps", fmt::format("{} steps, which no run holds: the checkpoint is damaged", steps_));
  const auto removed = in.count("removed");
  if (removed < 0) in.fail("removed", fmt::format("{} particles removed, which no run holds: the checkpoint is damaged", removed));
  removed_ = static_cast<std::size_t>(removed);
  dissipated_ = Energies::load(in, "dissipated");
  platen_displacement_ = in.numbers("platen_displacement", settings_.platens.size());
  const auto settling = in.numbers("settling_kinetic", 2);
  settling_peak_ = settling[0];
  settling_kinetic_ = settling[1];
  if (in.flag("settled") && !settled_) remove_supports();
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

#define INSTANTIATE(Dim)                                                       \
  template void Solver<Dim>::save(checkpoint::Out) const;                      \
  template void Solver<Dim>::load(const checkpoint::In&);                      \
  template void Solver<Dim>::restore_state(const State&);                      \
  template typename Solver<Dim>::Memory Solver<Dim>::memory() const;
INSTANTIATE(2)
INSTANTIATE(3)
#undef INSTANTIATE

}  // namespace outburst::mpm
