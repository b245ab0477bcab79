#include "seepage_fe/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/blas.hpp"
#include "seepage_fe/q1.hpp"

namespace outburst::seepage {

namespace {

using Clock = std::chrono::steady_clock;

// Adds the wall time of its scope to a counter.
class ScopedTimer {
 public:
  explicit ScopedTimer(double& total) : total_(total), start_(Clock::now()) {}
  ~ScopedTimer() { total_ += std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  double& total_;
  Clock::time_point start_;
};

}  // namespace

// The fastest numeric factorisation by size and dimension, read from
// seepage_fe/benchmark/orderings.csv and orderings_3d.csv
// (`seepage-benchmark --orderings-csv`, on the unit square, the outburst's
// meshes and the unit cube; docs/performance/seepage.md tables them). In 2D below about 5000
// unknowns simplicial: its loops beat supernodal's BLAS calls, and the
// orderings tie, so AMD, the quickest to compute. From there, and in 3D at
// every size (a hexahedron couples 27 nodes, and the fronts are wide from the
// start), supernodal with CHOLMOD's nested dissection: the fewest flops (to
// 1 %) and the fastest or within the noise of it. Its analysis, the slowest
// (seconds at 1e6), is done once per run.
Factorisation factorisation_for(std::size_t unknowns, int dim) {
  using F = Factorisation;
  if (dim == 2 && unknowns < 5000) return {F::Mode::simplicial, F::Ordering::amd};
  return {F::Mode::supernodal, F::Ordering::nesdis};
}

std::string Factorisation::name() const {
  static constexpr const char* orderings[] = {"amd", "metis", "nesdis", "cholmod_default"};
  return fmt::format("{}/{}", mode == Mode::simplicial ? "simplicial" : "supernodal",
                     orderings[static_cast<int>(ordering)]);
}

void configure(Cholmod& factor, Factorisation f) {
  factor.setMode(f.mode == Factorisation::Mode::simplicial ? Eigen::CholmodSimplicialLLt
                                                           : Eigen::CholmodSupernodalLLt);
  cholmod_common& c = factor.cholmod();
  if (f.ordering == Factorisation::Ordering::cholmod_default) {
    c.nmethods = 0;
    return;
  }
  c.nmethods = 1;
  c.method[0].ordering = f.ordering == Factorisation::Ordering::amd     ? CHOLMOD_AMD
                         : f.ordering == Factorisation::Ordering::metis ? CHOLMOD_METIS
                                                                        : CHOLMOD_NESDIS;
}

double Balance::error() const {
  double inflow = inflow_through_flux;
  for (double v : inflow_through_pressure) inflow += v;
  return stored - initial_stored - inflow;
}

double Balance::total_outflow() const {
  return -std::accumulate(inflow_through_pressure.begin(), inflow_through_pressure.end(), 0.0);
}

template <int Dim>
SolverOf<Dim>::SolverOf(MeshOf<Dim> mesh, Model model, Settings settings)
    : mesh_(std::move(mesh)),
      model_(std::move(model)),
      settings_(settings),
      sampler_(mesh_) {
  if (model_.materials.size() != mesh_.region_names.size())
    throw std::invalid_argument(fmt::format("the mesh has {} regions but the model {} materials",
                                            mesh_.region_names.size(), model_.materials.size()));
  setup_system();

  // Initial state: each node takes the mean initial pressure of the cells around it.
  const std::size_t n = mesh_.num_nodes();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  Eigen::VectorXd count = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c)
    for (int node : mesh_.cells[c]) {
      sum[node] += model_.materials[mesh_.cell_region[c]].initial_pressure;
      count[node] += 1;
    }
  u_.resize(static_cast<Eigen::Index>(n));
  for (Eigen::Index i = 0; i < u_.size(); ++i)
    u_[i] = unknown_from_pressure(model_.law, sum[i] / count[i]);
  u_previous_ = u_;

