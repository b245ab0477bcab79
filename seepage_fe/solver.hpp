#pragma once
// The implicit seepage solver: Q1 finite elements in space, backward Euler or
// variable-step BDF2 in time, Newton (with a line search) or Picard for the
// nonlinear storage, CHOLMOD for the linear systems with the symbolic
// factorisation computed once (or, as Settings::linear_solver asks,
// conjugate gradients with an incomplete Cholesky preconditioner, or with
// CHOLMOD's factor of an earlier Jacobian).
//
// Public face, in the order a driver uses it:
//   Solver s(mesh, model, settings);
//   s.set_conductivity(per_cell);   // optional: the coupler's lambda per cell
//   s.advance(dt);                  // one step, cut and retried if it fails
//   s.pressure_at(x), s.pressure_gradient_at(x)
//   s.sampler().sample(field, x)          // any nodal field at a point
//   auto st = s.save_state(); ...; s.restore_state(st);   // coupling sub-iterations

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/CholmodSupport>
#include <Eigen/Core>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include "common/checkpoint.hpp"
#include "seepage_fe/mesh.hpp"
#include "seepage_fe/model.hpp"
#include "seepage_fe/sampling.hpp"

namespace outburst::seepage {

// Volumetric source s(x, t) in stored units per volume per second (for the gas
// law: standard gas volume per coal volume per second). Used by manufactured
// solutions; a scene has none.
template <int Dim>
using SourceFunctionOf = std::function<double(const Eigen::Matrix<double, Dim, 1>&, double)>;
using SourceFunction = SourceFunctionOf<2>;

class StepFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct StepReport {
  int substeps = 0;           // accepted steps taken to cover the requested dt
  int cuts = 0;               // failed attempts that were halved and retried
  int nonlinear_iterations = 0;
  double smallest_substep = 0;
};

// Gas (or fluid) balance since t = 0, per unit depth (3D: in all). Volumes are
// standard gas volumes for the gas law and fluid volumes for the linear law
// [m^3/m; 3D: m^3].
struct Balance {
  double initial_stored = 0;
  double stored = 0;
  double inflow_through_flux = 0;  // flux boundaries and sources
  std::vector<std::string> pressure_boundaries;
  std::vector<double> inflow_through_pressure;  // per pressure boundary; < 0: outflow
  // stored - initial - all inflow: zero up to the nonlinear solver tolerance.
  double error() const;
  double total_outflow() const;  // through pressure boundaries, > 0 when gas leaves
};

// How CHOLMOD factorises the Jacobian: its mode and fill-reducing ordering
// ("cholmod_default": AMD, and METIS too when AMD fills in much).
struct Factorisation {
  enum class Mode { simplicial, supernodal };
  enum class Ordering { amd, metis, nesdis, cholmod_default };
  Mode mode;
  Ordering ordering;
  std::string name() const;  // "supernodal/nesdis"
};
// The one the solver picks for a Jacobian of this many unknowns.
Factorisation factorisation_for(std::size_t unknowns, int dim);
using Cholmod = Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower>;
// Sets the mode and ordering, before analyzePattern.
void configure(Cholmod& factor, Factorisation f);

// A CHOLMOD factor computed elsewhere as the preconditioner of Eigen's
// conjugate gradients: compute() and factorize() leave it as it is, so it may
// be the factor of an earlier matrix (the lagged linear solver's).
class FactorPreconditioner {
 public:
  template <typename Matrix>
  FactorPreconditioner& analyzePattern(const Matrix&) { return *this; }
  template <typename Matrix>
  FactorPreconditioner& factorize(const Matrix&) { return *this; }
  template <typename Matrix>
  FactorPreconditioner& compute(const Matrix&) { return *this; }
  void use(const Cholmod* factor) { factor_ = factor; }
  template <typename Rhs>
  Eigen::VectorXd solve(const Rhs& b) const { return factor_->solve(b); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  const Cholmod* factor_ = nullptr;
};

// Wall time spent in each part of the solver [s], for benchmarks and studies.
struct Timings {
  double assembly = 0;       // conductivity matrix
  double residual = 0;       // residual evaluations, including line search trials
  double jacobian = 0;       // building the Jacobian values
  double factorization = 0;  // CHOLMOD numeric factorisation, or the incomplete Cholesky factor
  double solve = 0;          // triangular solves, or the conjugate gradient iterations (lagged: on the factor)
  double total_step = 0;     // everything inside advance()
  long factorizations = 0;
  long nonlinear_iterations = 0;
  long residual_evaluations = 0;
  long linear_iterations = 0;  // conjugate gradient iterations
  long lagged_renewals = 0;    // lagged factors renewed for their iterations: past half the allowance
  long lagged_fallbacks = 0;   // ... and past all of it (solved directly)
};

// In Dim = 2 (plane, per unit depth) or 3 dimensions.
template <int Dim>
class SolverOf {
 public:
  using Point = typename MeshOf<Dim>::Point;
  static constexpr int cell_corners = MeshOf<Dim>::cell_corners;

