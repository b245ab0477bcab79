// mpm-solid: the MPM solver for coal and rock on its own (dry scenes).
#include <chrono>

#include <spdlog/spdlog.h>

#include "common/output_folder.hpp"
#include "common/program.hpp"
#include "common/progress.hpp"
#include "common/stop.hpp"
#include "mpm_solid/output.hpp"
#include "mpm_solid/scene_reader.hpp"

using namespace outburst;

namespace {

int run(const RunOptions& options, scene::Document& doc) {
  auto root = doc.root();
  const SceneHeader header = read_scene_header(root);
  require_solvers(root, header, {"mpm"}, "mpm-solid");
  const auto mpm_table = root.table("mpm", "the material point solver", true);
  mpm::Setup setup = mpm::read_setup(*mpm_table);
  doc.reject_unused();
  mpm::check_run_length(*mpm_table, setup, header.end_time);

  // The particles exist now: a fixed step can be checked against their CFL limit
  // (before --check returns, so it catches an unstable step too).
  mpm::Solver solver(setup.grid, std::move(setup.materials), std::move(setup.particles), setup.settings);
  const double stable = solver.stable_time_step();
  if (setup.fixed_time_step && *setup.fixed_time_step > stable / setup.settings.courant)
    mpm_table->fail("time_step", fmt::format("{:.3g} s exceeds the stability limit h / (c + |v|) = {:.3g} s of this "
                                             "scene; use a smaller step or drop the key to let the CFL condition "
                                             "choose",
                                             *setup.fixed_time_step, stable / setup.settings.courant));
  if (!finish_reading(options, doc)) return 0;
  const OutputFolder folder(options.output_directory(), "mpm-solid", options.overwrite);
  spdlog::info("{}: {} particles, {} x {} cells of {:g} m, stable step {:.3g} s", header.title,
               solver.particles().size(), setup.grid.cells[0], setup.grid.cells[1], setup.grid.h, stable);

  const auto wall_start = std::chrono::steady_clock::now();
  if (setup.settling.duration > 0) {
    const double left = solver.settle(setup.settling, setup.fixed_time_step);
    spdlog::info("settled for {:.3g} s: kinetic energy down to {:.2e} of its peak; supports removed",
                 setup.settling.duration, left);
  }
  mpm::Output out(folder.path(), run_info("mpm-solid", doc, "SI: m, s, kg, Pa; 2D plane strain, "
                                                                         "per metre of depth"),
                  setup.tracers);
  out.snapshot(solver);
  double last_snapshot_time = 0;
  Progress progress("mpm", 0.0, header.end_time, options.show_progress());
  double next_output = header.output_interval;
  RestWatch rest(header.rest_fraction);
  bool at_rest = false;
  while (solver.time() < header.end_time * (1 - 1e-12)) {
    const double target = std::min(next_output, header.end_time);
    const double dt = std::min(setup.fixed_time_step ? *setup.fixed_time_step : solver.stable_time_step(),
                               target - solver.time());
    try {
      const auto info = solver.step(dt);
      out.history(solver, info);
      if (info.removed > 0) spdlog::debug("{} particles left the grid at t = {:.6g} s", info.removed, solver.time());
    } catch (const mpm::SimulationError&) {
      progress.finish();
      spdlog::error("the last good state is the last snapshot written, at t = {:.6g} s, in {}",
                    last_snapshot_time, std::filesystem::absolute(out.series().index_path()).string());
      throw;
    }
    progress.update(solver.steps(), solver.time(), dt, fmt::format("particles {}", solver.particles().size()));
    const bool output_due = solver.time() >= target * (1 - 1e-12);
    at_rest = rest.active() && rest.at_rest(solver.kinetic_energy());
    const bool stop = stop_requested();  // read once: a signal may come in between
    if (output_due || at_rest || stop) {
      out.snapshot(solver);
      last_snapshot_time = solver.time();
      if (output_due) next_output += header.output_interval;
    }
    if (stop) {
      progress.finish();
      return report_stop(solver.time(), out.series().index_path());
    }
    if (at_rest) break;
  }
  progress.finish();
  out.finish();
  if (at_rest)
    spdlog::info("at rest at t = {:.4g} s: kinetic energy {:.3g} J/m, below {:g} of its peak {:.3g} J/m",
                 solver.time(), solver.kinetic_energy(), *header.rest_fraction, rest.peak());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  spdlog::info("done: {} steps, {:.3g} s wall, {:.3g} particle-steps/s, {} particles left the grid",
               solver.steps(), wall, static_cast<double>(solver.steps()) * static_cast<double>(solver.particles().size()) / wall,
               solver.removed_particles());
  spdlog::info("results: {}", std::filesystem::absolute(out.series().index_path()).string());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return run_program("mpm-solid", "Coal and rock: explicit material point method (2D plane strain)", argc, argv,
                     run);
}
