// mpm-solid: the MPM solver for coal and rock on its own (dry scenes).
#include <chrono>
#include <optional>

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "common/output_folder.hpp"
#include "common/program.hpp"
#include "common/progress.hpp"
#include "common/run_loop.hpp"
#include "common/stop.hpp"
#include "mpm_solid/output.hpp"
#include "mpm_solid/scene_reader.hpp"

using namespace outburst;

namespace {

// The run loop's driver (common/run_loop.hpp): explicit steps of the stable
// size (or the scene's fixed one).
template <int Dim>
struct Driver {
  mpm::Solver<Dim>& solver;
  mpm::Output<Dim>& out;
  std::optional<double> fixed_step;
  double last_snapshot_time = 0;

  double time() const { return solver.time(); }
  LoopStep advance(double target) {
    const double dt = std::min(fixed_step ? *fixed_step : solver.stable_time_step(), target - solver.time());
    const auto info = solver.step(dt);
    out.history(solver, info);
    if (info.removed > 0) spdlog::debug("{} particles left the grid at t = {:.6g} s", info.removed, solver.time());
    return {solver.steps(), dt, fmt::format("particles {}", solver.particles().size())};
  }
  double kinetic_energy() const { return solver.kinetic_energy(); }
  void snapshot() {
    out.snapshot(solver);
    last_snapshot_time = solver.time();
  }
  // Any exception, not only a blow-up: what was written stays good.
  void failed() const {
    spdlog::error("the last good state is the last snapshot written, at t = {:.6g} s, in {}", last_snapshot_time,
                  std::filesystem::absolute(out.series().index_path()).string());
  }
  void save(checkpoint::Out root, checkpoint::Out run) const {
    solver.save(root.group("mpm"));
    out.save(root.group("output"));
    run.number("last_snapshot_time", last_snapshot_time);
  }
  void load(const checkpoint::In& root, const checkpoint::In& run) {
    solver.load(root.group("mpm"));
    out.load(root.group("output"));
    last_snapshot_time = run.number("last_snapshot_time");
  }
};

// The settling stage before t = 0, from a checkpoint of it if one is given;
// false if a signal stopped it (its checkpoint written).
template <int Dim>
bool settle(mpm::Solver<Dim>& solver, const mpm::Setup<Dim>& setup, const OutputFolder& folder, const output::RunInfo& info,
            const SceneHeader& header, const std::optional<checkpoint::Reader>& restart) {
  SettlingCheckpoints checkpoints(folder.path(), info, header.checkpoint_interval, solver, "mpm");
  if (restart) {
    checkpoints.resume(*restart);
    spdlog::info("restarted from {} while settling, at {:.9g} s of the {:.9g} s stage", restart->path().string(),
                 solver.time(), setup.settling.duration);
  }
  const auto left =
      solver.settle(setup.settling, setup.fixed_time_step, [&] { return checkpoints.pause(solver.time()); });
  if (!left) return false;
  spdlog::info("settled for {:.3g} s: kinetic energy down to {:.2e} of its peak; supports removed",
               setup.settling.duration, *left);
  return true;
}

// What the run's steps cost, and where its results are.
template <int Dim>
void report_run(const mpm::Solver<Dim>& solver, const mpm::Output<Dim>& out, double wall) {
  spdlog::info("steps' wall time: {}", describe(solver.step_times()));
  spdlog::info("done: {} steps, {:.3g} s wall, {:.3g} particle-steps/s, {} particles left the grid",
               solver.steps(), wall, static_cast<double>(solver.steps()) * static_cast<double>(solver.particles().size()) / wall,
               solver.removed_particles());
  spdlog::info("results: {}", std::filesystem::absolute(out.series().index_path()).string());
}

// The run of a scene of dimension Dim (2: plane strain, 3: 3D).
template <int Dim>
int run_in(const RunOptions& options, scene::Document& doc, const SceneHeader& header, const scene::Table& mpm_table) {
  mpm::Setup<Dim> setup = mpm::read_setup<Dim>(mpm_table);
  doc.reject_unused();
  mpm::check_run_length(mpm_table, setup, header.end_time);

  mpm::check_time_step(mpm_table, setup);
  mpm::Solver<Dim> solver(setup.grid, std::move(setup.materials), std::move(setup.particles), setup.settings);
  const double stable = solver.stable_time_step();
  if (!finish_reading(options, doc)) return 0;
  const OutputFolder folder(options.output_directory(), "mpm-solid", options.earlier_files());
  spdlog::info("{}: {} particles, {} cells of {:g} m, stable step {:.3g} s", header.title,
               solver.particles().size(), fmt::join(setup.grid.cells, " x "), setup.grid.h, stable);
  const auto info =
      run_info("mpm-solid", doc, Dim == 2 ? "SI: m, s, kg, Pa; 2D plane strain, per metre of depth" : "SI: m, s, kg, Pa; 3D");
  std::optional<checkpoint::Reader> restart;
  if (options.restart) restart.emplace(folder.path(), info);
  // A checkpoint of the settling stage continues it; the run then starts as
  // a fresh one would, outputs and all.
  const bool resume_run = restart && restart->stage() == checkpoint::Stage::run;

  const auto wall_start = std::chrono::steady_clock::now();
  if (setup.settling.duration > 0 && !resume_run && !settle(solver, setup, folder, info, header, restart))
    return report_settling_stop(solver.time(), setup.settling.duration, folder.path() / checkpoint::file_name);
  mpm::Output<Dim> out(folder.path(), info, setup.tracers, resume_run);
  Driver<Dim> driver{solver, out, setup.fixed_time_step};
  RunLoop loop(header, folder.path(), info);
  if (resume_run) {
    loop.resume(*restart, driver);
    spdlog::info("restarted from {} at t = {:.9g} s, step {}", restart->path().string(), solver.time(),
                 solver.steps());
  } else {
    driver.snapshot();
  }
  const RunEnd end = loop.run(driver, "mpm", options.show_progress());
  if (end == RunEnd::stopped) return report_stop(solver.time(), out.series().index_path());
  out.finish();
  if (end == RunEnd::at_rest)
    spdlog::info("at rest at t = {0:.4g} s: kinetic energy {1:.3g} {2}, below {3:g} of its peak {4:.3g} {2}",
                 solver.time(), solver.kinetic_energy(), Dim == 2 ? "J/m" : "J", *header.rest_fraction,
                 loop.peak_kinetic_energy());
  report_run(solver, out, std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count());
  return 0;
}

int run(const RunOptions& options, scene::Document& doc) {
  auto root = doc.root();
  const SceneHeader header = read_scene_header(root);
  require_solvers(root, header, {"mpm"}, "mpm-solid");
  const auto mpm_table = root.table("mpm", "the material point solver", true);
  return mpm::scene_dimension(*mpm_table) == 2 ? run_in<2>(options, doc, header, *mpm_table)
                                               : run_in<3>(options, doc, header, *mpm_table);
}

}  // namespace

int main(int argc, char** argv) {
  return run_program("mpm-solid", "Coal and rock: explicit material point method (2D plane strain or 3D)", argc,
                     argv, run);
}
