#include "coupler/gas_solid.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace outburst::coupling {

namespace {

[[noreturn]] void unknown_field(const std::string& who, const std::string& field) {
  throw std::invalid_argument(fmt::format("{} has no field '{}'", who, field));
}

// The most compressive principal value of a 2D stress (tension positive).
double smallest_principal(double xx, double yy, double xy) {
  const double mean = 0.5 * (xx + yy), radius = std::hypot(0.5 * (xx - yy), xy);
  return mean - radius;
}

}  // namespace

double PermeabilityLaw::operator()(double lambda0, double compression, double damage) const {
  const double exponent = std::clamp(-beta * compression, -max_exponent, max_exponent);
  const double factor = damage >= full_damage ? xi_full : damage > 0 ? xi : 1.0;
  return lambda0 * std::exp(exponent) * factor;
}

// ---- seepage

SeepageParticipant::SeepageParticipant(seepage::Solver& solver, GasSolidSettings settings)
    : solver_(solver), settings_(settings), lambda0_(solver.conductivity()) {
  const auto nc = static_cast<Eigen::Index>(solver_.mesh().num_cells());
  occupancy_ = Eigen::VectorXd::Ones(nc);
  stress_ = Eigen::VectorXd::Zero(3 * nc);
  damage_ = Eigen::VectorXd::Zero(nc);
  dilatation_ = Eigen::VectorXd::Zero(nc);
  if (settings_.biot_storage && solver_.model().law != seepage::Law::linear)
    throw std::invalid_argument("seepage: Biot storage needs the linear Darcy law (law = \"linear\")");
  if (settings_.fixed_stress > 0) {
    if (!settings_.biot_storage) throw std::invalid_argument("seepage: the fixed-stress split needs Biot storage");
    solver_.add_storage(settings_.fixed_stress);
  }
  // Registers open space with the solver now, so that its balance (and any
  // history written from it) has the slot from the start.
  solver_.set_open_nodes(std::vector<char>(solver_.mesh().num_nodes(), 0), settings_.open_pressure);
}

void SeepageParticipant::write(const std::string& field, const Eigen::VectorXd& values) {
  Eigen::VectorXd* target = field == "occupancy" ? &occupancy_
                            : field == "stress"  ? &stress_
                            : field == "damage"  ? &damage_
                            : field == "dilatation" && settings_.biot_storage ? &dilatation_
                                                 : nullptr;
  if (!target) unknown_field(name(), field);
  if (values.size() != target->size())
    throw std::invalid_argument(
        fmt::format("seepage: field '{}' has {} values, expected {}", field, values.size(), target->size()));
  *target = values;
}

Eigen::VectorXd SeepageParticipant::read(const std::string& field) const {
  if (field != "pressure") unknown_field(name(), field);
  const auto p = solver_.nodal_pressure();
  return Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
}

// Cells the coal has left are open space, and so is every node touching one;
// the rest get the permeability of their stress and damage.
void SeepageParticipant::apply_solid_state() {
  const auto& mesh = solver_.mesh();
  const std::size_t nc = mesh.num_cells();
  std::vector<char> open(mesh.num_nodes(), 0);
  open_cells_ = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    if (occupancy_[static_cast<Eigen::Index>(c)] >= settings_.open_below) continue;
    ++open_cells_;
    for (int node : mesh.cells[c]) open[node] = 1;
  }
  solver_.set_open_nodes(open, settings_.open_pressure);
  if (!settings_.permeability_coupling) return;
  std::vector<double> lambda(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    const auto i = static_cast<Eigen::Index>(c);
    const double compression = -smallest_principal(stress_[3 * i], stress_[3 * i + 1], stress_[3 * i + 2]);
    lambda[c] = settings_.permeability(lambda0_[c], compression, std::clamp(damage_[i], 0.0, 1.0));
  }
  solver_.set_conductivity(lambda);
}

void SeepageParticipant::advance(double window) {
  apply_solid_state();
  if (settings_.biot_storage) {
    // The rate over the solid's last window, which matched the seepage's last.
    std::vector<double> source(static_cast<std::size_t>(dilatation_.size()), 0.0);
    if (last_size_ > 0)
      for (std::size_t c = 0; c < source.size(); ++c)
        source[c] = -settings_.biot * dilatation_[static_cast<Eigen::Index>(c)] / last_size_;
    solver_.set_cell_source(std::move(source));
  }
  last_report_ = solver_.advance(window);
  last_size_ = window;
}

