// seepage-benchmark: where the time of a seepage step goes, beside a bare
// CHOLMOD factor-and-solve of the same Jacobian in the same run.
//
// Problem (as the issue fixes it): unit square, A = 2, lambda = 0.1, P0 = 9
// (p0 = 3), the left side drained to p = 1, backward Euler, Newton.
// Usage: seepage-benchmark [--csv FILE] [cells per side ...]   (default 99 315 999: 1e4..1e6 unknowns; --help)
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/CholmodSupport>

#include "common/blas.hpp"
#include "seepage_fe/solver.hpp"

using namespace outburst;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Median-free and simple: the mean of `reps` factor-and-solve calls.
double bare_factor_and_solve(const Eigen::SparseMatrix<double>& j, int mode, int reps) {
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> f;
  f.setMode(static_cast<Eigen::CholmodMode>(mode));
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(j.rows());
  Eigen::VectorXd x;
  if (mode == Eigen::CholmodSupernodalLLt) {  // as the solver configures it
    f.cholmod().nmethods = 1;
    f.cholmod().method[0].ordering = CHOLMOD_NESDIS;
  }
  f.analyzePattern(j);
  const auto start = Clock::now();
  for (int r = 0; r < reps; ++r) {
    blas::without_openmp_regions([&] { f.factorize(j); });
    x = f.solve(b);
  }
  if (f.info() != Eigen::Success) std::fprintf(stderr, "bare factorisation failed\n");
  return seconds_since(start) / reps;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Where the time of a seepage step goes, beside a bare CHOLMOD factor-and-solve of the same Jacobian",
               "seepage-benchmark");
  std::vector<int> sides{99, 315, 999};
  std::string csv_path;
  app.add_option("cells", sides, "cells per side of the unit square, one row each (unknowns: (n + 1)^2)")
      ->check(CLI::Range(2, 4000))
      ->capture_default_str();
  app.add_option("--csv", csv_path, "also write the rows to this CSV file (seepage_fe/benchmark/crossover.csv is "
                                    "one, from which the solver's switch between CHOLMOD modes is set)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a success; anything else is a bad command line (exit code 2, as every program here).
    return app.exit(e) == 0 ? 0 : 2;
  }
  std::FILE* csv = nullptr;
  if (!csv_path.empty()) {
    csv = std::fopen(csv_path.c_str(), "w");
    if (!csv) {
      std::fprintf(stderr, "seepage-benchmark: cannot write %s\n", csv_path.c_str());
      return 2;
    }
    std::fprintf(csv, "unknowns,mode,step_s,newton_iteration_s,factor_s,solve_s,other_s,bare_s,"
                      "simplicial_over_supernodal\n");
  }
  std::printf("BLAS: %s\n\n", blas::description().c_str());
  std::printf("%9s %7s %9s %9s %9s %9s %9s %9s %7s %10s %10s %12s\n", "unknowns", "mode", "step[s]",
              "newton[s]", "factor[s]", "solve[s]", "other[s]", "bare[s]", "other/", "assembly",
              "assembly", "simplicial/");
  std::printf("%9s %7s %9s %9s %9s %9s %9s %9s %7s %10s %10s %12s\n", "", "", "", "iteration",
              "per it.", "per it.", "per it.", "fact+solve", "factor", "[s]", "[ns/cell]",
              "supernodal");
  for (int n : sides) {
    seepage::StructuredMeshSpec spec;
    spec.cells = {n, n};
    spec.regions = {{"square", true, {}, {}}};
    seepage::Model model;
    model.law = seepage::Law::gas;
    model.materials = {{0.1, 2.0, 3.0}};
    model.boundary_conditions = {{"left", seepage::BoundaryCondition::Type::pressure, TimeFunction(1.0)}};
    seepage::Settings settings;
    settings.scheme = seepage::TimeScheme::backward_euler;
    seepage::Solver solver(seepage::make_structured_mesh(spec), model, settings);
    const long unknowns = static_cast<long>(solver.mesh().num_nodes());

    const int steps = 2;
    for (int s = 0; s < steps; ++s) solver.advance(1e-3);
    const auto& t = solver.timings();
    const double iterations = static_cast<double>(t.nonlinear_iterations);
    const double factor = t.factorization / iterations;
    const double solve = t.solve / iterations;
    const double other = (t.total_step - t.factorization - t.solve) / iterations;

    // Re-assembly of the conductivity matrix, as the coupler triggers it.
    const auto start = Clock::now();
    const int assemblies = 5;
    for (int a = 0; a < assemblies; ++a) solver.set_conductivity(std::vector<double>(solver.mesh().num_cells(), 0.1 + 1e-3 * a));
    const double assembly = seconds_since(start) / assemblies;

    const bool supernodal = solver.supernodal();
    const double bare = bare_factor_and_solve(solver.jacobian(), supernodal ? Eigen::CholmodSupernodalLLt
                                                                            : Eigen::CholmodSimplicialLLt, 3);
    // Both CHOLMOD modes on the same matrix, to place the switch between them.
    const double simplicial = bare_factor_and_solve(solver.jacobian(), Eigen::CholmodSimplicialLLt, 2);
    const double super = bare_factor_and_solve(solver.jacobian(), Eigen::CholmodSupernodalLLt, 2);
    std::printf("%9ld %7s %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f %7.3f %10.4f %10.1f %12.2f\n", unknowns,
                supernodal ? "super" : "simpl", t.total_step / steps, t.total_step / iterations, factor, solve,
                other, bare, other / factor, assembly, 1e9 * assembly / static_cast<double>(solver.mesh().num_cells()),
                simplicial / super);
    std::fflush(stdout);
    if (csv)
      std::fprintf(csv, "%ld,%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.4f\n", unknowns,
                   supernodal ? "supernodal" : "simplicial", t.total_step / steps, t.total_step / iterations, factor,
                   solve, other, bare, simplicial / super);
  }
  if (csv && std::fclose(csv) != 0) {
    std::fprintf(stderr, "seepage-benchmark: the CSV could not be written in full\n");
    return 1;
  }
  std::printf("\nother = assembly, residuals, Jacobian values, line search and bookkeeping per Newton "
              "iteration;\ngoal: other/factor <= 0.5 and assembly ns/cell flat across sizes.\n");
  return 0;
}
