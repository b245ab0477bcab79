#include "seepage_fe/output.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "common/manifest.hpp"

namespace outburst::seepage {

namespace {

// ParaView's points and vectors have three components: plane ones get z = 0.
template <int Dim>
void append_xyz(std::vector<double>& to, const Eigen::Matrix<double, Dim, 1>& v) {
  if constexpr (Dim == 2)
    to.insert(to.end(), {v.x(), v.y(), 0.0});
  else
    to.insert(to.end(), {v.x(), v.y(), v.z()});
}

}  // namespace

template <int Dim>
Output::Output(const std::filesystem::path& directory, const output::RunInfo& info, const SolverOf<Dim>& solver,
               bool resume)
    : series_(directory, "seepage", info), history_path_(directory / "seepage_history.csv") {
  const MeshOf<Dim>& mesh = solver.mesh();
  std::vector<double> xyz;
  for (const auto& p : mesh.nodes) append_xyz<Dim>(xyz, p);
  std::vector<std::int64_t> cells;
  for (const auto& c : mesh.cells) cells.insert(cells.end(), c.begin(), c.end());
  series_.add_mesh("mesh", xyz, cells, Dim == 2 ? output::CellShape::quadrilateral : output::CellShape::hexahedron);

  if (resume) return;
  const char* volume = Dim == 2 ? "m3_per_m" : "m3";
  output::record_written(history_path_);
  history_.open(history_path_, std::ios::trunc);
  history_ << fmt::format("step,time_s,dt_s,substeps,cuts,iterations,stored_{},inflow_flux_{}", volume, volume);
  for (const auto& b : solver.balance().pressure_boundaries) history_ << ",inflow_" << b << "_" << volume;
  history_ << ",balance_error_relative\n";
  history_.flush();
}

void Output::save(checkpoint::Out out) const {
  series_.save(out.group("series"));
  checkpoint::save_length(out, "history_bytes", history_path_);
}

void Output::load(const checkpoint::In& in) {
  series_.load(in.group("series"));
  checkpoint::cut_back(in, "history_bytes", history_path_, history_);
}

template <int Dim>
void Output::snapshot(const SolverOf<Dim>& solver) {
  const bool gas = solver.model().law == Law::gas;
  output::Snapshot snap(solver.time());
  snap.add("mesh", {"p", output::Center::node, 1, "Pa", solver.nodal_pressure()});
  if (gas) {
    const auto& u = solver.unknown();
    snap.add("mesh", {"P", output::Center::node, 1, "Pa^2", {u.data(), u.data() + u.size()}});
  }
  snap.add("mesh", {gas ? "lambda" : "mobility", output::Center::cell, 1,
                    gas ? "m^2/(Pa^2 s)" : "m^2/(Pa s)", solver.conductivity()});
  std::vector<double> flux;
  for (const auto& q : solver.cell_flux()) append_xyz<Dim>(flux, q);
  snap.add("mesh", {"flux", output::Center::cell, 3, gas ? "m/s (standard gas volume)" : "m/s", flux});
  const auto& regions = solver.mesh().cell_region;
  snap.add("mesh", {"region", output::Center::cell, 1, "", {regions.begin(), regions.end()}});
  series_.write(snap);
}

template <int Dim>
void Output::history(const SolverOf<Dim>& solver, double dt, const StepReport& report) {
  const Balance& b = solver.balance();
  std::string line = fmt::format("{},{:.17g},{:.17g},{},{},{},{:.17g},{:.17g}", solver.steps(),
                                 solver.time(), dt, report.substeps, report.cuts,
                                 report.nonlinear_iterations, b.stored, b.inflow_through_flux);
  for (double v : b.inflow_through_pressure) line += fmt::format(",{:.17g}", v);
  line += fmt::format(",{:.6e}\n", b.initial_stored > 0 ? b.error() / b.initial_stored : b.error());
  history_ << line;
  history_.flush();
  if (!history_) throw std::runtime_error("cannot write seepage_history.csv: the disk may be full");
}

template Output::Output(const std::filesystem::path&, const output::RunInfo&, const SolverOf<2>&, bool);
template Output::Output(const std::filesystem::path&, const output::RunInfo&, const SolverOf<3>&, bool);
template void Output::snapshot(const SolverOf<2>&);
template void Output::snapshot(const SolverOf<3>&);
template void Output::history(const SolverOf<2>&, double, const StepReport&);
template void Output::history(const SolverOf<3>&, double, const StepReport&);

}  // namespace outburst::seepage