  for (std::size_t k = 0; k < model_.boundary_conditions.size(); ++k)
    if (model_.boundary_conditions[k].type == BoundaryCondition::Type::pressure)
      balance_.pressure_boundaries.push_back(model_.boundary_conditions[k].boundary);
  balance_.inflow_through_pressure.assign(balance_.pressure_boundaries.size(), 0.0);
  last_inflow_pressure_.assign(balance_.pressure_boundaries.size(), 0.0);
  restart_balance();
}

template <int Dim>
void SolverOf<Dim>::setup_system() {
  const std::size_t n = mesh_.num_nodes(), nc = mesh_.num_cells();
  cell_stiffness_.resize(nc);
  cell_lumped_.resize(nc);
  capacity_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  conductivity_.resize(nc);
  std::vector<Eigen::Triplet<double>> pattern;
  constexpr int N = cell_corners;
  pattern.reserve(nc * N * N);
  for (std::size_t c = 0; c < nc; ++c) {
    const auto integrals = q1::integrals(mesh_.corners(c));
    cell_stiffness_[c] = integrals.stiffness;
    cell_lumped_[c] = integrals.lumped;
    const Material& m = model_.materials[mesh_.cell_region[c]];
    conductivity_[c] = m.conductivity;
    for (int a = 0; a < N; ++a) {
      capacity_[mesh_.cells[c][a]] += m.capacity * integrals.lumped[a];
      for (int b = 0; b < N; ++b) pattern.emplace_back(mesh_.cells[c][a], mesh_.cells[c][b], 0.0);
    }
  }
  stiffness_.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  stiffness_.setFromTriplets(pattern.begin(), pattern.end());
  stiffness_.makeCompressed();

  // Where each (row, column) of each cell lands in the compressed value array,
  // so assembly is a plain scatter with no search.
  const auto value_index = [&](int row, int col) {
    const int* begin = stiffness_.innerIndexPtr() + stiffness_.outerIndexPtr()[col];
    const int* end = stiffness_.innerIndexPtr() + stiffness_.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) - stiffness_.innerIndexPtr());
  };
  scatter_.resize(nc);
  for (std::size_t c = 0; c < nc; ++c)
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b)
        scatter_[c][N * a + b] = value_index(mesh_.cells[c][a], mesh_.cells[c][b]);
  diagonal_.resize(n);
  for (std::size_t i = 0; i < n; ++i) diagonal_[i] = value_index(static_cast<int>(i), static_cast<int>(i));

  // Pressure conditions fix nodes; the first condition listed wins at corners.
  fixed_by_.assign(n, -1);
  pressure_bc_slot_.assign(model_.boundary_conditions.size(), -1);
  int slot = 0;
  for (std::size_t k = 0; k < model_.boundary_conditions.size(); ++k) {
    const auto& bc = model_.boundary_conditions[k];
    const auto* boundary = mesh_.boundary(bc.boundary);
    if (!boundary) throw std::invalid_argument(fmt::format("no boundary named '{}'", bc.boundary));
    if (bc.type != BoundaryCondition::Type::pressure) continue;
    pressure_bc_slot_[k] = slot++;
    for (const auto& face : boundary->faces)
      for (int node : face)
        if (fixed_by_[node] < 0) fixed_by_[node] = static_cast<int>(k);
  }
  boundary_fixed_by_ = fixed_by_;
  find_dirichlet_entries();

  jacobian_ = stiffness_;
  assemble_conductivity();
  blas::set_threads_for(static_cast<long>(n));
  if (settings_.linear_solver != LinearSolver::cg) {
    factorisation_ = factorisation_for(n, Dim);
    configure(factor_, factorisation_);
    factor_.analyzePattern(jacobian_);
  } else {
    cg_.setTolerance(settings_.cg_tolerance);
    cg_.setMaxIterations(settings_.cg_max_iterations);
    cg_.analyzePattern(jacobian_);
  }
  if (settings_.linear_solver == LinearSolver::lagged) {
    lagged_cg_.setTolerance(settings_.cg_tolerance);
    lagged_cg_.setMaxIterations(settings_.lag_max_iterations);
    lagged_cg_.preconditioner().use(&factor_);
  }
  const std::size_t size = n;
  for (auto* v : {&trial_, &history_, &load_, &r_, &delta_, &candidate_})
    v->setZero(static_cast<Eigen::Index>(size));
}

template <int Dim>
void SolverOf<Dim>::find_dirichlet_entries() {
  dirichlet_diagonal_.clear();
  dirichlet_zero_.clear();
  for (Eigen::Index col = 0; col < stiffness_.outerSize(); ++col)
    for (int k = stiffness_.outerIndexPtr()[col]; k < stiffness_.outerIndexPtr()[col + 1]; ++k) {
      const int row = stiffness_.innerIndexPtr()[k];
      if (row == col && fixed_by_[row] >= 0)
        dirichlet_diagonal_.push_back(k);
      else if (row != col && (fixed_by_[row] >= 0 || fixed_by_[col] >= 0))
        dirichlet_zero_.push_back(k);
    }
}

