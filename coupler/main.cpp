// outburst: the coupled gas-solid simulation. The seepage solver and the MPM
// solver run as partners of a coupling (coupler/coupling.hpp) window by window.
#include <chrono>
#include <fstream>
#include <optional>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "common/atomic_file.hpp"
#include "common/limits.hpp"
#include "common/manifest.hpp"
#include "common/output_folder.hpp"
#include "common/program.hpp"
#include "common/progress.hpp"
#include "common/run_loop.hpp"
#include "common/stop.hpp"
#include "coupler/model.hpp"
#include "mpm_solid/output.hpp"
#include "seepage_fe/output.hpp"

using namespace outburst;

namespace {

// Per window: what the coupling cost and how it converged, flushed line by line.
// A restarted run (resume) writes no header and appends once load() has cut
// the log back to the checkpoint.
class WindowLog {
 public:
  WindowLog(const std::filesystem::path& file, const std::vector<coupling::Convergence>& fields, bool resume)
      : path_(file), fields_(fields.size()) {
    if (resume) return;
    output::record_written(file);
    out_.open(file);
    out_ << "window,time,size,iterations,converged,seepage_s,solid_s,coupler_s,open_cells,gas_released,"
            "kinetic_energy,particles";
    for (const auto& f : fields) out_ << ",residual_" << f.field;
    out_ << '\n';
  }
  void write(std::size_t index, const coupling::WindowRecord& r, int open_cells, double released, double kinetic,
             std::size_t particles) {
    out_ << fmt::format("{},{:.9g},{:.6g},{},{},{:.4g},{:.4g},{:.4g},{},{:.9g},{:.9g},{}", index, r.start + r.size,
                        r.size, r.iterations, r.converged ? 1 : 0, r.first_seconds, r.second_seconds,
                        r.coupler_seconds, open_cells, released, kinetic, particles);
    // One-pass schemes measure no residual: their columns stay empty.
    for (std::size_t k = 0; k < fields_; ++k)
      out_ << (k < r.residuals.size() ? fmt::format(",{:.3e}", r.residuals[k]) : std::string(","));
    out_ << '\n';
    out_.flush();
    if (!out_) throw std::runtime_error("cannot write coupling.csv: the disk may be full");
  }
  void save(checkpoint::Out out) const { checkpoint::save_length(out, "bytes", path_); }
  void load(const checkpoint::In& in) { checkpoint::cut_back(in, "bytes", path_, out_); }

 private:
  std::filesystem::path path_;
  std::ofstream out_;
  std::size_t fields_;
};

// Refuses a run of more windows or MPM steps than any run may take.
template <int Dim>
void check_run_length(scene::Table root, const coupling::CoupledSetup<Dim>& setup) {
  const double end_time = setup.header.end_time, window = setup.coupling.window;
  limits::refuse_count(*root.table("coupling", "", true), "window", end_time / window, limits::max_steps,
                       "coupling windows",
                       fmt::format("end_time {:.3g} s / window {:.3g} s; lengthen the window", end_time, window));
  mpm::check_run_length(*root.table("mpm", "", true), setup.solid, end_time);
}

// Where a coupled run's wall time goes from the start of its run loop (after
// settling, after a restart), by the solvers' and the coupling's own clocks:
// MPM steps; the gas force read at the particles before each; the rest of
// the solid's windows (step sizes, escaped particles); the seepage's
// windows; the exchanges and acceleration (the solid's cell averages, made
// when the coupling reads them, among them); and what is left: output, the
// participants' saving and restoring, logs.
template <int Dim>
struct RunTimes {
  mpm::StepTimes phases;
  double gas_force, solid = 0, seepage = 0, coupler = 0;
  explicit RunTimes(const coupling::CoupledModel<Dim>& model)
      : phases(model.solid().step_times()), gas_force(model.solid_side().gas_force_seconds()) {
    for (const auto& r : model.coupling().records()) {
      solid += r.second_seconds;
      seepage += r.first_seconds;
      coupler += r.coupler_seconds;
    }
  }
  // What was spent after `start`, of `wall` seconds, by part.
  struct Spent {
    mpm::StepTimes steps;
    double gas_force, bookkeeping, seepage, coupler, rest, wall;

