#pragma once
// What a seepage run writes: the field time series for ParaView (nodal p and P,
// cell conductivity, flux and region, on quadrilaterals or hexahedra) and a
// per-step history CSV with the gas balance, appended and flushed line by line
// so a crash loses nothing written. A restarted run (resume) writes no header
// and appends once load() has cut the history back to the checkpoint.
//
// Gas volumes in the history are per metre of depth in 2D (columns ending in
// _m3_per_m) and whole volumes in 3D (_m3).

#include <filesystem>
#include <fstream>
#include <memory>

#include "common/field_output.hpp"
#include "seepage_fe/solver.hpp"

namespace outburst::seepage {

class Output {
 public:
  template <int Dim>
  Output(const std::filesystem::path& directory, const output::RunInfo& info, const SolverOf<Dim>& solver,
         bool resume = false);

  template <int Dim>
  void snapshot(const SolverOf<Dim>& solver);
  template <int Dim>
  void history(const SolverOf<Dim>& solver, double dt, const StepReport& report);

  const output::FieldSeries& series() const { return series_; }
  output::FieldSeries& series() { return series_; }

  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

 private:
  output::FieldSeries series_;
  std::filesystem::path history_path_;
  std::ofstream history_;
};

}  // namespace outburst::seepage
