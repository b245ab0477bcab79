#include "mpm_solid/output.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "common/manifest.hpp"

namespace outburst::mpm {

namespace {
// The time step's own energy error above which a run is warned: the shipped
// scenes stay under it at Courant 0.3, and the error falls at first order
// with the step (tests/CMakeLists.txt).
constexpr double integration_warning = 0.1;
}  // namespace

template <int Dim>
std::pair<double, double> principal_extremes(const Mat<Dim>& s, double s_zz) {
  if constexpr (Dim == 2) {
    const double centre = 0.5 * (s(0, 0) + s(1, 1));
    const double radius = std::hypot(0.5 * (s(0, 0) - s(1, 1)), s(0, 1));
    return {std::max(centre + radius, s_zz), std::min(centre - radius, s_zz)};
  } else {
    const Vec<3> values = Eigen::SelfAdjointEigenSolver<Mat<3>>(s, Eigen::EigenvaluesOnly).eigenvalues();
    return {values[2], values[0]};
  }
}

template std::pair<double, double> principal_extremes<2>(const Mat<2>&, double);
template std::pair<double, double> principal_extremes<3>(const Mat<3>&, double);

namespace {
// "x_m,y_m" or "x_m,y_m,z_m": a column per axis, the name's {} the axis.
template <int Dim>
std::string per_axis(std::string_view name) {
  std::string columns;
  for (int d = 0; d < Dim; ++d)
    columns += fmt::format(fmt::runtime(std::string(d == 0 ? "" : ",") + std::string(name)), "xyz"[d]);
  return columns;
}
}  // namespace

template <int Dim>
Output<Dim>::Output(const std::filesystem::path& directory, const output::RunInfo& info, std::vector<int> tracers,
                    bool resume)
    : directory_(directory), series_(directory, "particles", info), tracers_(std::move(tracers)) {
  series_.add_point_grid("particles");
  if (resume) return;
  if (!tracers_.empty()) {
    output::record_written(tracer_path());
    tracer_file_.open(tracer_path(), std::ios::trunc);
    tracer_file_ << "time_s,tracer,particle_id," << per_axis<Dim>("{}_m") << "," << per_axis<Dim>("v{}_m_per_s")
                 << ",speed_m_per_s," << per_axis<Dim>("u{}_m") << ",sigma_max_Pa,sigma_min_Pa,plastic_strain,damage\n";
  }
  output::record_written(history_path());
  history_.open(history_path(), std::ios::trunc);
  const std::string unit = Dim == 2 ? "J_per_m" : "J";
  history_ << fmt::format("step,time_s,dt_s,particles,removed_total,kinetic_{0},strain_{0},gravity_{0},plastic_{0},"
                          "damage_{0},damping_{0},walls_{0},transfer_{0},integration_{0},left_grid_{0},"
                          "external_work_{0},balance_error_{0}\n",
                          unit);
  history_.flush();
}

template <int Dim>
void Output<Dim>::save(checkpoint::Out out) const {
  series_.save(out.group("series"));
  checkpoint::save_length(out, "history_bytes", history_path());
  if (!tracers_.empty()) checkpoint::save_length(out, "tracer_bytes", tracer_path());
  out.flag("has_initial_total", initial_total_.has_value());
  out.number("initial_total", initial_total_.value_or(0.0));
  audit_.save(out.group("audit"));
}

template <int Dim>
void Output<Dim>::load(const checkpoint::In& in) {
  series_.load(in.group("series"));
  checkpoint::cut_back(in, "history_bytes", history_path(), history_);
  if (!tracers_.empty()) checkpoint::cut_back(in, "tracer_bytes", tracer_path(), tracer_file_);
  initial_total_.reset();
  if (in.flag("has_initial_total")) initial_total_ = in.number("initial_total");
  audit_.load(in.group("audit"));
}

template <int Dim>
void Output<Dim>::snapshot(const Solver<Dim>& solver) {
  if (!initial_total_) {
    const Energies e = solver.energies();
    initial_total_ = e.total();
    audit_.record(e, solver.time());
  }
  const auto& p = solver.particles();
  const std::size_t n = p.size();
  std::vector<double> xyz, velocity, displacement, stress, s_max, s_min;
  xyz.reserve(3 * n);
  // ParaView's vectors have three components, and its symmetric tensors six
  // (xx, xy, xz, yy, yz, zz); a plane state's missing ones are zero.
  const auto three = [](std::vector<double>& out, const Vec<Dim>& v) {
    out.insert(out.end(), {v[0], v[1], Dim == 3 ? v[Dim - 1] : 0.0});
  };
  for (std::size_t i = 0; i < n; ++i) {
    three(xyz, p.x[i]);
    three(velocity, p.v[i]);
    three(displacement, p.x[i] - p.x0[i]);
    const Mat<Dim>& s = p.stress[i];
    const double zz = Dim == 2 ? p.stress_zz[i] : 0.0;
    if constexpr (Dim == 2)
      stress.insert(stress.end(), {s(0, 0), s(0, 1), 0.0, s(1, 1), 0.0, zz});
    else
      stress.insert(stress.end(), {s(0, 0), s(0, 1), s(0, 2), s(1, 1), s(1, 2), s(2, 2)});
    const auto [hi, lo] = principal_extremes<Dim>(s, zz);
    s_max.push_back(hi);
    s_min.push_back(lo);
  }
  output::Snapshot snap(solver.time());
  snap.set_points("particles", std::move(xyz));
  snap.add("particles", {"velocity", output::Center::node, 3, "m/s", std::move(velocity)});
  snap.add("particles", {"displacement", output::Center::node, 3, "m", std::move(displacement)});
  snap.add("particles", {"stress", output::Center::node, 6, "Pa (tension positive)", std::move(stress)});
  snap.add("particles", {"sigma_max", output::Center::node, 1, "Pa", std::move(s_max)});
  snap.add("particles", {"sigma_min", output::Center::node, 1, "Pa", std::move(s_min)});
  // The particles' own scalar fields, as their table says.
  p.for_each_field([&](const auto& field, const auto& values) {
    using Written = typename Particles<Dim>::Written;
    if constexpr (std::is_arithmetic_v<typename std::decay_t<decltype(values)>::value_type>) {
      if (field.written == Written::never || (values.empty() && field.written == Written::when_present)) return;
      std::vector<double> shown(n, field.fill);
      if (!values.empty()) std::copy(values.begin(), values.end(), shown.begin());
      snap.add("particles", {field.name, output::Center::node, 1, field.unit, std::move(shown)});
    }
  });
  series_.write(snap);
}

template <int Dim>
void Output<Dim>::history(const Solver<Dim>& solver, const StepInfo& step) {
  const Energies e = solver.energies();
  if (!initial_total_) initial_total_ = e.total();
  audit_.record(e, solver.time());
  history_ << fmt::format(
      "{},{:.17g},{:.17g},{},{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},"
      "{:.6g}\n",
      solver.steps(), solver.time(), step.dt, solver.particles().size(), solver.removed_particles(), e.kinetic,
      e.strain, e.gravity, e.plastic, e.damage, e.damping, e.walls, e.transfer, e.integration, e.left, e.external,
      e.total() - *initial_total_);
  history_.flush();
  if (!history_) throw std::runtime_error("cannot write mpm_history.csv: the disk may be full");
  if (tracers_.empty()) return;
  const auto& p = solver.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto found = std::find(tracers_.begin(), tracers_.end(), p.id[i]);
    if (found == tracers_.end()) continue;
    const Vec<Dim> u = p.x[i] - p.x0[i];
    const auto [hi, lo] = principal_extremes<Dim>(p.stress[i], Dim == 2 ? p.stress_zz[i] : 0.0);
    const auto components = [](const Vec<Dim>& v) { return fmt::format("{:.10g}", fmt::join(v, ",")); };
    tracer_file_ << fmt::format("{:.10g},{},{},{},{},{:.10g},{},{:.10g},{:.10g},{:.6g},{:.6g}\n", solver.time(),
                                found - tracers_.begin(), p.id[i], components(p.x[i]), components(p.v[i]),
                                p.v[i].norm(), components(u), hi, lo,
                                p.plastic_strain.empty() ? 0.0 : p.plastic_strain[i],
                                p.damage.empty() ? 0.0 : p.damage[i]);
  }
  tracer_file_.flush();
  if (!tracer_file_) throw std::runtime_error("cannot write tracers.csv: the disk may be full");
}

template <int Dim>
void Output<Dim>::finish() const {
  const double open = audit_.open_share(), step = audit_.integration_share();
  const char* unit = Dim == 2 ? "J/m" : "J";
  if (open > 0.01)
    spdlog::warn("the energy budget is open by {:.2g} % of its largest term ({:.3g} {}) at t = {:.4g} s: a "
                 "velocity changed where no book sees it, which is a defect of the solver; please report it with "
                 "the scene (docs/theory/energies.md; mpm_history.csv)",
                 100 * open, audit_.largest_term(), unit, audit_.worst_time());
  else
    spdlog::info("energy budget closed to {:.2g} % of its largest term ({:.3g} {}); the time step's own error at "
                 "most {:.2g} %",
                 100 * open, audit_.largest_term(), unit, 100 * step);
  if (step > integration_warning)
    spdlog::warn("the time step's own energy error reached {:.2g} % of the largest term ({:.3g} {}): a step too "
                 "close to the stable one, or a run gone unstable (integration_{} in mpm_history.csv)",
                 100 * step, audit_.largest_term(), unit, Dim == 2 ? "J_per_m" : "J");
}

template class Output<2>;
template class Output<3>;

}  // namespace outburst::mpm