void SeepageParticipant::save_between_windows(checkpoint::Out out) const {
  out.numbers("occupancy", occupancy_);
  out.numbers("stress", stress_);
  out.numbers("damage", damage_);
  out.numbers("dilatation", dilatation_);
  out.number("last_size", last_size_);
}

void SeepageParticipant::load_between_windows(const checkpoint::In& in) {
  const auto cells = static_cast<std::size_t>(occupancy_.size());
  occupancy_ = in.vector("occupancy", cells);
  stress_ = in.vector("stress", 3 * cells);
  damage_ = in.vector("damage", cells);
  dilatation_ = in.vector("dilatation", cells);
  last_size_ = in.number("last_size");
}

void SeepageParticipant::save() { saved_ = solver_.save_state(); }
void SeepageParticipant::restore() { solver_.restore_state(saved_); }

// ---- solid

SolidParticipant::SolidParticipant(mpm::Solver& solver, const MeshMapping& mapping, const GasSolidSettings& settings,
                                   Eigen::VectorXd pressure, std::optional<double> fixed_time_step)
    : solver_(solver),
      mapping_(mapping),
      biot_(settings.biot),
      force_(settings.force),
      fixed_stress_(settings.fixed_stress),
      window_pressure_(settings.window_pressure),
      fixed_time_step_(fixed_time_step),
      pressure_start_(pressure),
      pressure_end_(std::move(pressure)),
      felt_change_(Eigen::VectorXd::Zero(pressure_start_.size())),
      sends_dilatation_(settings.biot_storage) {
  if (pressure_start_.size() != static_cast<Eigen::Index>(mapping_.mesh().num_nodes()))
    throw std::invalid_argument("solid: the initial pressure does not match the seepage mesh");
  mark_window_start();
}

void SolidParticipant::mark_window_start() {
  if (!sends_dilatation_) return;
  const auto& p = solver_.particles();
  const auto ids = std::max_element(p.id.begin(), p.id.end());
  start_volume_.assign(ids == p.id.end() ? 0 : static_cast<std::size_t>(*ids) + 1, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) start_volume_[static_cast<std::size_t>(p.id[i])] = p.volume[i];
}

void SolidParticipant::make_initial_stress_effective(const std::vector<double>& cell_pressure) {
  if (cell_pressure.size() != mapping_.mesh().num_cells())
    throw std::invalid_argument("solid: one initial pressure per seepage cell expected");
  const auto& p = solver_.particles();
  std::vector<double> shift(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (const int c = mapping_.cell_of(p.x[i]); c >= 0) shift[i] = biot_ * cell_pressure[static_cast<std::size_t>(c)];
  solver_.shift_initial_stress(shift);
  averages_.reset();
}

void SolidParticipant::write(const std::string& field, const Eigen::VectorXd& values) {
  if (field != "pressure") unknown_field(name(), field);
  if (values.size() != pressure_end_.size())
    throw std::invalid_argument(fmt::format("solid: field 'pressure' has {} values, expected {}", values.size(),
                                            pressure_end_.size()));
  pressure_end_ = values;
}

void SolidParticipant::compute_averages() const {
  if (averages_) return;
  const auto& p = solver_.particles();
  const std::size_t k = sends_dilatation_ ? 5 : 4;
  std::vector<double> values(k * p.size());
  // Fixed stress: the volume change less (alpha / K_dr) times the change of
  // the pressure felt, beta / alpha = alpha / K_dr.
  const double felt_share = fixed_stress_ > 0 ? fixed_stress_ / biot_ : 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    values[k * i] = p.stress[i](0, 0);
    values[k * i + 1] = p.stress[i](1, 1);
    values[k * i + 2] = p.stress[i](0, 1);
    values[k * i + 3] = p.damage.empty() ? 0.0 : p.damage[i];
    // Volume-weighted, this sums to the volume change over the window.
    if (sends_dilatation_) {
      values[k * i + 4] = (p.volume[i] - start_volume_[static_cast<std::size_t>(p.id[i])]) / p.volume[i];
      if (felt_share > 0)
        if (const auto felt = mapping_.sample(felt_change_, p.x[i])) values[k * i + 4] -= felt_share * felt->value;
    }
  }
  averages_ = mapping_.average(p.x, p.volume, values, static_cast<int>(k));
}

