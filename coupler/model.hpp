#pragma once
// A coupled gas-solid model assembled from a scene: both solvers, the mapping
// between them, their participants and the coupling, in the order the
// coupling needs (total initial stresses made effective, then the solid's
// settling stage). The `outburst` program and the tests build it alike.

#include <functional>
#include <memory>
#include <optional>

#include "common/program.hpp"
#include "coupler/coupling.hpp"
#include "coupler/gas_solid.hpp"
#include "coupler/mapping.hpp"
#include "coupler/scene_reader.hpp"
#include "mpm_solid/scene_reader.hpp"
#include "seepage_fe/scene_reader.hpp"

namespace outburst::coupling {

// Everything a coupled scene says, read and checked: plane (Dim = 2) or 3D.
template <int Dim>
struct CoupledSetup {
  SceneHeader header;
  seepage::SetupOf<Dim> seepage;
  mpm::Setup<Dim> solid;
  CouplingSetup coupling;
};

// A coupled scene's dimension: its MPM grid's (a size of two lengths or
// three). Its seepage mesh must have the same (refused at seepage.mesh).
int coupled_dimension(scene::Table root);

// Reads [scene], [seepage], [mpm] and [coupling] (the caller then rejects
// unused keys), and with Biot storage resolves the window pressure by the
// stability analysis, refusing (scene::Refusal) a scheme the scene names that
// cannot be stable at its window.
template <int Dim>
CoupledSetup<Dim> read_coupled_setup(scene::Table root);
// The same without that resolution: what the scene says, as it says it.
template <int Dim>
CoupledSetup<Dim> read_coupled_scene(scene::Table root);

// The poroelastic regime of every pair of MPM material (a heterogeneous one's
// softest and stiffest draws of the moduli apart) and seepage region,
// with the modes the seepage mesh carries along its longest extent
// (coupler/stability.hpp).
template <int Dim>
std::vector<stability::Regime> poroelastic_regimes(const CoupledSetup<Dim>& setup);

template <int Dim>
class CoupledModel {
 public:
  // The solid's settling stage runs here, unless `settle_later`: then
  // settle() runs it, or load() of a checkpoint of the run makes it needless.
  explicit CoupledModel(CoupledSetup<Dim> setup, bool settle_later = false);
  // Runs the settling stage, or carries on with it after load() of a
  // checkpoint taken during it; `pause` as for mpm::Solver<Dim>::settle.
  // False when paused.
  bool settle(const std::function<bool()>& pause);

  // One coupling window, cut short at `limit`.
  const WindowRecord& advance(double limit);

  // The coupling's settings (the mesh and particles of the scene's setup
  // live in the solvers now).
  const CouplingSetup& coupling_setup() const { return setup_.coupling; }
  seepage::SolverOf<Dim>& seepage() { return *seepage_; }
  mpm::Solver<Dim>& solid() { return *solid_; }
  const mpm::Solver<Dim>& solid() const { return *solid_; }
  const MeshMapping<Dim>& mapping() const { return *mapping_; }
  const SeepageParticipant<Dim>& seepage_side() const { return *seepage_side_; }
  const SolidParticipant<Dim>& solid_side() const { return *solid_side_; }
  const Coupling& coupling() const { return *coupling_; }
  // Both solvers, both participants and the coupling, to and from a
  // checkpoint taken between windows.
  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

  // Kinetic energy left by the settling stage over its peak (nullopt: no stage).
  std::optional<double> settled() const { return settled_; }

 private:
  CoupledSetup<Dim> setup_;
  std::unique_ptr<seepage::SolverOf<Dim>> seepage_;
  std::unique_ptr<mpm::Solver<Dim>> solid_;
  std::unique_ptr<MeshMapping<Dim>> mapping_;
  std::unique_ptr<SeepageParticipant<Dim>> seepage_side_;
  std::unique_ptr<SolidParticipant<Dim>> solid_side_;
  std::unique_ptr<Coupling> coupling_;
  std::optional<double> settled_;
};

}  // namespace outburst::coupling
