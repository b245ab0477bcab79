#pragma once
// What an MPM run writes: particles as a point cloud for ParaView (velocity,
// displacement, stress tensor, principal stresses, material, id) and a per-step
// history CSV (time step, particles, the energy account and its balance error).

#include <filesystem>
#include <fstream>
#include <optional>
#include <vector>

#include "common/field_output.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

// Largest and smallest principal stress: of a plane-strain state (zz
// included) in 2D, of the matrix in 3D (s_zz unused).
template <int Dim>
std::pair<double, double> principal_extremes(const Mat<Dim>& s, double s_zz);

// The histories' energies are per metre of depth in 2D (J_per_m columns), whole
// in 3D (J).
template <int Dim>
class Output {
 public:
  // `tracers`: ids of particles whose state is written every step to tracers.csv.
  // A restarted run (resume) writes no headers and appends once load() has
  // cut the histories back to the checkpoint.
  Output(const std::filesystem::path& directory, const output::RunInfo& info, std::vector<int> tracers,
         bool resume = false);
  void snapshot(const Solver<Dim>& solver);
  void history(const Solver<Dim>& solver, const StepInfo& step);
  const output::FieldSeries& series() const { return series_; }
  output::FieldSeries& series() { return series_; }
  // The energy books of the histories written so far; at the end of a run,
  // finish() warns in the log if they are open by more than 1 % of their
  // largest term (the method lost or, worse, created energy).
  const EnergyAudit& energy_audit() const { return audit_; }
  void finish() const;

  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

 private:
  std::filesystem::path history_path() const { return directory_ / "mpm_history.csv"; }
  std::filesystem::path tracer_path() const { return directory_ / "tracers.csv"; }

  std::filesystem::path directory_;
  output::FieldSeries series_;
  std::ofstream history_;
  std::optional<double> initial_total_;  // energy total when the history starts
  EnergyAudit audit_;
  std::vector<int> tracers_;
  std::ofstream tracer_file_;
};

}  // namespace outburst::mpm