    // "MPM steps 76 %, ... of 20.9 s".
    std::string shares() const {
      const auto share = [this](double part) { return wall > 0 ? 100 * part / wall : 0.0; };
      return fmt::format("MPM steps {:.0f} %, gas force at the particles {:.0f} %, the solid's step bookkeeping "
                         "{:.0f} %, seepage {:.0f} %, exchanges and acceleration {:.0f} %, output and the rest "
                         "{:.0f} % of {:.3g} s",
                         share(steps.total()), share(gas_force), share(bookkeeping), share(seepage), share(coupler),
                         share(rest), wall);
    }
    // The same parts as a CSV (part, seconds), the MPM steps by phase: what
    // scripts/outburst-benchmark.py reads to show what limits a run.
    std::string table() const {
      std::string out = "part,seconds\n";
      const auto row = [&out](const char* part, double seconds) { out += fmt::format("{},{:.6g}\n", part, seconds); };
      row("mpm_particles_to_grid", steps.map);
      row("mpm_grid", steps.grid);
      row("mpm_stresses_and_forces", steps.stress);
      row("mpm_grid_to_particles", steps.motion);
      row("gas_force", gas_force);
      row("solid_bookkeeping", bookkeeping);
      row("seepage", seepage);
      row("exchanges_and_acceleration", coupler);
      row("output_and_rest", rest);
      row("wall", wall);
      return out;
    }
  };
  Spent since(const RunTimes& start, double wall) const {
    const mpm::StepTimes steps{phases.map - start.phases.map, phases.grid - start.phases.grid,
                               phases.stress - start.phases.stress, phases.motion - start.phases.motion};
    const double gas = gas_force - start.gas_force, solid_all = solid - start.solid;
    const double seep = seepage - start.seepage, coupling = coupler - start.coupler;
    return {steps, gas, solid_all - steps.total() - gas, seep, coupling, wall - solid_all - seep - coupling, wall};
  }
};

// The run of a coupled scene of dimension Dim (2: plane strain, 3: 3D).
template <int Dim>
int run_in(const RunOptions& options, scene::Document& doc) {
  coupling::CoupledSetup<Dim> setup = coupling::read_coupled_setup<Dim>(doc.root());
  doc.reject_unused();
  check_run_length(doc.root(), setup);
  if (!finish_reading(options, doc)) return 0;
  const OutputFolder folder(options.output_directory(), "outburst", options.earlier_files());
  const auto& directory = folder.path();
  const auto info = run_info("outburst", doc,
                             fmt::format("SI: m, s, kg, Pa; {}; MPM stresses are effective (total = effective - alpha "
                                         "p I)",
                                         Dim == 2 ? "2D plane strain, per metre of depth" : "3D"));
  const char* energy_unit = Dim == 2 ? "J/m" : "J";
  std::optional<checkpoint::Reader> restart;
  if (options.restart) restart.emplace(directory, info);
  // A checkpoint of the settling stage continues it; the run then starts as
  // a fresh one would, outputs and all.
  const bool resume_run = restart && restart->stage() == checkpoint::Stage::run;
  const SceneHeader header = setup.header;
  const auto tracers = setup.solid.tracers;
  const mpm::Settling settling = setup.solid.settling;
  coupling::CoupledModel<Dim> model(std::move(setup), /*settle_later=*/true);
  if (settling.duration > 0 && !resume_run) {
    SettlingCheckpoints checkpoints(directory, info, header.checkpoint_interval, model, "model");
    if (restart) {
      checkpoints.resume(*restart);
      spdlog::info("restarted from {} while settling, at {:.9g} s of the {:.9g} s stage", restart->path().string(),
                   model.solid().time(), settling.duration);
    }
    if (!model.settle([&] { return checkpoints.pause(model.solid().time()); }))
      return report_settling_stop(model.solid().time(), settling.duration, directory / checkpoint::file_name);
    spdlog::info("settled for {:.3g} s: kinetic energy down to {:.2e} of its peak; supports removed",
                 settling.duration, *model.settled());
  }
  auto& seepage_solver = model.seepage();
  auto& solid = model.solid();
  const auto& cs = model.coupling_setup();
  spdlog::info("{}: {} seepage cells, {} particles, window {:.3g} s", header.title, model.mapping().mesh().num_cells(),
               solid.particles().size(), cs.window);

  seepage::Output seepage_out(directory, info, seepage_solver, resume_run);
  mpm::Output<Dim> solid_out(directory, info, tracers, resume_run);
  WindowLog log(directory / "coupling.csv", cs.scheme.to_first, resume_run);
  seepage_out.series().list_with_others();
  solid_out.series().list_with_others();
  const auto wall_start = std::chrono::steady_clock::now();
  const auto& coupler = model.coupling();
  // One coupling window at a time, cut short at an output time.
  struct Driver {
    coupling::CoupledModel<Dim>& model;
    seepage::Output& seepage_out;
    mpm::Output<Dim>& solid_out;
    WindowLog& log;
    long iterations = 0;
    double kinetic = 0;  // after the last window [J; J/m in 2D]

    double time() const { return model.coupling().time(); }
    LoopStep advance(double target) {
      const auto& r = model.advance(target);
      iterations += r.iterations;
      auto& solid = model.solid();
      auto& seepage = model.seepage();
      solid_out.history(solid, model.solid_side().last_window());
      seepage_out.history(seepage, r.size, model.seepage_side().last_report());
      kinetic = solid.kinetic_energy();
      const auto windows = model.coupling().records().size();
      log.write(windows, r, model.seepage_side().open_cells(), seepage.balance().total_outflow(), kinetic,
                solid.particles().size());
      return {static_cast<long>(windows), r.size, fmt::format("sub-iterations {}", r.iterations)};
    }
    double kinetic_energy() const { return kinetic; }
    void snapshot() {
      seepage_out.snapshot(model.seepage());
      solid_out.snapshot(model.solid());
      output::publish({&seepage_out.series(), &solid_out.series()});
    }
    void save(checkpoint::Out root, checkpoint::Out run) const {
      model.save(root.group("model"));
      seepage_out.save(root.group("seepage_output"));
      solid_out.save(root.group("mpm_output"));
      log.save(root.group("coupling_log"));
      run.count("iterations", iterations);
    }
    void load(const checkpoint::In& root, const checkpoint::In& run) {
      model.load(root.group("model"));
      seepage_out.load(root.group("seepage_output"));
      solid_out.load(root.group("mpm_output"));
      log.load(root.group("coupling_log"));
      iterations = run.count("iterations");
    }
  } driver{model, seepage_out, solid_out, log};
  RunLoop loop(header, directory, info);
  if (resume_run) {
    loop.resume(*restart, driver);
    spdlog::info("restarted from {} at t = {:.9g} s, window {}", restart->path().string(), coupler.time(),
                 coupler.records().size());
  } else {
    driver.snapshot();
  }
  const RunTimes times_from(model);
  const RunEnd end = loop.run(driver, "outburst", options.show_progress());
  if (end == RunEnd::stopped) return report_stop(coupler.time(), directory);
  solid_out.finish();
  if (end == RunEnd::at_rest)
    spdlog::info("the coal is at rest at t = {0:.4g} s: kinetic energy {1:.3g} {2}, below {3:g} of its peak {4:.3g} {2}",
                 coupler.time(), solid.kinetic_energy(), energy_unit, *header.rest_fraction,
                 loop.peak_kinetic_energy());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  spdlog::info("MPM steps' wall time: {}", mpm::describe(solid.step_times()));
  const auto spent = RunTimes(model).since(times_from, wall);
  spdlog::info("the run's wall time: {}", spent.shares());
  output::write_file_atomically(directory / "wall_times.csv", spent.table());
  spdlog::info("done: {} windows, {} sub-iterations, {} MPM steps, {:.3g} s wall; gas released {:.4g} {}, "
               "{} particles left the grid",
               coupler.records().size(), driver.iterations, solid.steps(), wall, seepage_solver.balance().total_outflow(),
               Dim == 2 ? "m3/m" : "m3", solid.removed_particles());
  spdlog::info("results: {}", std::filesystem::absolute(directory).string());
  return 0;
}

int run(const RunOptions& options, scene::Document& doc) {
  return coupling::coupled_dimension(doc.root()) == 2 ? run_in<2>(options, doc) : run_in<3>(options, doc);
}

}  // namespace

int main(int argc, char** argv) {
  return run_program("outburst", "Coal-and-gas outburst: seepage (FE) and coal (MPM) coupled by windows", argc, argv,
                     run);
}