  SolverOf(MeshOf<Dim> mesh, Model model, Settings settings);
  // The sampler and the factorisation refer into the solver: it stays put.
  SolverOf(const SolverOf&) = delete;
  SolverOf& operator=(const SolverOf&) = delete;

  // Advance by dt; a failing step is halved and retried up to max_step_cuts times,
  // then StepFailure explains what failed and where.
  StepReport advance(double dt);
  double time() const { return time_; }
  long steps() const { return steps_; }

  // ---- what a coupling driver reads and writes
  void set_conductivity(const std::vector<double>& per_cell);
  const std::vector<double>& conductivity() const { return conductivity_; }
  void set_source(SourceFunctionOf<Dim> source) { source_ = std::move(source); }
  // A source per cell, constant over each step, in the units of SourceFunction
  // (the coupler's Biot storage term -alpha d(eps_v)/dt); added to any
  // source function. Empty: none.
  void set_cell_source(std::vector<double> per_cell);
  // Adds `per_pressure` [1/Pa] to the storage coefficient everywhere (linear
  // law, before the first step): the coupler's fixed-stress stabilisation,
  // whose matching source it supplies itself.
  void add_storage(double per_pressure);
  // Nodes touching open space (the tunnel, a cavity the coal has left) held at
  // `pressure` [Pa], on top of the scene's pressure boundaries; the gas they
  // take is booked as outflow to "open space". Replaces the previous set.
  void set_open_nodes(const std::vector<char>& open, double pressure);
  // Replace the initial nodal pressures p [Pa] (before the first step only).
  void set_initial_pressure(const std::vector<double>& nodal_p);
  // p [Pa] and grad p [Pa/m] at any point of the mesh; nullopt outside it.
  std::optional<double> pressure_at(const Point& x) const;
  std::optional<Point> pressure_gradient_at(const Point& x) const;

  struct State {
    double time;
    long steps;
    Eigen::VectorXd u, u_previous;
    double dt_previous;
    bool has_previous;
    std::vector<double> conductivity;
    Balance balance;
    std::vector<double> last_inflow_pressure;  // BDF2 flux quadrature memory
    double last_inflow_flux;
    std::vector<int> fixed_by;  // which condition holds each node (open space included)
    std::vector<int> pressure_bc_slot;
    double open_pressure;
  };
  State save_state() const;
  void restore_state(const State& state);
  // The state to and from a checkpoint (a run continued by --restart).
  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

  // ---- results
  const MeshOf<Dim>& mesh() const { return mesh_; }
  // Reads nodal fields of this mesh at points, and finds the cell of a point.
  const SamplerOf<Dim>& sampler() const { return sampler_; }
  const Model& model() const { return model_; }
  const Eigen::VectorXd& unknown() const { return u_; }  // P (gas) or p (linear)
  std::vector<double> nodal_pressure() const;           // p [Pa]
  std::vector<Point> cell_flux() const;                 // -k grad u at cell centres [m/s]
  const Balance& balance() const { return balance_; }
  const Timings& timings() const { return timings_; }
  const Settings& settings() const { return settings_; }

  // How CHOLMOD factorises (with Settings::linear_solver direct).
  const Factorisation& factorisation() const { return factorisation_; }
  // The current Jacobian (for benchmarks that time a bare factorisation of it).
  const Eigen::SparseMatrix<double>& jacobian() const { return jacobian_; }
  // The next Newton iteration factorises afresh (benchmarks time runs of the
  // lagged solver from their first factorisation).
  void drop_factorisation() { factor_key_ = {}; }