// Open space is one more pressure condition, index K = number of the scene's
// conditions, with its own balance slot added on first use.
template <int Dim>
void SolverOf<Dim>::set_open_nodes(const std::vector<char>& open, double pressure) {
  if (open.size() != mesh_.num_nodes())
    throw std::invalid_argument(fmt::format("set_open_nodes: {} flags for {} nodes", open.size(), mesh_.num_nodes()));
  if (model_.law == Law::gas && !(pressure > 0))
    throw std::invalid_argument(fmt::format("set_open_nodes: open pressure {} Pa; the gas law needs p > 0", pressure));
  const int open_condition = static_cast<int>(model_.boundary_conditions.size());
  if (static_cast<int>(pressure_bc_slot_.size()) == open_condition) {
    pressure_bc_slot_.push_back(static_cast<int>(balance_.pressure_boundaries.size()));
    balance_.pressure_boundaries.push_back("open space");
    balance_.inflow_through_pressure.push_back(0.0);
    last_inflow_pressure_.push_back(0.0);
  }
  open_pressure_ = pressure;
  bool changed = false;
  for (std::size_t i = 0; i < open.size(); ++i) {
    const int by = boundary_fixed_by_[i] < 0 && open[i] ? open_condition : boundary_fixed_by_[i];
    changed = changed || by != fixed_by_[i];
    fixed_by_[i] = by;
  }
  if (!changed) return;  // the coupler calls this every window
  find_dirichlet_entries();
  ++conductivity_version_;  // the Jacobian's rows changed: refactorise
}

template <int Dim>
void SolverOf<Dim>::assemble_conductivity() {
  ScopedTimer timer(timings_.assembly);
  double* values = stiffness_.valuePtr();
  std::fill(values, values + stiffness_.nonZeros(), 0.0);
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c) {
    const double k = conductivity_[c];
    const double* ke = cell_stiffness_[c].data();  // column-major, symmetric
    for (int e = 0; e < cell_corners * cell_corners; ++e) values[scatter_[c][e]] += k * ke[e];
  }
  ++conductivity_version_;
}

template <int Dim>
void SolverOf<Dim>::set_conductivity(const std::vector<double>& per_cell) {
  if (per_cell.size() != mesh_.num_cells())
    throw std::invalid_argument(fmt::format("set_conductivity: {} values for {} cells",
                                            per_cell.size(), mesh_.num_cells()));
  for (std::size_t c = 0; c < per_cell.size(); ++c)
    if (!(per_cell[c] > 0) || !std::isfinite(per_cell[c]))
      throw std::invalid_argument(
          fmt::format("set_conductivity: cell {} gets {}, expected a positive finite value", c,
                      per_cell[c]));
  conductivity_ = per_cell;
  assemble_conductivity();
}

template <int Dim>
void SolverOf<Dim>::set_initial_pressure(const std::vector<double>& nodal_p) {
  if (steps_ > 0) throw std::logic_error("set_initial_pressure: the run has already started");
  if (nodal_p.size() != mesh_.num_nodes())
    throw std::invalid_argument(fmt::format("set_initial_pressure: {} values for {} nodes",
                                            nodal_p.size(), mesh_.num_nodes()));
  for (Eigen::Index i = 0; i < u_.size(); ++i) {
    u_[i] = unknown_from_pressure(model_.law, nodal_p[i]);
    if (model_.law == Law::gas && !(nodal_p[i] > 0))
      throw std::invalid_argument(fmt::format("set_initial_pressure: node {} gets p = {}; the gas law needs p > 0", i, nodal_p[i]));
  }
  u_previous_ = u_;
  restart_balance();
}

// The gas stored now becomes the balance's starting point.
template <int Dim>
void SolverOf<Dim>::restart_balance() {
  balance_.initial_stored = 0;
  for (Eigen::Index i = 0; i < u_.size(); ++i)
    balance_.initial_stored += capacity_[i] * storage_x(model_.law, u_[i]);
  balance_.stored = balance_.initial_stored;
}

template <int Dim>
void SolverOf<Dim>::set_boundary_values(double t, Eigen::VectorXd& u) const {
  for (std::size_t i = 0; i < fixed_by_.size(); ++i)
    if (fixed_by_[i] >= 0)
      u[static_cast<Eigen::Index>(i)] = unknown_from_pressure(
          model_.law, static_cast<std::size_t>(fixed_by_[i]) < model_.boundary_conditions.size()
                          ? model_.boundary_conditions[fixed_by_[i]].value(t)
                          : open_pressure_);
}

template <int Dim>
void SolverOf<Dim>::set_cell_source(std::vector<double> per_cell) {
  if (!per_cell.empty() && per_cell.size() != mesh_.num_cells())
    throw std::invalid_argument(fmt::format("set_cell_source: {} values for {} cells", per_cell.size(),
                                            mesh_.num_cells()));
  cell_source_ = std::move(per_cell);
}