Eigen::VectorXd SolidParticipant::read(const std::string& field) const {
  compute_averages();
  const auto& a = *averages_;
  const auto nc = static_cast<Eigen::Index>(a.fraction.size());
  if (field == "occupancy") return Eigen::Map<const Eigen::VectorXd>(a.fraction.data(), nc);
  const Eigen::Map<const Eigen::MatrixXd> mean(a.mean.data(), sends_dilatation_ ? 5 : 4, nc);
  if (field == "stress") {
    const Eigen::MatrixXd top = mean.topRows(3);
    return Eigen::Map<const Eigen::VectorXd>(top.data(), 3 * nc);
  }
  if (field == "damage") return mean.row(3).transpose();
  if (field == "dilatation" && sends_dilatation_)
    return mean.row(4).transpose().cwiseProduct(Eigen::Map<const Eigen::VectorXd>(a.fraction.data(), nc));
  unknown_field(name(), field);
}

// The gas force (-alpha grad(p) V_p, or alpha p in the total stress) with p
// interpolated between the window's ends at `fraction` of it, or at its end.
void SolidParticipant::set_gas_force(double fraction) {
  const auto& p = solver_.particles();
  if (window_pressure_ == stability::Pressure::end) fraction = 1;
  pressure_now_ = (1 - fraction) * pressure_start_ + fraction * pressure_end_;
  const int n = static_cast<int>(p.size());
  // Particles leaving the grid renumber the rest: the hints are then only stale.
  cell_hint_.resize(p.size(), -1);
  if (force_ == GasForce::stress) {
    auto& pore = solver_.pore_pressure();
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
      const auto s = mapping_.sample(pressure_now_, p.x[i], &cell_hint_[i]);
      pore[i] = s ? biot_ * s->value : 0.0;
    }
    return;
  }
  auto& force = solver_.external_force();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < n; ++i) {
    const auto s = mapping_.sample(pressure_now_, p.x[i], &cell_hint_[i]);
    force[i] = s ? mpm::Vec<2>(-biot_ * p.volume[i] * s->gradient) : mpm::Vec<2>::Zero();
  }
}

void SolidParticipant::advance(double window) {
  mark_window_start();
  const double start = solver_.time(), end = start + window;
  last_window_ = {0};
  while (solver_.time() < end - 1e-12 * window) {
    const double dt = std::min(fixed_time_step_ ? *fixed_time_step_ : solver_.stable_time_step(), end - solver_.time());
    // The force at the middle of the step (explicit steps are short: the
    // pressure barely changes over one).
    set_gas_force((solver_.time() + 0.5 * dt - start) / window);
    const auto info = solver_.step(dt);
    last_window_.dt = info.dt;
    last_window_.removed += info.removed;
  }
  felt_change_ = pressure_end_ - pressure_start_;
  pressure_start_ = pressure_end_;
  averages_.reset();
}

void SolidParticipant::save_between_windows(checkpoint::Out out) const {
  out.numbers("pressure_start", pressure_start_);
  out.numbers("pressure_end", pressure_end_);
  out.numbers("felt_change", felt_change_);
  out.counts("cell_hint", cell_hint_);
}

void SolidParticipant::load_between_windows(const checkpoint::In& in) {
  const auto nodes = static_cast<std::size_t>(pressure_start_.size());
  pressure_start_ = in.vector("pressure_start", nodes);
  pressure_end_ = in.vector("pressure_end", nodes);
  felt_change_ = in.vector("felt_change", nodes);
  cell_hint_ = in.counts<int>("cell_hint");
  averages_.reset();
}

void SolidParticipant::save() {
  saved_ = solver_.save_state();
  saved_pressure_ = pressure_start_;
}

void SolidParticipant::restore() {
  solver_.restore_state(saved_);
  pressure_start_ = saved_pressure_;
  averages_.reset();
}

}  // namespace outburst::coupling
