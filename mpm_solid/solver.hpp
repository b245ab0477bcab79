#pragma once
// The explicit material point method on a fixed background grid: 2D plane
// strain (Dim = 2, quantities per metre of depth) or 3D (Dim = 3), one code.
//
// One step (update-stress-first, the paper's section 3; USL and MUSL move the
// stress update after the grid update), each pass in a file of passes/:
//   1. particles -> grid: mass and momentum (under USF with the FLIP/PIC
//      blend, mapped by the last step's 6, unless the particles changed
//      since)                                                scatter.cpp
//   2. grid velocities, walls applied                      grid_update.cpp
//   3. grid -> particles: velocity gradient; materials update stress
//      (Jaumann)                                     stress_and_forces.cpp
//   4. particles -> grid: internal force, gravity, external forces (ditto)
//   5. grid momentum update, walls applied        grid_update.cpp, walls.cpp
//   6. grid -> particles: velocity (FLIP/PIC blend) and position
//      (motion.cpp), and the census of what moved (census.cpp)
// The shape function and the update scheme are compiled into the step: the
// solver picks one specialised kernel at construction (solver.cpp), so
// neither costs a branch per particle. energy_books.cpp keeps the books,
// solver_state.cpp the state a checkpoint holds. docs/theory/mpm.md derives
// the step.

#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "mpm_solid/active_blocks.hpp"
#include "mpm_solid/energy_books.hpp"
#include "mpm_solid/grid.hpp"
#include "mpm_solid/material.hpp"
#include "mpm_solid/particles.hpp"
#include "mpm_solid/settings.hpp"

namespace outburst::mpm {

class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct StepInfo {
  double dt;
  std::size_t removed = 0;  // particles that left the grid this step
};

// Wall time the steps have spent in each of their parts, in seconds: where a
// run's time goes, and which part a second thread speeds up.
struct StepTimes {
  double map = 0;     // particles to grid: mass and momentum scattered (under USF and FLIP/PIC, in `motion`)
  double grid = 0;    // the threads' copies summed, ghosts folded, velocities and update, walls, platens
  double stress = 0;  // velocity gradients, the stress update, nodal forces scattered
  double motion = 0;  // grid to particles: velocities, positions, the census
  double total() const { return map + grid + stress + motion; }
};
// "particles to grid 18 %, grid 9 %, ... of 93.1 s".
std::string describe(const StepTimes& t);

// What the last pass over the particles in a step found: the work of the
// external forces over the step and the particles that went wrong or left.
// The same pass finds the fastest signal, max (c_p + |v_p|), over the
// particles that stay: the next stable step, without a pass of its own.
struct Census {
  double external_work = 0;
  long bad = 0, escaped = 0, runaway = 0;
  // Under USF, the particles whose stress the update left non-finite: the
  // update pass (split, the force scatter after it) checks them while they
  // are in cache, and bad counts only positions and velocities. Under USL
  // and MUSL the update comes last and bad counts the stresses too.
  long bad_stresses = 0;
  double fastest = 0;
  Census& operator+=(const Census& o) {
    external_work += o.external_work;
    bad += o.bad;
    bad_stresses += o.bad_stresses;
    escaped += o.escaped;
    runaway += o.runaway;
    fastest = std::max(fastest, o.fastest);
    return *this;
  }
};

// The indices of each material's particles, in order.
template <int Dim>
std::vector<std::vector<int>> material_members(const Particles<Dim>& particles, std::size_t materials);

// Largest stable step: courant h / max over particles of (c_p + |v_p|), c_p
// the P-wave speed of each particle's material at its current density and
// with its draw of the moduli (a heterogeneous material's modulus_scale).
template <int Dim>
double stable_time_step(const std::vector<std::unique_ptr<Material<Dim>>>& materials,
                        const Particles<Dim>& particles, double h, double courant);

struct SolverMemory {
  std::size_t particles, grid;  // [bytes]
};

template <int Dim>
class Solver {
 public:
  Solver(Grid<Dim> grid, std::vector<std::unique_ptr<Material<Dim>>> materials, Particles<Dim> particles,
         Settings<Dim> settings);

  // The free function's step for this solver's particles and grid (as the
  // last step's move found it, or computed afresh).
  double stable_time_step() const;
  // One explicit step; SimulationError (naming the step, particle and field)
  // if a particle's state becomes non-finite or it outruns its P wave.
  StepInfo step(double dt);

  double time() const { return time_; }
  long steps() const { return steps_; }
  const StepTimes& step_times() const { return times_; }
  std::size_t removed_particles() const { return removed_; }
  const Grid<Dim>& grid() const { return grid_; }
  const Settings<Dim>& settings() const { return settings_; }
  // Switch local damping on (quasi-static stage) or off (dynamic stage).
  void set_local_damping(double alpha) { settings_.local_damping = alpha; }
  const std::vector<std::unique_ptr<Material<Dim>>>& materials() const { return materials_; }