template <int Dim>
void SolverOf<Dim>::add_storage(double per_pressure) {
  if (steps_ > 0) throw std::logic_error("add_storage: the run has already started");
  if (model_.law != Law::linear) throw std::invalid_argument("add_storage: only for the linear law");
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c)
    for (int a = 0; a < cell_corners; ++a) capacity_[mesh_.cells[c][a]] += per_pressure * cell_lumped_[c][a];
  restart_balance();
}

template <int Dim>
void SolverOf<Dim>::load_vector(double t, Eigen::VectorXd& f) const {
  f.setZero();
  for (const auto& bc : model_.boundary_conditions) {
    if (bc.type != BoundaryCondition::Type::flux) continue;
    const double q = bc.value(t);
    if (q == 0) continue;
    for (const auto& face : mesh_.boundary(bc.boundary)->faces) {
      const auto w = q1::face_lumped(mesh_.face_corners_of(face));
      for (std::size_t a = 0; a < face.size(); ++a) f[face[a]] += q * w[a];
    }
  }
  for (std::size_t c = 0; c < cell_source_.size(); ++c) {
    if (cell_source_[c] == 0) continue;
    for (int a = 0; a < cell_corners; ++a) f[mesh_.cells[c][a]] += cell_source_[c] * cell_lumped_[c][a];
  }
  if (!source_) return;
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c) {
    const auto x = mesh_.corners(c);
    for (const auto& g : q1::gauss_points<Dim>()) {
      const auto p = q1::evaluate(x, g);
      Point at = Point::Zero();
      for (int a = 0; a < cell_corners; ++a) at += p.n[a] * x[a];
      const double s = source_(at, t) * p.det_j;
      for (int a = 0; a < cell_corners; ++a) f[mesh_.cells[c][a]] += p.n[a] * s;
    }
  }
}

// r = c (a0 X(u) + history) + h (K u - f); returns the norm over free nodes.
// The full vector (fixed rows included) stays in r_ for the boundary reactions;
// residual_scale_ is the size of the terms that cancel in it (storage and flux),
// so that a residual at round-off of those terms counts as converged.
template <int Dim>
double SolverOf<Dim>::residual(const Eigen::VectorXd& u, double a0, double h) {
  ScopedTimer timer(timings_.residual);
  ++timings_.residual_evaluations;
  r_.noalias() = h * (stiffness_ * u);
  const Law law = model_.law;
  double norm2 = 0, scale2 = 0;
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    const double stored = capacity_[i] * a0 * storage_x(law, u[i]);
    const double flux = h * stiffness_.valuePtr()[diagonal_[i]] * u[i];
    if (fixed_by_[i] < 0) scale2 += stored * stored + flux * flux;
    r_[i] += stored + capacity_[i] * history_[i] - h * load_[i];
    if (fixed_by_[i] < 0) norm2 += r_[i] * r_[i];
  }
  residual_scale_ = std::sqrt(scale2);
  return std::sqrt(norm2);
}

template <int Dim>
void SolverOf<Dim>::build_jacobian(const Eigen::VectorXd& u, double a0, double h) {
  ScopedTimer timer(timings_.jacobian);
  const Law law = model_.law;
  double* j = jacobian_.valuePtr();
  const double* k = stiffness_.valuePtr();
  const Eigen::Index nnz = stiffness_.nonZeros();
  for (Eigen::Index e = 0; e < nnz; ++e) j[e] = h * k[e];
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    double slope = storage_dx(law, u[i]);
    if (settings_.method == NonlinearMethod::picard) {
      // Secant through the previous time level: a fixed point whose solution is
      // the same conservative discrete equation Newton solves.
      const double du = u[i] - u_[i];
      if (std::abs(du) > 1e-12 * std::abs(u[i]))
        slope = (storage_x(law, u[i]) - storage_x(law, u_[i])) / du;
    }
    j[diagonal_[i]] += a0 * capacity_[i] * slope;
  }
  for (int e : dirichlet_zero_) j[e] = 0.0;
  for (int e : dirichlet_diagonal_) j[e] = 1.0;
}

