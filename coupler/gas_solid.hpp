#pragma once
// The gas-solid coupling of the outburst: the two solvers as coupling
// participants, and the permeability law that turns the solid's state into the
// seepage's conductivity.
//
// Stress split (model-notes section 2): total = effective - alpha p I, tension
// positive. The MPM solver carries the effective stress; the gas acts on the
// solid as the body force -alpha grad(p) V_p per particle. Tractions and
// initial stresses of an MPM body are therefore effective ones; a coupled
// scene may give total initial stresses and have alpha p0 added.
//
// Seepage is the first participant, the solid the second:
//   seepage -> solid: "pressure", nodal p [Pa] at the window's end; the solid
//     interpolates it linearly in time over the window, in space with the Q1
//     shape functions, at every MPM step.
//   solid -> seepage: per seepage cell, "occupancy" (solid volume fraction),
//     "stress" (volume-averaged effective stress xx, yy, xy [Pa]; in 3D xx,
//     yy, zz, yz, xz, xy) and "damage";
//     with Biot storage also "dilatation": the particles' volume change over
//     the window per cell area, which the seepage takes as the source
//     -alpha dilatation / window (linear Darcy law). With the fixed-stress
//     split the solid sends the volume change less (alpha / K_dr) times the
//     change of the pressure it felt, so that the seepage's extra storage
//     alpha^2 / K_dr cancels at convergence and what it takes depends only
//     on what the coupling hands it (an accelerated iteration needs that).

#include <array>
#include <optional>
#include <string_view>
#include <vector>

#include "coupler/coupling.hpp"
#include "coupler/mapping.hpp"
#include "coupler/stability.hpp"
#include "mpm_solid/solver.hpp"
#include "seepage_fe/solver.hpp"

namespace outburst::coupling {

// lambda = lambda0 exp(-beta sigma') f(D)  (paper eqs. 12 and 14, model-notes
// section 3): sigma' the largest effective compression (sigma_1 - alpha p of the
// paper, compression positive), f = 1 intact, xi damaged, xi' fully damaged.
struct PermeabilityLaw {
  double beta = 0.2e-6;       // [1/Pa] (the paper's 0.2 1/MPa)
  double xi = 5;              // damaged (0 < D < 1)
  double xi_full = 100;       // fragmented (D >= full_damage)
  double full_damage = 0.99;  // D counted as complete
  double max_exponent = 10;   // |beta sigma'| clamp: lambda within e^(+-10) of lambda0
  double operator()(double lambda0, double compression, double damage) const;
};

// How the gas pressure loads the solid. Both are the same force inside a
// body; they differ by alpha p on its surfaces:
//   body:   the body force -alpha grad(p) V_p (the paper's, model-notes
//           section 2): surfaces feel only the pressure drop the seepage
//           mesh resolves across them; right where surfaces see the open
//           pressure or rest on rigid rock (the outburst);
//   stress: alpha p enters each particle's total stress, so the pore
//           pressure also pushes on surfaces it cannot drain through (a
//           loading plate: Mandel's problem).
enum class GasForce { body, stress };

struct GasSolidSettings {
  double biot = 0.5;         // alpha
  GasForce force = GasForce::body;
  PermeabilityLaw permeability;
  bool permeability_coupling = true;  // off: lambda stays the scene's
  double open_below = 0.5;   // a cell with less solid than this fraction is open space
  double open_pressure = 1e5;  // [Pa] of open space
  bool biot_storage = false;   // the solid's volume change is a seepage source
  // Fixed-stress split (Kim, Tchelepi & Juanes 2011): the seepage carries the
  // extra storage beta = alpha^2 / K_dr and the source beta dp/dt of the
  // pressure the solid felt, so the staggered scheme is stable and its
  // iteration a contraction; the two cancel once the window has converged.
  // [1/Pa]; 0: off.
  double fixed_stress = 0;
  // The pore pressure the solid feels within a window: the ramp between its
  // ends, or its end value throughout (coupler/stability.hpp).
  stability::Pressure window_pressure = stability::Pressure::ramp;
};

// The fields the solid sends the seepage, each declared once: the solid's
// cell averaging, the seepage's storage and checkpoint, and the coupling's
// stacking and convergence measures (coupler/scene_reader.cpp) all run over
// this table. Seepage to solid goes one field, `pressure_field`.
enum class SolidField { occupancy, stress, damage, dilatation };
struct SolidFieldInfo {
  SolidField id;
  std::string_view name;  // the coupling's and the checkpoint's
  std::array<int, 2> components;  // values per seepage cell, in 2D and in 3D
  double start;           // what the seepage holds before the solid first sends it
  // The [coupling] key of its absolute convergence floor (the scene reader
  // reads each floor key once).
  std::string_view floor_key;
  // Whether a coupled run with these settings sends it (the scheme decides
  // whether anything is sent back at all: a one-way scheme sends nothing).
  bool (*sent)(const GasSolidSettings&);
  int components_in(int dim) const { return components[static_cast<std::size_t>(dim - 2)]; }
};
inline constexpr std::string_view pressure_field = "pressure";  // nodal p [Pa]
// In the order they stack.
inline constexpr std::array<SolidFieldInfo, 4> solid_fields{{
    {SolidField::occupancy, "occupancy", {1, 1}, 1.0, "fraction_floor", [](const GasSolidSettings&) { return true; }},
    {SolidField::stress, "stress", {3, 6}, 0.0, "stress_floor",
     [](const GasSolidSettings& g) { return g.permeability_coupling; }},
    {SolidField::damage, "damage", {1, 1}, 0.0, "fraction_floor",
     [](const GasSolidSettings& g) { return g.permeability_coupling; }},
    {SolidField::dilatation, "dilatation", {1, 1}, 0.0, "dilatation_floor",
     [](const GasSolidSettings& g) { return g.biot_storage; }},
}};
constexpr std::string_view name_of(SolidField field) {
  for (const auto& f : solid_fields)
    if (f.id == field) return f.name;
  return {};
}

template <int Dim>
class SeepageParticipant final : public Participant {
 public:
  SeepageParticipant(seepage::SolverOf<Dim>& solver, GasSolidSettings settings);
  std::string name() const override { return "seepage"; }
  void write(const std::string& field, const Eigen::VectorXd& values) override;
  Eigen::VectorXd read(const std::string& field) const override;
  void advance(double window) override;
  void save() override;
  void restore() override;