  // Read access, and the per-particle external force another program sets.
  const Particles<Dim>& particles() const { return particles_; }
  // Created (zero) on first call, with the scene's tractions.
  std::vector<Vec<Dim>>& external_force();
  // The per-particle pore pressure that enters the total stress, created
  // (zero) on first call; scenes that never call it carry no such field.
  std::vector<double>& pore_pressure();
  // Adds s_p to each particle's normal stresses before the first step (alpha
  // p when a coupled scene gives total stresses); in 2D to the in-plane ones,
  // and 2 nu s_p to the out-of-plane one: the initial state stays one of
  // plane strain, whose sigma_zz = nu (sigma_xx + sigma_yy) holds for the
  // stress the solid feels.
  void shift_initial_stress(const std::vector<double>& per_particle);

  struct State {
    double time;
    long steps;
    std::size_t removed;
    Particles<Dim> particles;
    Energies dissipated;
    std::vector<double> platen_displacement;
  };
  State save_state() const { return {time_, steps_, removed_, particles_, dissipated_, platen_displacement_}; }
  void restore_state(const State& s);
  // The state to and from a checkpoint (a run continued by --restart), the
  // settling stage's progress included. A checkpoint of the dynamic stage
  // removes the supports as settle() did; the stage need not run again.
  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

  // Runs the quasi-static stage (steps of `fixed_step` or the CFL step), then
  // starts the dynamic one: supports removed, material at rest, clock and
  // energy books at zero, local damping back to the scene's. Returns the
  // kinetic energy left at the end of the stage, relative to its largest.
  // `pause`, called after each step of the stage (time() is the stage's
  // clock then), may stop it by returning true: settle() then returns
  // nullopt, and called again, after load() of a checkpoint taken then if
  // need be, carries on where it stopped.
  std::optional<double> settle(const Settling& stage, std::optional<double> fixed_step,
                               const std::function<bool()>& pause = {});

  // How far each platen has moved along its axis since t = 0 [m].
  const std::vector<double>& platen_displacement() const { return platen_displacement_; }
  // The force each platen exerted on the material in the last step, along its
  // axis [N; N/m in 2D]: its load, or the reaction of a plate moved at a set
  // speed.
  const std::vector<double>& platen_force() const { return platen_force_; }

  // The grid nodes of the last mapping's active blocks (ActiveBlocks): those
  // the next step's passes run over when USF's move mapped ahead, else those
  // the last step's ran over.
  std::size_t active_nodes() const { return active_.active_nodes(); }
  // Nonzero nodal values outside those nodes, and in the threads' scatter
  // buffers anywhere (on those nodes, when mapped ahead, the next step's
  // sums): none between steps, the invariant the grid's passes rely on
  // (checked by the tests).
  std::size_t stray_nodal_values() const;
  // The velocities (before and after the last step's grid update) of ghost
  // nodes beyond fixed and roller walls that are not their mirror's
  // reflected: none, the invariant the energy books rely on, as fold_ghosts
  // put each ghost's mass into its mirror (checked by the tests). Active
  // blocks come and go across a mirroring wall whole, ghost and mirror
  // together (ActiveBlocks), so it holds after USF's mapping ahead too.
  std::size_t unmirrored_ghosts() const;

  // Memory held now [bytes]: by the particles (every field, and the per-step
  // arrays sized by them) and by the grid (the nodal arrays, one set per thread).
  using Memory = SolverMemory;
  Memory memory() const;

  Energies energies() const;
  double kinetic_energy() const;  // the part of energies() a settling stage watches [J; J/m in 2D]
  double strain_energy() const;
  double gravitational_energy() const;  // from the grid's lower corner [J; J/m in 2D]
  double stored_energy() const { return strain_energy() + gravitational_energy(); }