template <int Dim>
std::optional<std::string> SolverOf<Dim>::try_step(double h, int& iterations) {
  double a0 = 1, a1 = -1, a2 = 0;
  if (settings_.scheme == TimeScheme::bdf2 && has_previous_) {
    const double w = h / dt_previous_;
    a0 = (1 + 2 * w) / (1 + w);
    a1 = -(1 + w);
    a2 = w * w / (1 + w);
  }
  const Law law = model_.law;
  const double t_new = time_ + h;
  for (Eigen::Index i = 0; i < u_.size(); ++i)
    history_[i] = a1 * storage_x(law, u_[i]) + a2 * storage_x(law, u_previous_[i]);
  load_vector(t_new, load_);
  trial_ = u_;
  set_boundary_values(t_new, trial_);

  double norm = residual(trial_, a0, h);
  // The update criterion needs one more iteration to confirm convergence; a
  // residual this small relative to its terms needs none.
  const double residual_tolerance = 1e-2 * settings_.tolerance;
  // Eisenstat and Walker's forcing term, choice 2 (gamma 0.9, alpha 2), from
  // 0.1 at a step's first iteration down to cg_tolerance. Not for the linear
  // law: one solve to cg_tolerance is its whole Newton iteration.
  const bool adaptive = settings_.cg_forcing == Forcing::adaptive &&
                        settings_.linear_solver != LinearSolver::direct && law != Law::linear;
  const double loosest = std::max(0.1, settings_.cg_tolerance);
  double forcing = loosest;
  for (iterations = 1; iterations <= settings_.max_iterations; ++iterations) {
    ++timings_.nonlinear_iterations;
    if (adaptive) set_linear_tolerance(forcing);
    if (auto failure = newton_direction(trial_, a0, h)) return failure;
    if (!delta_.allFinite()) return "the Newton update is not finite";

    // Keep the gas law's P positive: never step more than 90% of the way to zero.
    double alpha = 1.0;
    if (law == Law::gas)
      for (Eigen::Index i = 0; i < delta_.size(); ++i)
        if (delta_[i] < 0) alpha = std::min(alpha, 0.9 * trial_[i] / -delta_[i]);

    double trial_norm = 0;
    for (int halving = 0;; ++halving) {
      candidate_ = trial_ + alpha * delta_;
      trial_norm = residual(candidate_, a0, h);
      // Newton must reduce the residual (Armijo); Picard's secant direction need
      // not, so it only keeps positivity.
      if (settings_.method == NonlinearMethod::picard || trial_norm <= (1 - 1e-4 * alpha) * norm ||
          trial_norm <= residual_tolerance * residual_scale_)
        break;
      if (halving == 12)
        return fmt::format("the line search found no decrease of the residual ({:.3e}) after 12 "
                           "halvings of the Newton step",
                           norm);
      alpha *= 0.5;
    }
    const double update = alpha * delta_.lpNorm<Eigen::Infinity>();
    trial_.swap(candidate_);
    const double reduction = trial_norm / norm;
    norm = trial_norm;
    if (!std::isfinite(norm)) return "the residual is not finite";
    // A small update from a loose solve says little: the true Newton step may
    // be the condition number times the forcing term larger. It counts only
    // from a solve to cg_tolerance.
    const bool small_update = update <= settings_.tolerance * trial_.lpNorm<Eigen::Infinity>();
    if ((small_update && (!adaptive || forcing <= settings_.cg_tolerance)) ||
        norm <= residual_tolerance * residual_scale_) {
      // r_ holds the residual of the accepted iterate, fixed rows included.
      accept_step(h, a0, a2);
      return std::nullopt;
    }
    if (adaptive) {
      const double kept = 0.9 * forcing * forcing;  // safeguard: no sudden drop after a slow iteration
      forcing = 0.9 * reduction * reduction;
      if (kept > 0.1) forcing = std::max(forcing, kept);
      forcing = small_update ? settings_.cg_tolerance : std::clamp(forcing, settings_.cg_tolerance, loosest);
    }
  }
  iterations = settings_.max_iterations;
  return fmt::format("no convergence in {} {} iterations (residual {:.3e})",
                     settings_.max_iterations,
                     settings_.method == NonlinearMethod::newton ? "Newton" : "Picard", norm);
}