 private:
  void setup_system();
  void restart_balance();
  void assemble_conductivity();
  void set_boundary_values(double t, Eigen::VectorXd& u) const;
  void load_vector(double t, Eigen::VectorXd& f) const;
  double residual(const Eigen::VectorXd& u, double a0, double h);
  void build_jacobian(const Eigen::VectorXd& u, double a0, double h);
  // One attempt at a step of size h; on failure returns the reason.
  std::optional<std::string> try_step(double h, int& iterations);
  // delta_ = -J^-1 r_ for the Jacobian at u, built and factorised as the
  // linear solver needs; on failure the reason.
  std::optional<std::string> newton_direction(const Eigen::VectorXd& u, double a0, double h);
  // Factorises jacobian_ (CHOLMOD or incomplete Cholesky); on failure the reason.
  std::optional<std::string> factorise();
  // delta_ = -J^-1 r_ by the factorisation (or cg_'s iterations) of jacobian_.
  std::optional<std::string> solve_newton_system();
  std::optional<std::string> conjugate_gradients();
  // delta_ by conjugate gradients preconditioned by factor_ (of an earlier
  // Jacobian); false when they need more than lag_max_iterations.
  bool lagged_conjugate_gradients();
  // The relative residual conjugate gradients solve the next Newton system to.
  void set_linear_tolerance(double tolerance);
  void accept_step(double h, double a0, double a2);

  MeshOf<Dim> mesh_;
  Model model_;
  Settings settings_;
  SamplerOf<Dim> sampler_;

  // Geometry, computed once.
  std::vector<Eigen::Matrix<double, cell_corners, cell_corners>> cell_stiffness_;  // unit conductivity
  std::vector<Eigen::Matrix<double, cell_corners, 1>> cell_lumped_;  // int N_a dA (3D: dV) per cell
  Eigen::VectorXd capacity_;                                          // sum over cells of c * int N_a
  std::vector<std::array<int, cell_corners * cell_corners>> scatter_;  // cell entry -> matrix value index
  std::vector<int> diagonal_;                    // node -> value index of (i, i)

  // Boundary conditions: per node, the condition index fixing it (or -1).
  std::vector<int> fixed_by_;
  std::vector<int> pressure_bc_slot_;  // condition index -> slot in balance vectors
  std::vector<int> dirichlet_zero_;    // value indices zeroed in the Jacobian
  std::vector<int> dirichlet_diagonal_;
  void find_dirichlet_entries();
  std::int64_t mesh_fingerprint() const;
  std::vector<int> boundary_fixed_by_;  // fixed_by_ as the scene's conditions alone set it
  double open_pressure_ = 0;

  std::vector<double> conductivity_;
  long conductivity_version_ = 0;
  Eigen::SparseMatrix<double> stiffness_;  // K = sum_e k_e K_e
  Eigen::SparseMatrix<double> jacobian_;
  Factorisation factorisation_{};
  Cholmod factor_;
  // Eigen's conjugate gradients on the whole (column-major, so
  // single-threaded: Eigen's threaded product, on row-major matrices,
  // measured slower on 2 cores, 30x at 1e4 unknowns and 1.2x at 1e6) matrix.
  // Its incomplete Cholesky factor in natural order: on a mesh numbered along
  // its rows it needs fewer iterations than AMD's (seepage-benchmark's square:
  // 55 against 87 at 1e5 unknowns, 18 against 27 at 1e4).
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::NaturalOrdering<int>>>
      cg_;
  // The lagged solver's iterations on factor_ while jacobian_ moves on.
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, FactorPreconditioner> lagged_cg_;
  // What factor_ was computed for. The Jacobian is h K + diag(a0 c S'(u)):
  // with h and K (its version) kept, only the diagonal has moved since.
  struct FactorKey {
    double h = -1, a0 = 0;
    long version = -1;
  } factor_key_;

  SourceFunctionOf<Dim> source_;
  std::vector<double> cell_source_;

  // State.
  double time_ = 0;
  long steps_ = 0;
  Eigen::VectorXd u_, u_previous_;
  double dt_previous_ = 0;
  bool has_previous_ = false;
  Balance balance_;
  std::vector<double> last_inflow_pressure_;
  double last_inflow_flux_ = 0;

  // Work vectors of the current step.
  Eigen::VectorXd trial_, history_, load_, r_, delta_, candidate_;
  double residual_scale_ = 0;
  Timings timings_;
};

using Solver = SolverOf<2>;
using Solver3 = SolverOf<3>;

}  // namespace outburst::seepage
