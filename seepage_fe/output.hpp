#pragma once
// What a seepage run writes: the field time series for ParaView (nodal p and P,
// cell conductivity, flux and region) and a per-step history CSV with the gas
// balance, appended and flushed line by line so a crash loses nothing written.

#include <filesystem>
#include <fstream>
#include <memory>

#include "common/field_output.hpp"
#include "seepage_fe/solver.hpp"

namespace outburst::seepage {

class Output {
 public:
  Output(const std::filesystem::path& directory, const output::RunInfo& info, const Solver& solver);

  void snapshot(const Solver& solver);
  void history(const Solver& solver, double dt, const StepReport& report);

  const output::FieldSeries& series() const { return series_; }
  output::FieldSeries& series() { return series_; }

 private:
  output::FieldSeries series_;
  std::ofstream history_;
};

}  // namespace outburst::seepage