// The step converged: update the balance and shift the time levels.
//
// Summing the discrete equation over all nodes (sum_i (K u)_i = 0) gives
//   a0 dS(n+1) - a2 dS(n) = h F + rho
// with dS the change of stored gas over a step, F the prescribed inflow and rho
// the reactions of the fixed nodes. The inflow of each step is therefore the
// scheme's own quadrature I(n+1) = (a2 I(n) + h F + rho) / a0 (for backward
// Euler simply h F + rho), which keeps stored + inflow exact for BDF2 as well.
template <int Dim>
void SolverOf<Dim>::accept_step(double h, double a0, double a2) {
  std::vector<double> rho(last_inflow_pressure_.size(), 0.0);
  for (Eigen::Index i = 0; i < r_.size(); ++i)
    if (fixed_by_[i] >= 0) rho[pressure_bc_slot_[fixed_by_[i]]] += r_[i];
  for (std::size_t b = 0; b < rho.size(); ++b) {
    last_inflow_pressure_[b] = (a2 * last_inflow_pressure_[b] + rho[b]) / a0;
    balance_.inflow_through_pressure[b] += last_inflow_pressure_[b];
  }
  last_inflow_flux_ = (a2 * last_inflow_flux_ + h * load_.sum()) / a0;
  balance_.inflow_through_flux += last_inflow_flux_;

  u_previous_.swap(u_);
  u_.swap(trial_);
  dt_previous_ = h;
  has_previous_ = true;
  time_ += h;
  ++steps_;
  double stored = 0;
  for (Eigen::Index i = 0; i < u_.size(); ++i) stored += capacity_[i] * storage_x(model_.law, u_[i]);
  balance_.stored = stored;
}

template <int Dim>
StepReport SolverOf<Dim>::advance(double dt) {
  if (!(dt > 0)) throw std::invalid_argument(fmt::format("advance: dt = {} is not positive", dt));
  ScopedTimer timer(timings_.total_step);
  StepReport report;
  const double t_end = time_ + dt;
  double h = dt;
  report.smallest_substep = dt;
  int cuts_in_a_row = 0;
  while (time_ < t_end * (1 - 1e-14) - 1e-300) {
    h = std::min(h, t_end - time_);
    int iterations = 0;
    const auto failure = try_step(h, iterations);
    report.nonlinear_iterations += iterations;
    if (!failure) {
      ++report.substeps;
      report.smallest_substep = std::min(report.smallest_substep, h);
      cuts_in_a_row = 0;
      h *= 2;  // grow back after a cut; BDF2 stays zero-stable for ratios below 2.4
      continue;
    }
    ++report.cuts;
    if (++cuts_in_a_row > settings_.max_step_cuts)
      throw StepFailure(fmt::format(
          "seepage: the step from t = {:.6g} s could not be completed: {}. It was halved {} times "
          "down to dt = {:.3g} s. Check that boundary pressures stay positive and consistent "
          "with the initial state, or start with a smaller seepage.time_step.",
          time_, *failure, settings_.max_step_cuts, h));
    spdlog::debug("seepage: step of {:.3g} s at t = {:.6g} s failed ({}); halving", h, time_,
                  *failure);
    h *= 0.5;
  }
  return report;
}

template <int Dim>
std::optional<std::string> SolverOf<Dim>::newton_direction(const Eigen::VectorXd& u, double a0, double h) {
  for (Eigen::Index i = 0; i < r_.size(); ++i)
    if (fixed_by_[i] >= 0) r_[i] = 0;
  const FactorKey key{h, a0, conductivity_version_};
  // A linear law's Jacobian depends only on h, a0 and k: keep its
  // factorisation (the lagged solver too: its iterations would converge in one).
  if (model_.law == Law::linear) {
    if (factor_key_.h != h || factor_key_.a0 != a0 || factor_key_.version != conductivity_version_) {
      build_jacobian(u, a0, h);
      if (auto failure = factorise()) {
        factor_key_ = {};
        return failure;
      }
      factor_key_ = key;
    }
    return solve_newton_system();
  }
  build_jacobian(u, a0, h);
  if (settings_.linear_solver == LinearSolver::lagged && factor_key_.h == h &&
      factor_key_.version == conductivity_version_ && lagged_conjugate_gradients())
    return std::nullopt;
  if (auto failure = factorise()) {
    factor_key_ = {};
    return failure;
  }
  if (settings_.linear_solver == LinearSolver::lagged) factor_key_ = key;
  return solve_newton_system();
}

template <int Dim>
bool SolverOf<Dim>::lagged_conjugate_gradients() {
  ScopedTimer timer(timings_.solve);
  lagged_cg_.compute(jacobian_);
  delta_ = lagged_cg_.solve(-r_);
  timings_.linear_iterations += lagged_cg_.iterations();
  if (lagged_cg_.info() != Eigen::Success || !delta_.allFinite()) {
    ++timings_.lagged_fallbacks;
    return false;
  }
  // Half the allowance spent: the next iteration renews the factor rather than
  // spend as much again.
  if (2 * lagged_cg_.iterations() > settings_.lag_max_iterations) {
    factor_key_ = {};
    ++timings_.lagged_renewals;
  }
  return true;
}

template <int Dim>
void SolverOf<Dim>::set_linear_tolerance(double tolerance) {
  if (settings_.linear_solver == LinearSolver::cg)
    cg_.setTolerance(tolerance);
  else
    lagged_cg_.setTolerance(tolerance);
}