  // What it carries from window to window (the solid's last data and the
  // last window's size; the solver saves its own state), to and from a
  // checkpoint.
  void save_between_windows(checkpoint::Out out) const;
  void load_between_windows(const checkpoint::In& in);

  int open_cells() const { return open_cells_; }
  // The seepage solver's report of the last advance (sub-steps, cuts, iterations).
  const seepage::StepReport& last_report() const { return last_report_; }

 private:
  void apply_solid_state();

  seepage::SolverOf<Dim>& solver_;
  GasSolidSettings settings_;
  std::vector<double> lambda0_;  // the scene's conductivity per cell
  // What the solid last sent, per field of solid_fields (unsent ones keep
  // their start).
  std::array<Eigen::VectorXd, solid_fields.size()> received_;
  const Eigen::VectorXd& received(SolidField f) const { return received_[static_cast<std::size_t>(f)]; }
  // The size of the last advance: the solid's dilatation covers the window
  // it last took, which had this size (the previous iterate of this window,
  // or the previous window in a one-pass scheme).
  double last_size_ = 0;
  typename seepage::SolverOf<Dim>::State saved_;
  seepage::StepReport last_report_;
  int open_cells_ = 0;
};

template <int Dim>
class SolidParticipant final : public Participant {
 public:
  // `pressure` is the nodal p [Pa] at the start (the seepage's initial state).
  // Of `settings` it uses alpha, the gas force's form, Biot storage
  // ("dilatation" is tracked and sent only with it), the fixed-stress split
  // and the window pressure.
  SolidParticipant(mpm::Solver<Dim>& solver, const MeshMapping<Dim>& mapping, const GasSolidSettings& settings,
                   Eigen::VectorXd pressure, std::optional<double> fixed_time_step);
  std::string name() const override { return "solid"; }
  void write(const std::string& field, const Eigen::VectorXd& values) override;
  Eigen::VectorXd read(const std::string& field) const override;
  void advance(double window) override;
  void save() override;
  void restore() override;

  // Converts total initial stresses to effective: adds alpha p0 to each
  // particle's normal stresses (before the first step), p0 the initial
  // pressure of the region of the seepage cell holding it (`cell_pressure`):
  // nodes between regions (the face, between coal and tunnel) start at a mean,
  // which is not the pressure in the coal before it is exposed.
  void make_initial_stress_effective(const std::vector<double>& cell_pressure);
  // What it carries from window to window (the pressures at the window's
  // ends, the change felt, the cells the particles were last found in; the
  // solver saves its own state), to and from a checkpoint.
  void save_between_windows(checkpoint::Out out) const;
  void load_between_windows(const checkpoint::In& in);

  // The last advance: its last MPM step and the particles that left the grid.
  const mpm::StepInfo& last_window() const { return last_window_; }
  // Wall time spent reading the gas pressure at the particles before each
  // MPM step, since construction [s].
  double gas_force_seconds() const { return gas_force_seconds_; }

 private:
  void set_gas_force(double fraction);
  void compute_averages() const;
  void mark_window_start();

  mpm::Solver<Dim>& solver_;
  const MeshMapping<Dim>& mapping_;
  double biot_;
  GasForce force_;
  double fixed_stress_;  // beta [1/Pa]
  stability::Pressure window_pressure_;
  std::optional<double> fixed_time_step_;
  Eigen::VectorXd pressure_start_, pressure_end_, pressure_now_;
  Eigen::VectorXd felt_change_;  // the pressure felt at the last window's end less at its start
  std::vector<int> cell_hint_;  // per particle, the seepage cell it was last found in
  // The cell means it sends (solid_fields less occupancy, which is the
  // fraction itself), in stacking order.
  std::vector<SolidFieldInfo> averaged_;
  bool sends_dilatation_;
  std::vector<double> start_volume_;  // per particle id, at the window's start
  mpm::StepInfo last_window_{0};
  double gas_force_seconds_ = 0;
  typename mpm::Solver<Dim>::State saved_;
  Eigen::VectorXd saved_pressure_;
  mutable std::optional<typename MeshMapping<Dim>::Averages> averages_;  // of the current state
};

}  // namespace outburst::coupling
