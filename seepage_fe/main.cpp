// seepage-fe: the gas seepage solver on its own (verification, drainage studies).
#include <chrono>

#include <spdlog/spdlog.h>

#include "common/blas.hpp"
#include "common/output_folder.hpp"
#include "common/program.hpp"
#include "common/progress.hpp"
#include "common/stop.hpp"
#include "seepage_fe/output.hpp"
#include "seepage_fe/scene_reader.hpp"

using namespace outburst;

namespace {

int run(const RunOptions& options, scene::Document& doc) {
  auto root = doc.root();
  const SceneHeader header = read_scene_header(root);
  require_solvers(root, header, {"seepage"}, "seepage-fe");
  const auto seepage_table = root.table("seepage", "the gas seepage solver", true);
  seepage::Setup setup = seepage::read_setup(*seepage_table);
  seepage::check_run_length(*seepage_table, setup.steps, header.end_time, header.output_interval);
  if (!finish_reading(options, doc)) return 0;

  const auto wall_start = std::chrono::steady_clock::now();
  const bool gas = setup.model.law == seepage::Law::gas;
  seepage::Solver solver(std::move(setup.mesh), setup.model, setup.settings);
  spdlog::debug("BLAS: {}", blas::description());
  spdlog::info("{}: {} nodes, {} cells, {} law, until t = {}", header.title,
               solver.mesh().num_nodes(), solver.mesh().num_cells(), gas ? "gas" : "linear",
               format_duration(header.end_time));

  const OutputFolder folder(options.output_directory(), "seepage-fe", options.overwrite);
  seepage::Output out(folder.path(), run_info("seepage-fe", doc, gas ? "SI: m, s, Pa; P = p^2 in Pa^2; "
                                                                  "gas volumes at standard conditions"
                                                                : "SI: m, s, Pa"),
                      solver);
  out.snapshot(solver);

  Progress progress("seepage", 0.0, header.end_time, options.show_progress());
  double dt = setup.steps.first;
  double next_output = header.output_interval;
  long iterations = 0;
  while (solver.time() < header.end_time * (1 - 1e-12)) {
    const double target = std::min(next_output, header.end_time);
    const double h = std::min(dt, target - solver.time());
    const auto report = solver.advance(h);
    iterations += report.nonlinear_iterations;
    out.history(solver, h, report);
    progress.update(solver.steps(), solver.time(), h,
                    fmt::format("iterations {}", report.nonlinear_iterations));
    const bool output_due = solver.time() >= target * (1 - 1e-12);
    const bool stop = stop_requested();  // read once: a signal may come in between
    if (output_due || stop) out.snapshot(solver);
    if (output_due) next_output += header.output_interval;
    if (stop) {
      progress.finish();
      return report_stop(solver.time(), out.series().index_path());
    }
    // A step shortened to land on an output time does not shrink the next one.
    if (h == dt) dt = std::min(dt * setup.steps.growth, setup.steps.maximum);
  }
  progress.finish();

  const auto& b = solver.balance();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  spdlog::info("done: {} steps, {} nonlinear iterations, {:.3g} s wall", solver.steps(), iterations, wall);
  spdlog::info("gas balance: stored {:.6g} of initially {:.6g} m3/m, released {:.6g} m3/m, "
               "balance error {:.2e} (relative)",
               b.stored, b.initial_stored, b.total_outflow(),
               b.initial_stored > 0 ? b.error() / b.initial_stored : b.error());
  spdlog::info("results: {}", std::filesystem::absolute(out.series().index_path()).string());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return run_program("seepage-fe", "Gas seepage in a coal seam: implicit Q1 finite elements", argc,
                     argv, run);
}