 private:
  template <class Shape, Scheme S, bool Apic>
  void step_kernel(double dt);
  template <class Shape, bool Apic>
  void scatter_mass_momentum();
  // Check: count the particles whose stress is non-finite (USF's split
  // passes, whose update just wrote them), returned.
  template <class Shape, bool Check>
  long scatter_forces();
  template <class Shape>
  long update_and_scatter(double dt);  // the particles whose stress it left non-finite
  template <class Shape>
  void gather_velocity_gradient();
  template <class Shape>
  void smooth_dilatation();
  template <class Shape, bool Apic, bool Move>
  void gather_motion(double dt);
  // gather_motion's two transfers; the calling thread's census and sums.
  template <class Shape, bool Move>
  void gather_affine_motion(double dt, Census& census, double& lost, double& work);
  template <class Shape, bool Move>
  void gather_blended_motion(double dt, Census& census, double& lost, double& work);
  void grid_velocities();
  void grid_update(double dt);
  double apply_walls(std::vector<Vec<Dim>>& velocity) const;
  // apply_walls' obstacles (their friction's work added to friction_work) and
  // ghost rows beyond fixed and roller walls.
  void constrain_obstacles(std::vector<Vec<Dim>>& velocity, double& friction_work) const;
  void mirror_ghosts(std::vector<Vec<Dim>>& velocity) const;
  void apply_platens(std::vector<Vec<Dim>>& velocity, double impulse, double dt);
  using Kernel = void (Solver::*)(double);
  Kernel pick_kernel() const;
  void create_grid_fields();
  void create_transfer_fields();
  void find_obstacle_nodes();
  void find_platen_nodes();
  void remove_supports();  // the settling stage is over
  // Folds what the particles gave the ghost nodes beyond fixed and roller
  // walls into their mirrors inside (mass, if given, and vectors), and calls
  // refresh(node) at each node folded into, after its fold.
  template <class F>
  void fold_ghosts(std::vector<double>* mass, std::vector<Vec<Dim>>& vectors, F&& refresh) const;
  // f(node) over the nodes of the layer `row` across `axis` (a row of nodes
  // in 2D, a plane in 3D), ghosts included, in active blocks: elsewhere every
  // nodal value is zero, which walls and folds leave so.
  template <class F>
  void over_layer(int axis, int row, F&& f) const;
  // f(node, mirror) over the nodes `depth` rows beyond wall `side` (0: its
  // wall row), as over_layer visits them; mirror the node as far inside.
  template <class F>
  void over_ghost_layer(int side, int depth, F&& f) const;
  void update_stresses(double dt);
  // At most chunk_lanes particles; Stresses: whether their stresses are
  // checked here (USL, MUSL) or were where the update wrote them (USF).
  template <bool Stresses>
  void count(int start, int lanes, double dt, Census& census) const;
  Census move_particles(double dt);
  void remove_escaped(const Census& census, StepInfo& info);
  void rebuild_material_groups();

  Grid<Dim> grid_;
  std::vector<std::unique_ptr<Material<Dim>>> materials_;
  Particles<Dim> particles_;
  Settings<Dim> settings_;
  Kernel kernel_ = nullptr;
  // Every particle's stress update reads only its own fields, and no
  // smoothing of the dilatation runs between the gather and the update: USF
  // fuses them with the force scatter (update_and_scatter).
  bool pointwise_ = false;

  std::vector<std::vector<int>> members_;  // particle indices per material
  std::vector<double> wave_speed_squared_;  // per material, for the runaway check
  std::vector<double> p_modulus_;           // lambda + 2 G per material, for the stable step
  // max (c_p + |v_p|) over the particles now, as the last move counted it; 0
  // when the particles changed since (restored, loaded, set at rest).
  double fastest_ = 0;
  // Square of the speed beyond which particle i is running away.
  double runaway_speed_squared(int i) const;
  double empty_node_mass_ = 0;

  // Grid fields; per-thread copies of the scattered ones avoid locks.
  std::vector<double> mass_;
  std::vector<Vec<Dim>> momentum_, force_, velocity_, velocity_new_;
  int threads_ = 1;
  std::vector<std::vector<double>> thread_mass_;     // of threads 1, 2, ...
  std::vector<std::vector<Vec<Dim>>> thread_vector_;
  std::vector<std::array<int, Dim>> node_ij_;  // grid coordinates of each node
  ActiveBlocks<Dim> active_;  // where the nodal arrays may be nonzero
  // Zero the sums (mass, momentum, force) there before a new mapping; run by
  // every thread of a parallel region.
  void clear_sums();
  void clear_dropped();  // zero the velocities where the mapping no longer reaches
  // The grid's mass and momentum (the threads' copies not yet summed) are the
  // particles' as they are now: USF's move mapped them for the next step.
  // Whatever changes the particles between steps discards that mapping.
  bool mapped_ahead_ = false;
  void discard_mapping();
  // Nodes whose mass counts once (in the damping's work): not the ghosts
  // beyond a fixed or roller wall, whose share fold_ghosts moved inside.
  std::vector<char> counted_;
  std::vector<Vec<Dim>> displacement_;         // of each particle over the step
  struct ObstacleNode {
    std::size_t node;
    Vec<Dim> normal;  // unit, pointing into the obstacle
  };
  std::vector<std::vector<ObstacleNode>> obstacle_nodes_;  // per obstacle, in node order
  std::vector<std::vector<std::size_t>> platen_nodes_;  // the nodes each platen holds
  std::vector<double> platen_displacement_;
  std::vector<double> platen_force_;
  Census census_;  // of the last step's move

  double time_ = 0;
  long steps_ = 0;
  StepTimes times_;
  std::size_t removed_ = 0;
  Energies dissipated_;  // only the accumulated members are used
  bool settled_ = false;  // a settling stage ran: its supports are gone
  // Of the settling stage so far: the largest kinetic energy and the last [J; J/m in 2D].
  double settling_peak_ = 0, settling_kinetic_ = 0;
};

}  // namespace outburst::mpm
