#pragma once
// What a seepage run writes: the field time series for ParaView (nodal p and P,
// cell conductivity, flux and region) and a per-step history CSV with the gas
// balance, appended and flushed line by line so a crash loses nothing written.
// A restarted run (resume) writes no header and appends once load() has cut
// the history back to the checkpoint.

#include <filesystem>
#include <fstream>
#include <memory>

#include "common/field_output.hpp"
#include "seepage_fe/solver.hpp"

namespace outburst::seepage {

class Output {
 public:
  Output(const std::filesystem::path& directory, const output::RunInfo& info, const Solver& solver,
         bool resume = false);

  void snapshot(const Solver& solver);
  void history(const Solver& solver, double dt, const StepReport& report);

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
