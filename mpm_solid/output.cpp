#include "mpm_solid/output.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace outburst::mpm {

namespace {
// The time step's own energy error above which a run is warned: the shipped
// scenes stay under it at Courant 0.3, and the error falls at first order
// with the step (tests/CMakeLists.txt).
constexpr double integration_warning = 0.1;
}  // namespace

std::pair<double, double> principal_extremes(const Mat<2>& s, double s_zz) {
  const double centre = 0.5 * (s(0, 0) + s(1, 1));
  const double radius = std::hypot(0.5 * (s(0, 0) - s(1, 1)), s(0, 1));
  return {std::max(centre + radius, s_zz), std::min(centre - radius, s_zz)};
}

Output::Output(const std::filesystem::path& directory, const output::RunInfo& info, std::vector<int> tracers,
               bool resume)
    : directory_(directory), series_(directory, "particles", info), tracers_(std::move(tracers)) {
  series_.add_point_grid("particles");
  if (resume) return;
  if (!tracers_.empty()) {
    tracer_file_.open(tracer_path(), std::ios::trunc);
    tracer_file_ << "time_s,tracer,particle_id,x_m,y_m,vx_m_per_s,vy_m_per_s,speed_m_per_s,ux_m,uy_m,"
                    "sigma_max_Pa,sigma_min_Pa,plastic_strain,damage\n";
  }
  history_.open(history_path(), std::ios::trunc);
  history_ << "step,time_s,dt_s,particles,removed_total,kinetic_J_per_m,strain_J_per_m,gravity_J_per_m,"
              "plastic_J_per_m,damage_J_per_m,damping_J_per_m,walls_J_per_m,transfer_J_per_m,integration_J_per_m,"
              "left_grid_J_per_m,"
              "external_work_J_per_m,balance_error_J_per_m\n";
  history_.flush();
}

void Output::save(checkpoint::Out out) const {
  series_.save(out.group("series"));
  checkpoint::save_length(out, "history_bytes", history_path());
  if (!tracers_.empty()) checkpoint::save_length(out, "tracer_bytes", tracer_path());
  out.flag("has_initial_total", initial_total_.has_value());
  out.number("initial_total", initial_total_.value_or(0.0));
  audit_.save(out.group("audit"));
}

void Output::load(const checkpoint::In& in) {
  series_.load(in.group("series"));
  checkpoint::cut_back(in, "history_bytes", history_path(), history_);
  if (!tracers_.empty()) checkpoint::cut_back(in, "tracer_bytes", tracer_path(), tracer_file_);
  initial_total_.reset();
  if (in.flag("has_initial_total")) initial_total_ = in.number("initial_total");
  audit_.load(in.group("audit"));
}

void Output::snapshot(const Solver& solver) {
  if (!initial_total_) {
    const Energies e = solver.energies();
    initial_total_ = e.total();
    audit_.record(e, solver.time());
  }
  const auto& p = solver.particles();
  const std::size_t n = p.size();
  std::vector<double> xyz, velocity, displacement, stress, s_max, s_min;
  xyz.reserve(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    xyz.insert(xyz.end(), {p.x[i].x(), p.x[i].y(), 0.0});
    velocity.insert(velocity.end(), {p.v[i].x(), p.v[i].y(), 0.0});
    const Vec<2> u = p.x[i] - p.x0[i];
    displacement.insert(displacement.end(), {u.x(), u.y(), 0.0});
    const Mat<2>& s = p.stress[i];
    stress.insert(stress.end(), {s(0, 0), s(0, 1), 0.0, s(1, 1), 0.0, p.stress_zz[i]});
    const auto [hi, lo] = principal_extremes(s, p.stress_zz[i]);
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
    using Written = Particles<2>::Written;
    if constexpr (std::is_arithmetic_v<typename std::decay_t<decltype(values)>::value_type>) {
      if (field.written == Written::never || (values.empty() && field.written == Written::when_present)) return;
      std::vector<double> shown(n, field.fill);
      if (!values.empty()) std::copy(values.begin(), values.end(), shown.begin());
      snap.add("particles", {field.name, output::Center::node, 1, field.unit, std::move(shown)});
    }
  });
  series_.write(snap);
}

void Output::history(const Solver& solver, const StepInfo& step) {
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
    const Vec<2> u = p.x[i] - p.x0[i];
    const auto [hi, lo] = principal_extremes(p.stress[i], p.stress_zz[i]);
    tracer_file_ << fmt::format("{:.10g},{},{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.6g},{:.6g}\n",
                                solver.time(), found - tracers_.begin(), p.id[i], p.x[i].x(), p.x[i].y(), p.v[i].x(),
                                p.v[i].y(), p.v[i].norm(), u.x(), u.y(), hi, lo,
                                p.plastic_strain.empty() ? 0.0 : p.plastic_strain[i],
                                p.damage.empty() ? 0.0 : p.damage[i]);
  }
  tracer_file_.flush();
  if (!tracer_file_) throw std::runtime_error("cannot write tracers.csv: the disk may be full");
}

void Output::finish() const {
  const double open = audit_.open_share(), step = audit_.integration_share();
  if (open > 0.01)
    spdlog::warn("the energy budget is open by {:.2g} % of its largest term ({:.3g} J/m) at t = {:.4g} s: a "
                 "velocity changed where no book sees it, which is a defect of the solver; please report it with "
                 "the scene (mpm_solid/README.md, Energies; mpm_history.csv)",
                 100 * open, audit_.largest_term(), audit_.worst_time());
  else
    spdlog::info("energy budget closed to {:.2g} % of its largest term ({:.3g} J/m); the time step's own error at "
                 "most {:.2g} %",
                 100 * open, audit_.largest_term(), 100 * step);
  if (step > integration_warning)
    spdlog::warn("the time step's own energy error reached {:.2g} % of the largest term ({:.3g} J/m): a step too "
                 "close to the stable one, or a run gone unstable (integration_J_per_m in mpm_history.csv)",
                 100 * step, audit_.largest_term());
}

}  // namespace outburst::mpm
