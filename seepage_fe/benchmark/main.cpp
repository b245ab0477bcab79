// seepage-benchmark: the seepage solver's Newton iterations under each linear
// solver, and CHOLMOD's factorisation of their Jacobian under each mode and
// ordering, measured in one run.
//
// Problem (as issue 2 fixed it): unit square, A = 2, lambda = 0.1, P0 = 9
// (p0 = 3), the left side drained to p = 1, backward Euler, Newton, steps of
// --time-step (1e-3 by default). --mesh adds Gmsh meshes: every region that material, the mesh's
// first boundary drained. --cube adds the unit cube in hexahedra, its left face drained.
//
// The machine may be shared: contenders alternate within each round and each
// keeps its best round, so a burst of load elsewhere costs a round, not a row.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "common/blas.hpp"
#include "common/host.hpp"
#include "seepage_fe/solver.hpp"

using namespace outburst;
using Clock = std::chrono::steady_clock;
using seepage::Factorisation;

namespace {

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

template <int Dim>
struct CaseOf {
  std::string mesh_name;  // "square", "cube" or the Gmsh file's name
  seepage::MeshOf<Dim> mesh;
  seepage::Model model;
};
using Case = CaseOf<2>;

template <int Dim>
seepage::Model benchmark_model(const seepage::MeshOf<Dim>& mesh) {
  seepage::Model model;
  model.law = seepage::Law::gas;
  model.materials.assign(mesh.region_names.size(), {0.1, 2.0, 3.0});
  model.boundary_conditions = {
      {mesh.boundary_names().front(), seepage::BoundaryCondition::Type::pressure, TimeFunction(1.0)}};
  return model;
}

Case square(int cells) {
  seepage::StructuredMeshSpec spec;
  spec.cells = {cells, cells};
  spec.regions = {{"square", true, {}, {}}};
  Case c{"square", seepage::make_structured_mesh(spec), {}};
  c.model = benchmark_model(c.mesh);
  return c;
}

CaseOf<3> cube(int cells) {
  seepage::BoxMeshSpec spec;
  spec.cells = {cells, cells, cells};
  CaseOf<3> c{"cube", seepage::make_box_mesh(spec), {}};
  c.model = benchmark_model(c.mesh);
  return c;
}

Case gmsh(const std::string& path) {
  Case c{path.substr(path.find_last_of('/') + 1), seepage::read_gmsh(path, 1.0), {}};
  if (c.mesh.boundary_names().empty()) throw std::runtime_error(path + ": the mesh names no boundary to drain");
  c.model = benchmark_model(c.mesh);
  return c;
}

// ---- the solver's Newton iterations, one contender per linear solver

template <int Dim>
struct Contender {
  std::string linear_solver;
  std::unique_ptr<seepage::SolverOf<Dim>> solver;
  typename seepage::SolverOf<Dim>::State start;  // every round times the step from here
  seepage::Timings best{};  // the round with the cheapest Newton iteration
  double best_per_iteration = std::numeric_limits<double>::infinity();
  double difference = 0;  // max |u - u_reference| / max |u_reference| after a round
};

seepage::Timings minus(const seepage::Timings& a, const seepage::Timings& b) {
  seepage::Timings d;
  d.factorization = a.factorization - b.factorization;
  d.solve = a.solve - b.solve;
  d.total_step = a.total_step - b.total_step;
  d.nonlinear_iterations = a.nonlinear_iterations - b.nonlinear_iterations;
  d.linear_iterations = a.linear_iterations - b.linear_iterations;
  return d;
}

// A Newton row's linear solver by name: direct, cg or lagged, the iterative
// ones with "-adaptive" for Eisenstat and Walker's forcing term.
seepage::Settings linear_solver(const std::string& name, double cg_tolerance) {
  seepage::Settings settings;
  settings.linear_solver = name.starts_with("cg")       ? seepage::LinearSolver::cg
                           : name.starts_with("lagged") ? seepage::LinearSolver::lagged
                                                        : seepage::LinearSolver::direct;
  settings.cg_tolerance = cg_tolerance;
  if (name.ends_with("-adaptive")) settings.cg_forcing = seepage::Forcing::adaptive;
  return settings;
}

template <int Dim>
void newton_rows(const CaseOf<Dim>& c, const std::vector<std::string>& linear_solvers, double dt, double cg_tolerance,
                 int rounds, int steps, std::FILE* csv) {
  std::vector<Contender<Dim>> contenders;
  for (const auto& name : linear_solvers) {
    seepage::Settings settings = linear_solver(name, cg_tolerance);
    settings.scheme = seepage::TimeScheme::backward_euler;
    contenders.push_back({name, std::make_unique<seepage::SolverOf<Dim>>(c.mesh, c.model, settings), {}});
    contenders.back().solver->advance(dt);  // first touch of every array
    contenders.back().start = contenders.back().solver->save_state();
  }
  // Every round the same steps, from the same state and with nothing
  // factorised: a round's cost must not depend on where the solution has got
  // to (CG's iterations do) nor on a factor an earlier round left (the lagged
  // solver's).
  Eigen::VectorXd reference;  // the first contender's solution after its round
  for (int r = 0; r < rounds; ++r)
    for (auto& k : contenders) {
      k.solver->restore_state(k.start);
      k.solver->drop_factorisation();
      const auto before = k.solver->timings();
      for (int step = 0; step < steps; ++step) k.solver->advance(dt);
      const auto d = minus(k.solver->timings(), before);
      const Eigen::VectorXd& u = k.solver->unknown();
      if (&k == &contenders.front())
        reference = u;
      else
        k.difference = std::max(k.difference, (u - reference).lpNorm<Eigen::Infinity>() / reference.lpNorm<Eigen::Infinity>());
      const double per_iteration = d.total_step / static_cast<double>(d.nonlinear_iterations);
      if (per_iteration < k.best_per_iteration) {
        k.best_per_iteration = per_iteration;
        k.best = d;
      }
    }
  const double direct = contenders.front().best_per_iteration;
  for (const auto& k : contenders) {
    const auto& t = k.best;
    const double its = static_cast<double>(t.nonlinear_iterations);
    const auto kind = k.solver->settings().linear_solver;
    const std::string method = kind == seepage::LinearSolver::cg       ? "cg/incomplete_cholesky"
                               : kind == seepage::LinearSolver::lagged ? "cg/" + k.solver->factorisation().name()
                                                                       : k.solver->factorisation().name();
    const long unknowns = static_cast<long>(c.mesh.num_nodes());
    const double cg_iterations = static_cast<double>(t.linear_iterations) / its;
    std::printf("%9ld %-14s %7.0e %-15s %-24s %7.0f %10.4f %9.4f %9.4f %9.4f %8.1f %8.3f %9.1e\n", unknowns,
                c.mesh_name.c_str(), dt, k.linear_solver.c_str(), method.c_str(), its, k.best_per_iteration,
                t.factorization / its, t.solve / its, (t.total_step - t.factorization - t.solve) / its,
                cg_iterations, k.best_per_iteration / direct, k.difference);
    std::fflush(stdout);
    if (csv)
      std::fprintf(csv, "%ld,%s,%g,%d,%s,%s,%g,%.0f,%.6g,%.6g,%.6g,%.6g,%.1f,%.4f,%.3g,%s\n", unknowns,
                   c.mesh_name.c_str(), dt, steps, k.linear_solver.c_str(), method.c_str(),
                   kind == seepage::LinearSolver::direct ? 0.0 : cg_tolerance, its,
                   k.best_per_iteration, t.factorization / its, t.solve / its,
                   (t.total_step - t.factorization - t.solve) / its, cg_iterations, k.best_per_iteration / direct,
                   k.difference, host_csv_field().c_str());
    if (csv) std::fflush(csv);  // a stopped run keeps its rows
  }
}

// ---- CHOLMOD alone on the solver's Jacobian, every mode and ordering

struct Variant {
  Factorisation f;
  std::unique_ptr<seepage::Cholmod> factor;
  double analyse_s = 0, factor_nonzeros = 0, flops = 0;
  double best = std::numeric_limits<double>::infinity();
};

template <int Dim>
void ordering_rows(const CaseOf<Dim>& c, double dt, long simplicial_up_to, int rounds, std::FILE* csv) {
  seepage::Settings settings;
  settings.scheme = seepage::TimeScheme::backward_euler;
  seepage::SolverOf<Dim> solver(c.mesh, c.model, settings);
  solver.advance(dt);  // the Jacobian of a Newton iteration
  const auto& j = solver.jacobian();
  const long unknowns = j.rows();
  std::vector<Variant> variants;
  for (auto mode : {Factorisation::Mode::simplicial, Factorisation::Mode::supernodal}) {
    if (mode == Factorisation::Mode::simplicial && unknowns > simplicial_up_to) continue;
    for (auto ordering : {Factorisation::Ordering::amd, Factorisation::Ordering::metis,
                          Factorisation::Ordering::nesdis, Factorisation::Ordering::cholmod_default}) {
      Variant v{{mode, ordering}, std::make_unique<seepage::Cholmod>()};
      seepage::configure(*v.factor, v.f);
      const auto start = Clock::now();
      v.factor->analyzePattern(j);
      v.analyse_s = seconds_since(start);
      v.factor_nonzeros = v.factor->cholmod().lnz;
      v.flops = v.factor->cholmod().fl;
      variants.push_back(std::move(v));
    }
  }
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(unknowns);
  Eigen::VectorXd x;
  for (int r = 0; r < rounds; ++r)
    for (auto& v : variants) {
      const auto start = Clock::now();
      blas::without_openmp_regions([&] { v.factor->factorize(j); });
      x = v.factor->solve(b);
      v.best = std::min(v.best, seconds_since(start));
      // A failed factorisation has no time to record.
      if (v.factor->info() != Eigen::Success)
        throw std::runtime_error(fmt::format("{} could not factorise the Jacobian of {} unknowns", v.f.name(),
                                             unknowns));
    }
  double fastest = std::numeric_limits<double>::infinity();
  for (const auto& v : variants) fastest = std::min(fastest, v.best);
  const std::string chosen = seepage::factorisation_for(static_cast<std::size_t>(unknowns), Dim).name();
  for (const auto& v : variants) {
    const std::string name = v.f.name();
    std::printf("%9ld %-14s %-28s %9.4f %10.5f %10.3g %10.3g %8.3f%s\n", unknowns, c.mesh_name.c_str(),
                name.c_str(), v.analyse_s, v.best, v.factor_nonzeros, v.flops, v.best / fastest,
                name == chosen ? "  <- the solver's" : "");
    if (csv)
      std::fprintf(csv, "%ld,%s,%s,%s,%.6g,%.6g,%.6g,%.6g,%.4f,%d,%s\n", unknowns, c.mesh_name.c_str(),
                   name.substr(0, name.find('/')).c_str(), name.substr(name.find('/') + 1).c_str(), v.analyse_s,
                   v.best, v.factor_nonzeros, v.flops, v.best / fastest, name == chosen ? 1 : 0,
                   host_csv_field().c_str());
    if (csv) std::fflush(csv);
  }
  std::fflush(stdout);
}

std::FILE* open_csv(const std::string& path, const char* header) {
  if (path.empty()) return nullptr;
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::fprintf(f, "%s\n", header);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("The seepage solver's Newton iterations under each linear solver, and CHOLMOD's factorisation of "
               "their Jacobian under each mode and ordering",
               "seepage-benchmark");
  std::vector<int> sides, cube_sides;
  std::vector<std::string> meshes, linear_solvers{"direct", "cg"};
  std::string csv_path, orderings_path;
  std::vector<double> time_steps{1e-3};
  double cg_tolerance = seepage::Settings{}.cg_tolerance;
  int rounds = 3, steps = 1;
  long simplicial_up_to = std::numeric_limits<long>::max();
  bool no_newton = false, no_orderings = false;
  app.add_option("cells", sides,
                 "cells per side of the unit square, one case each (unknowns: (n + 1)^2); without these, --mesh "
                 "and --cube: 99 315 999")
      ->check(CLI::Range(2, 4000));
  app.add_option("--cube", cube_sides, "cells per side of the unit cube in hexahedra, one case each, after the "
                                      "meshes (unknowns: (n + 1)^3)")
      ->check(CLI::Range(1, 200));
  app.add_option("--mesh", meshes, "a Gmsh MSH 4.1 mesh, one case each, after the squares")->check(CLI::ExistingFile);
  app.add_option("--csv", csv_path,
                 "write the Newton iterations' rows to this CSV (seepage_fe/benchmark/crossover.csv is one)");
  app.add_option("--orderings-csv", orderings_path,
                 "write the factorisations' rows to this CSV (seepage_fe/benchmark/orderings.csv is one, from which "
                 "the solver's choice of mode and ordering is set)");
  app.add_option("--linear-solvers", linear_solvers, "linear solvers of the Newton rows, the first the reference (-adaptive: the "
                                                    "conjugate gradients' tolerance by Eisenstat and Walker's forcing term)")
      ->check(CLI::IsMember({"direct", "cg", "lagged", "cg-adaptive", "lagged-adaptive"}))
      ->capture_default_str();
  app.add_option("--time-step", time_steps, "time steps [s] of the Newton rows, rows for each (the factorisations' "
                                            "rows take the first)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--steps", steps, "time steps per round of the Newton rows, the first of them factorising afresh")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--cg-tolerance", cg_tolerance, "the cg and lagged rows' seepage.cg_tolerance")
      ->check(CLI::Range(1e-16, 0.5))
      ->capture_default_str();
  app.add_option("--rounds", rounds, "rounds, each contender's best kept")->check(CLI::Range(1, 100))->capture_default_str();
  app.add_option("--simplicial-up-to", simplicial_up_to, "factorise simplicially only up to this many unknowns")
      ->check(CLI::PositiveNumber);
  app.add_flag("--no-newton", no_newton, "skip the Newton rows");
  app.add_flag("--no-orderings", no_orderings, "skip the factorisations' rows");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a success; anything else is a bad command line (exit code 2, as every program here).
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    std::FILE* csv = open_csv(csv_path, "unknowns,mesh,time_step_s,steps,linear_solver,method,cg_tolerance,"
                                        "newton_iterations,newton_iteration_s,factor_s,solve_s,other_s,"
                                        "cg_iterations,over_reference,difference,host");
    std::FILE* orderings = open_csv(orderings_path, "unknowns,mesh,mode,ordering,analyse_s,factor_solve_s,"
                                                    "factor_nonzeros,flops,over_fastest,chosen,host");
    if (sides.empty() && meshes.empty() && cube_sides.empty()) sides = {99, 315, 999};
    std::vector<Case> cases;
    for (int n : sides) cases.push_back(square(n));
    for (const auto& m : meshes) cases.push_back(gmsh(m));
    std::vector<CaseOf<3>> cubes;
    for (int n : cube_sides) cubes.push_back(cube(n));
    std::printf("On %s; BLAS: %s; %d rounds, best kept\n", host_description().c_str(), blas::description().c_str(),
                rounds);
    if (!no_newton) {
      std::printf("\nPer Newton iteration [s] (other: residuals, Jacobian values, line search, bookkeeping; differs: max |u - u_first| / max |u_first| after the round)\n");
      std::printf("%9s %-14s %7s %-15s %-24s %7s %10s %9s %9s %9s %8s %8s %9s\n", "unknowns", "mesh", "dt", "solver",
                  "method", "Newton", "per it.", "factor", "solve", "other", "cg its", "/ first", "differs");
      for (const auto& c : cases)
        for (double dt : time_steps) newton_rows(c, linear_solvers, dt, cg_tolerance, rounds, steps, csv);
      for (const auto& c : cubes)
        for (double dt : time_steps) newton_rows(c, linear_solvers, dt, cg_tolerance, rounds, steps, csv);
    }
    if (!no_orderings) {
      std::printf("\nCHOLMOD factor-and-solve of the Jacobian\n");
      std::printf("%9s %-14s %-28s %9s %10s %10s %10s %8s\n", "unknowns", "mesh", "mode/ordering", "analyse",
                  "factor+solve", "nnz(L)", "flops", "/ best");
      for (const auto& c : cases) ordering_rows(c, time_steps.front(), simplicial_up_to, rounds, orderings);
      for (const auto& c : cubes) ordering_rows(c, time_steps.front(), simplicial_up_to, rounds, orderings);
    }
    for (std::FILE* f : {csv, orderings})
      if (f && std::fclose(f) != 0) throw std::runtime_error("a CSV could not be written in full");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "seepage-benchmark: %s\n", e.what());
    return 1;
  }
  return 0;
}