template <int Dim>
std::optional<std::string> SolverOf<Dim>::factorise() {
  ScopedTimer timer(timings_.factorization);
  ++timings_.factorizations;
  if (settings_.linear_solver == LinearSolver::cg) {
    cg_.factorize(jacobian_);
    if (cg_.preconditioner().info() != Eigen::Success)
      return "the incomplete Cholesky preconditioner could not be computed (is the Jacobian positive definite?)";
    return std::nullopt;
  }
  blas::without_openmp_regions([&] { factor_.factorize(jacobian_); });
  if (factor_.info() != Eigen::Success) return "the Jacobian is not positive definite (CHOLMOD could not factorise it)";
  return std::nullopt;
}

template <int Dim>
std::optional<std::string> SolverOf<Dim>::solve_newton_system() {
  ScopedTimer timer(timings_.solve);
  if (settings_.linear_solver == LinearSolver::cg) return conjugate_gradients();
  delta_ = factor_.solve(-r_);
  return std::nullopt;
}

// J delta = -r from delta = 0, to cg_tolerance of |r|.
template <int Dim>
std::optional<std::string> SolverOf<Dim>::conjugate_gradients() {
  delta_ = cg_.solve(-r_);
  timings_.linear_iterations += cg_.iterations();
  if (cg_.info() == Eigen::Success) return std::nullopt;
  if (!std::isfinite(cg_.error()))
    return fmt::format("conjugate gradients broke down after {} iterations (is the Jacobian positive definite?)",
                       cg_.iterations());
  const std::string target =
      cg_.tolerance() > settings_.cg_tolerance
          ? fmt::format("{:.2e} (the adaptive forcing term; seepage.cg_tolerance = {:.2e})", cg_.tolerance(),
                        settings_.cg_tolerance)
          : fmt::format("seepage.cg_tolerance = {:.2e}", settings_.cg_tolerance);
  return fmt::format("conjugate gradients reached a relative residual of {:.2e} in {} iterations "
                     "(seepage.cg_max_iterations = {}), short of {}",
                     cg_.error(), cg_.iterations(), settings_.cg_max_iterations, target);
}

template <int Dim>
std::optional<double> SolverOf<Dim>::pressure_at(const Point& x) const {
  const auto s = sampler_.sample(u_, x);
  if (!s) return std::nullopt;
  return pressure_from_unknown(model_.law, s->value);
}

template <int Dim>
auto SolverOf<Dim>::pressure_gradient_at(const Point& x) const -> std::optional<Point> {
  const auto s = sampler_.sample(u_, x);
  if (!s) return std::nullopt;
  if (model_.law == Law::linear) return s->gradient;
  // grad p = grad P / (2 p)
  return s->gradient / (2.0 * std::sqrt(std::max(s->value, 1e-300)));
}

template <int Dim>
std::vector<double> SolverOf<Dim>::nodal_pressure() const {
  std::vector<double> p(static_cast<std::size_t>(u_.size()));
  for (Eigen::Index i = 0; i < u_.size(); ++i) p[i] = pressure_from_unknown(model_.law, u_[i]);
  return p;
}

template <int Dim>
auto SolverOf<Dim>::cell_flux() const -> std::vector<Point> {
  std::vector<Point> q(mesh_.num_cells());
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c) {
    const auto p = q1::evaluate(mesh_.corners(c), Point(Point::Zero()));
    Point grad = Point::Zero();
    for (int a = 0; a < cell_corners; ++a) grad += p.grad[a] * u_[mesh_.cells[c][a]];
    q[c] = -conductivity_[c] * grad;
  }
  return q;
}

template <int Dim>
auto SolverOf<Dim>::save_state() const -> State {
  return {time_,     steps_,    u_, u_previous_, dt_previous_, has_previous_, conductivity_, balance_,
          last_inflow_pressure_, last_inflow_flux_, fixed_by_, pressure_bc_slot_, open_pressure_};
}

// A mesh file may change under an unchanged scene text.
template <int Dim>
std::int64_t SolverOf<Dim>::mesh_fingerprint() const {
  checkpoint::Fingerprint f;
  f.add(mesh_.nodes);
  f.add(mesh_.cells);
  f.add(mesh_.cell_region);
  for (const auto& b : mesh_.boundaries) {
    f.add(b.name.data(), b.name.size());
    f.add(b.faces);
  }
  return f.value();
}

