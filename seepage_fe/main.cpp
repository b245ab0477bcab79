// seepage-fe: the gas seepage solver on its own (verification, drainage studies).
#include <chrono>
#include <optional>
#include <string>
#include <variant>

#include <spdlog/spdlog.h>

#include "common/blas.hpp"
#include "common/output_folder.hpp"
#include "common/program.hpp"
#include "common/progress.hpp"
#include "common/run_loop.hpp"
#include "common/stop.hpp"
#include "seepage_fe/output.hpp"
#include "seepage_fe/scene_reader.hpp"

using namespace outburst;

namespace {

// The run of a plane (Dim = 2) or 3D scene, once read.
template <int Dim>
int run_scene(const RunOptions& options, scene::Document& doc, const SceneHeader& header,
              seepage::SetupOf<Dim> setup) {
  const auto wall_start = std::chrono::steady_clock::now();
  const bool gas = setup.model.law == seepage::Law::gas;
  seepage::SolverOf<Dim> solver(std::move(setup.mesh), setup.model, setup.settings);
  spdlog::debug("BLAS: {}", blas::description());
  spdlog::info("{}: {} nodes, {} cells{}, {} law, until t = {}", header.title, solver.mesh().num_nodes(),
               solver.mesh().num_cells(), Dim == 2 ? "" : " (3D)", gas ? "gas" : "linear",
               format_duration(header.end_time));

  // Plane balances are per metre of depth: a 3D run's are whole volumes.
  const char* volume = Dim == 2 ? "m3/m" : "m3";
  const OutputFolder folder(options.output_directory(), "seepage-fe", options.earlier_files());
  std::string units = gas ? "SI: m, s, Pa; P = p^2 in Pa^2; gas volumes at standard conditions" : "SI: m, s, Pa";
  if (Dim == 3) units += "; balances in m3 (3D: not per metre of depth)";
  const auto info = run_info("seepage-fe", doc, units);
  std::optional<checkpoint::Reader> restart;
  if (options.restart) restart.emplace(folder.path(), info);
  seepage::Output out(folder.path(), info, solver, options.restart);

  // One implicit step at a time, growing from the first step size; a step
  // shortened to land on an output time does not shrink the next one.
  struct Driver {
    seepage::SolverOf<Dim>& solver;
    seepage::Output& out;
    const seepage::TimeStepControl& steps;
    double dt;
    long iterations = 0;

    double time() const { return solver.time(); }
    LoopStep advance(double target) {
      const double h = std::min(dt, target - solver.time());
      const auto report = solver.advance(h);
      iterations += report.nonlinear_iterations;
      out.history(solver, h, report);
      if (h == dt) dt = std::min(dt * steps.growth, steps.maximum);
      return {solver.steps(), h, fmt::format("iterations {}", report.nonlinear_iterations)};
    }
    double kinetic_energy() const { return 0; }
    void snapshot() { out.snapshot(solver); }
    void save(checkpoint::Out root, checkpoint::Out run) const {
      solver.save(root.group("seepage"));
      out.save(root.group("output"));
      run.number("dt", dt);
      run.count("iterations", iterations);
    }
    void load(const checkpoint::In& root, const checkpoint::In& run) {
      solver.load(root.group("seepage"));
      out.load(root.group("output"));
      dt = run.number("dt");
      iterations = run.count("iterations");
    }
  } driver{solver, out, setup.steps, setup.steps.first};
  RunLoop loop(header, folder.path(), info);
  if (restart) {
    loop.resume(*restart, driver);
    spdlog::info("restarted from {} at t = {:.9g} s, step {}", restart->path().string(), solver.time(),
                 solver.steps());
  } else {
    driver.snapshot();
  }
  if (loop.run(driver, "seepage", options.show_progress()) == RunEnd::stopped)
    return report_stop(solver.time(), out.series().index_path());

  const auto& b = solver.balance();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  spdlog::info("done: {} steps, {} nonlinear iterations, {:.3g} s wall", solver.steps(), driver.iterations, wall);
  spdlog::info("gas balance: stored {:.6g} of initially {:.6g} {}, released {:.6g} {}, "
               "balance error {:.2e} (relative)",
               b.stored, b.initial_stored, volume, b.total_outflow(), volume,
               b.initial_stored > 0 ? b.error() / b.initial_stored : b.error());
  spdlog::info("results: {}", std::filesystem::absolute(out.series().index_path()).string());
  return 0;
}

int run(const RunOptions& options, scene::Document& doc) {
  auto root = doc.root();
  const SceneHeader header = read_scene_header(root);
  require_solvers(root, header, {"seepage"}, "seepage-fe");
  const auto seepage_table = root.table("seepage", "the gas seepage solver", true);
  auto setup = seepage::read_any_setup(*seepage_table);
  const auto& steps = std::visit([](const auto& s) -> const seepage::TimeStepControl& { return s.steps; }, setup);
  seepage::check_run_length(*seepage_table, steps, header.end_time, header.output_interval);
  if (!finish_reading(options, doc)) return 0;
  return std::visit([&](auto& s) { return run_scene(options, doc, header, std::move(s)); }, setup);
}

}  // namespace

int main(int argc, char** argv) {
  return run_program("seepage-fe", "Gas seepage in a coal seam: implicit Q1 finite elements", argc,
                     argv, run);
}
