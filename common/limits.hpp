#pragma once
// Guards against runs that cannot finish: a run whose estimated step count,
// window count or snapshot count is beyond any real run's, or whose sizes
// exceed the machine's memory, is refused before it starts (and by --check),
// naming the key to change and the estimate.

#include <string>
#include <string_view>

#include "common/scene.hpp"

namespace outburst::limits {

// Most time steps of either solver, or coupling windows, a run may take: 1e8
// MPM steps of the outburst case (6480 particles) would take about 36 hours
// on this project's 2-core machine.
inline constexpr double max_steps = 1e8;
// Most particle-steps an MPM run may take: the same 36 hours or so (the step
// bound alone lets a run of few steps on millions of particles through).
inline constexpr double max_particle_steps = 1e8 * 6480;
// Most snapshots a run may write (one file each).
inline constexpr double max_snapshots = 1e5;

// Physical memory of this machine [bytes].
double physical_memory();

// Refuses at `key` when `count` (an estimate of `what`, such as "MPM steps")
// exceeds `bound`; `how` says how the estimate was made and what to change.
void refuse_count(const scene::Table& table, std::string_view key, double count, double bound,
                  std::string_view what, const std::string& how);

// Refuses at `key` when `bytes` (an estimate of what `what` needs, counted
// low) exceed the physical memory.
void refuse_memory(const scene::Table& table, std::string_view key, double bytes, const std::string& what);

}  // namespace outburst::limits