template <int Dim>
void SolverOf<Dim>::save(checkpoint::Out out) const {
  out.count("mesh_fingerprint", mesh_fingerprint());
  out.number("time", time_);
  out.count("steps", steps_);
  out.numbers("u", u_);
  out.numbers("u_previous", u_previous_);
  out.number("dt_previous", dt_previous_);
  out.flag("has_previous", has_previous_);
  out.numbers("conductivity", conductivity_);
  const auto b = out.group("balance");
  b.number("initial_stored", balance_.initial_stored);
  b.number("stored", balance_.stored);
  b.number("inflow_through_flux", balance_.inflow_through_flux);
  std::string names;
  for (const auto& n : balance_.pressure_boundaries) names += n + "\n";
  b.text("pressure_boundaries", names);
  b.numbers("inflow_through_pressure", balance_.inflow_through_pressure);
  b.numbers("last_inflow_pressure", last_inflow_pressure_);
  b.number("last_inflow_flux", last_inflow_flux_);
  out.counts("fixed_by", fixed_by_);
  out.counts("pressure_bc_slot", pressure_bc_slot_);
  out.number("open_pressure", open_pressure_);
}

template <int Dim>
void SolverOf<Dim>::load(const checkpoint::In& in) {
  if (in.count("mesh_fingerprint") != mesh_fingerprint())
    in.refuse("written for another seepage mesh (the mesh file changed since); finish the run with that mesh, or "
              "start afresh");
  const std::size_t nodes = mesh_.num_nodes();
  State s;
  s.time = in.number("time");
  s.steps = in.count("steps");
  s.u = in.vector("u", nodes);
  s.u_previous = in.vector("u_previous", nodes);
  s.dt_previous = in.number("dt_previous");
  s.has_previous = in.flag("has_previous");
  s.conductivity = in.numbers("conductivity", mesh_.num_cells());
  const auto b = in.group("balance");
  s.balance.initial_stored = b.number("initial_stored");
  s.balance.stored = b.number("stored");
  s.balance.inflow_through_flux = b.number("inflow_through_flux");
  const std::string names = b.text("pressure_boundaries");
  for (std::size_t start = 0, end; (end = names.find('\n', start)) != std::string::npos; start = end + 1)
    s.balance.pressure_boundaries.push_back(names.substr(start, end - start));
  const std::size_t slots = s.balance.pressure_boundaries.size();
  s.balance.inflow_through_pressure = b.numbers("inflow_through_pressure", slots);
  s.last_inflow_pressure = b.numbers("last_inflow_pressure", slots);
  s.last_inflow_flux = b.number("last_inflow_flux");
  s.fixed_by = in.counts<int>("fixed_by", nodes);
  s.pressure_bc_slot = in.counts<int>("pressure_bc_slot");
  s.open_pressure = in.number("open_pressure");
  const int conditions = static_cast<int>(model_.boundary_conditions.size());
  for (const int by : s.fixed_by)
    if (by < -1 || by > conditions) in.fail("fixed_by", fmt::format("a node fixed by condition {} of {}", by, conditions));
  for (const int slot : s.pressure_bc_slot)
    if (slot < -1 || slot >= static_cast<int>(slots)) in.fail("pressure_bc_slot", fmt::format("slot {} of {}", slot, slots));
  // Values no run holds (the numbers are finite already): the assembly
  // needs each cell's conductivity positive, as set_conductivity does.
  if (s.steps < 0) in.fail("steps", fmt::format("{} steps", s.steps));
  for (std::size_t c = 0; c < s.conductivity.size(); ++c)
    if (!(s.conductivity[c] > 0))
      in.fail("conductivity", fmt::format("cell {} has the conductivity {}, which no run holds: the checkpoint is "
                                          "damaged",
                                          c, s.conductivity[c]));
  restore_state(s);
}

template <int Dim>
void SolverOf<Dim>::restore_state(const State& s) {
  time_ = s.time;
  steps_ = s.steps;
  u_ = s.u;
  u_previous_ = s.u_previous;
  dt_previous_ = s.dt_previous;
  has_previous_ = s.has_previous;
  balance_ = s.balance;
  last_inflow_pressure_ = s.last_inflow_pressure;
  last_inflow_flux_ = s.last_inflow_flux;
  pressure_bc_slot_ = s.pressure_bc_slot;
  open_pressure_ = s.open_pressure;
  if (s.fixed_by != fixed_by_) {
    fixed_by_ = s.fixed_by;
    find_dirichlet_entries();
    ++conductivity_version_;
  }
  if (s.conductivity != conductivity_) {
    conductivity_ = s.conductivity;
    assemble_conductivity();
  }
}

template class SolverOf<2>;
template class SolverOf<3>;

}  // namespace outburst::seepage
