#include "coupler/gas_solid.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <omp.h>

#include "common/interval.hpp"

namespace outburst::coupling {

namespace {

[[noreturn]] void unknown_field(const std::string& who, const std::string& field) {
  throw std::invalid_argument(fmt::format("{} has no field '{}'", who, field));
}

// The most compressive principal value of a cell's mean stress (tension
// positive): in 2D of xx, yy, xy (the in-plane stresses the paper's law
// reads), in 3D of xx, yy, zz, yz, xz, xy.
template <int Dim>
double smallest_principal(const double* s) {
  if constexpr (Dim == 2) {
    const double mean = 0.5 * (s[0] + s[1]), radius = std::hypot(0.5 * (s[0] - s[1]), s[2]);
    return mean - radius;
  } else {
    Eigen::Matrix3d m;
    m << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(m, Eigen::EigenvaluesOnly);
    return solver.eigenvalues()[0];
  }
}

}  // namespace

double PermeabilityLaw::operator()(double lambda0, double compression, double damage) const {
  const double exponent = std::clamp(-beta * compression, -max_exponent, max_exponent);
  const double factor = damage >= full_damage ? xi_full : damage > 0 ? xi : 1.0;
  return lambda0 * std::exp(exponent) * factor;
}

// ---- seepage

template <int Dim>
SeepageParticipant<Dim>::SeepageParticipant(seepage::SolverOf<Dim>& solver, GasSolidSettings settings)
    : solver_(solver), settings_(settings), lambda0_(solver.conductivity()) {
  const auto nc = static_cast<Eigen::Index>(solver_.mesh().num_cells());
  for (const auto& f : solid_fields)
    received_[static_cast<std::size_t>(f.id)] = Eigen::VectorXd::Constant(f.components_in(Dim) * nc, f.start);
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

template <int Dim>
void SeepageParticipant<Dim>::write(const std::string& field, const Eigen::VectorXd& values) {
  const auto f = std::find_if(solid_fields.begin(), solid_fields.end(), [&](const SolidFieldInfo& candidate) {
    return candidate.name == field && candidate.sent(settings_);
  });
  if (f == solid_fields.end()) unknown_field(name(), field);
  auto& target = received_[static_cast<std::size_t>(f->id)];
  if (values.size() != target.size())
    throw std::invalid_argument(
        fmt::format("seepage: field '{}' has {} values, expected {}", field, values.size(), target.size()));
  target = values;
}

template <int Dim>
Eigen::VectorXd SeepageParticipant<Dim>::read(const std::string& field) const {
  if (field != pressure_field) unknown_field(name(), field);
  const auto p = solver_.nodal_pressure();
  return Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
}

// Cells the coal has left are open space, and so is every node touching one;
// the rest get the permeability of their stress and damage.
template <int Dim>
void SeepageParticipant<Dim>::apply_solid_state() {
  const auto& mesh = solver_.mesh();
  const std::size_t nc = mesh.num_cells();
  const auto& occupancy = received(SolidField::occupancy);
  const auto& stress = received(SolidField::stress);
  const auto& damage = received(SolidField::damage);
  std::vector<char> open(mesh.num_nodes(), 0);
  open_cells_ = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    if (occupancy[static_cast<Eigen::Index>(c)] >= settings_.open_below) continue;
    ++open_cells_;
    for (int node : mesh.cells[c]) open[node] = 1;
  }
  solver_.set_open_nodes(open, settings_.open_pressure);
  if (!settings_.permeability_coupling) return;
  std::vector<double> lambda(nc);
  const Eigen::Index k = solid_fields[static_cast<std::size_t>(SolidField::stress)].components_in(Dim);
  for (std::size_t c = 0; c < nc; ++c) {
    const auto i = static_cast<Eigen::Index>(c);
    const double compression = -smallest_principal<Dim>(&stress[k * i]);
    lambda[c] = settings_.permeability(lambda0_[c], compression, std::clamp(damage[i], 0.0, 1.0));
  }
  solver_.set_conductivity(lambda);
}

template <int Dim>
void SeepageParticipant<Dim>::advance(double window) {
  apply_solid_state();
  if (settings_.biot_storage) {
    // The rate over the solid's last window, which matched the seepage's last.
    const auto& dilatation = received(SolidField::dilatation);
    std::vector<double> source(static_cast<std::size_t>(dilatation.size()), 0.0);
    if (last_size_ > 0)
      for (std::size_t c = 0; c < source.size(); ++c)
        source[c] = -settings_.biot * dilatation[static_cast<Eigen::Index>(c)] / last_size_;
    solver_.set_cell_source(std::move(source));
  }
  last_report_ = solver_.advance(window);
  last_size_ = window;
}

template <int Dim>
void SeepageParticipant<Dim>::save_between_windows(checkpoint::Out out) const {
  for (const auto& f : solid_fields) out.numbers(std::string(f.name), received(f.id));
  out.number("last_size", last_size_);
}

template <int Dim>
void SeepageParticipant<Dim>::load_between_windows(const checkpoint::In& in) {
  for (const auto& f : solid_fields) {
    auto& values = received_[static_cast<std::size_t>(f.id)];
    values = in.vector(std::string(f.name), static_cast<std::size_t>(values.size()));
  }
  last_size_ = in.number("last_size");
}

template <int Dim>
void SeepageParticipant<Dim>::save() {
  saved_ = solver_.save_state();
}

template <int Dim>
void SeepageParticipant<Dim>::restore() {
  solver_.restore_state(saved_);
}

// ---- solid

template <int Dim>
SolidParticipant<Dim>::SolidParticipant(mpm::Solver<Dim>& solver, const MeshMapping<Dim>& mapping,
                                        const GasSolidSettings& settings, Eigen::VectorXd pressure,
                                        std::optional<double> fixed_time_step)
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
  for (const auto& f : solid_fields)
    if (f.id != SolidField::occupancy && f.sent(settings)) averaged_.push_back(f);
  if (pressure_start_.size() != static_cast<Eigen::Index>(mapping_.mesh().num_nodes()))
    throw std::invalid_argument("solid: the initial pressure does not match the seepage mesh");
  mark_window_start();
}

template <int Dim>
void SolidParticipant<Dim>::mark_window_start() {
  if (!sends_dilatation_) return;
  const auto& p = solver_.particles();
  const auto ids = std::max_element(p.id.begin(), p.id.end());
  start_volume_.assign(ids == p.id.end() ? 0 : static_cast<std::size_t>(*ids) + 1, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) start_volume_[static_cast<std::size_t>(p.id[i])] = p.volume[i];
}

template <int Dim>
void SolidParticipant<Dim>::make_initial_stress_effective(const std::vector<double>& cell_pressure) {
  if (cell_pressure.size() != mapping_.mesh().num_cells())
    throw std::invalid_argument("solid: one initial pressure per seepage cell expected");
  const auto& p = solver_.particles();
  std::vector<double> shift(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (const int c = mapping_.cell_of(p.x[i]); c >= 0) shift[i] = biot_ * cell_pressure[static_cast<std::size_t>(c)];
  solver_.shift_initial_stress(shift);
  averages_.reset();
}

template <int Dim>
void SolidParticipant<Dim>::write(const std::string& field, const Eigen::VectorXd& values) {
  if (field != pressure_field) unknown_field(name(), field);
  if (values.size() != pressure_end_.size())
    throw std::invalid_argument(fmt::format("solid: field 'pressure' has {} values, expected {}", values.size(),
                                            pressure_end_.size()));
  pressure_end_ = values;
}

template <int Dim>
void SolidParticipant<Dim>::compute_averages() const {
  if (averages_) return;
  const auto& p = solver_.particles();
  std::size_t k = 0;
  for (const auto& f : averaged_) k += static_cast<std::size_t>(f.components_in(Dim));
  std::vector<double> values(k * p.size());
  // Fixed stress: the volume change less (alpha / K_dr) times the change of
  // the pressure felt, beta / alpha = alpha / K_dr.
  const double felt_share = fixed_stress_ > 0 ? fixed_stress_ / biot_ : 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double* out = &values[k * i];
    for (const auto& f : averaged_) {
      switch (f.id) {
        case SolidField::stress: {
          const auto& s = p.stress[i];
          if constexpr (Dim == 2) {
            out[0] = s(0, 0), out[1] = s(1, 1), out[2] = s(0, 1);
          } else {
            out[0] = s(0, 0), out[1] = s(1, 1), out[2] = s(2, 2), out[3] = s(1, 2), out[4] = s(0, 2), out[5] = s(0, 1);
          }
          break;
        }
        case SolidField::damage: out[0] = p.damage.empty() ? 0.0 : p.damage[i]; break;
        case SolidField::dilatation:
          // Volume-weighted, this sums to the volume change over the window.
          out[0] = (p.volume[i] - start_volume_[static_cast<std::size_t>(p.id[i])]) / p.volume[i];
          if (felt_share > 0)
            if (const auto felt = mapping_.sample(felt_change_, p.x[i])) out[0] -= felt_share * felt->value;
          break;
        case SolidField::occupancy: break;  // the fraction itself, not a mean
      }
      out += f.components_in(Dim);
    }
  }
  averages_ = mapping_.average(p.x, p.volume, values, static_cast<int>(k));
}

template <int Dim>
Eigen::VectorXd SolidParticipant<Dim>::read(const std::string& field) const {
  compute_averages();
  const auto& a = *averages_;
  const auto nc = static_cast<Eigen::Index>(a.fraction.size());
  const Eigen::Map<const Eigen::VectorXd> fraction(a.fraction.data(), nc);
  if (field == name_of(SolidField::occupancy)) return fraction;
  Eigen::Index row = 0, rows = 0;
  for (const auto& f : averaged_) rows += f.components_in(Dim);
  const Eigen::Map<const Eigen::MatrixXd> mean(a.mean.data(), rows, nc);
  for (const auto& f : averaged_) {
    const int components = f.components_in(Dim);
    if (f.name != field) {
      row += components;
      continue;
    }
    const Eigen::MatrixXd block = mean.middleRows(row, components);
    const Eigen::Map<const Eigen::VectorXd> cellwise(block.data(), components * nc);
    // The dilatation is a volume change per cell area: the mean over the
    // solid times its fraction.
    if (f.id == SolidField::dilatation) return cellwise.cwiseProduct(fraction);
    return cellwise;
  }
  unknown_field(name(), field);
}

// The gas force (-alpha grad(p) V_p, or alpha p in the total stress) with p
// interpolated between the window's ends at `fraction` of it, or at its end.
template <int Dim>
void SolidParticipant<Dim>::set_gas_force(double fraction) {
  const auto& p = solver_.particles();
  if (window_pressure_ == stability::Pressure::end) fraction = 1;
  pressure_now_ = (1 - fraction) * pressure_start_ + fraction * pressure_end_;
  const int n = static_cast<int>(p.size());
  // Particles leaving the grid renumber the rest: the hints are then only stale.
  cell_hint_.resize(p.size(), -1);
  using Batch = typename MeshMapping<Dim>::Batch;
  constexpr int lanes = MeshMapping<Dim>::batch_lanes;
  const int batches = (n + lanes - 1) / lanes;
  // The batch reads the positions as Dim doubles a particle, back to back.
  static_assert(sizeof(mpm::Vec<Dim>) == Dim * sizeof(double));
  // Only the field the gas force's form loads: the solver allocates each on demand.
  const bool stress = force_ == GasForce::stress;
  double* pore = stress ? solver_.pore_pressure().data() : nullptr;
  mpm::Vec<Dim>* force = stress ? nullptr : solver_.external_force().data();
#pragma omp parallel
  {
    Batch s;
#pragma omp for schedule(static)
    for (int b = 0; b < batches; ++b) {
      const int start = b * lanes, count = std::min(lanes, n - start);
      mapping_.sample(pressure_now_, p.x[start].data(), count, &cell_hint_[start], s);
      for (int k = 0; k < count; ++k) {
        const auto i = static_cast<std::size_t>(start + k);
        if (stress) {
          pore[i] = s.found[k] != 0 ? biot_ * s.value[k] : 0.0;
          continue;
        }
        const double scale = -biot_ * p.volume[i];
        for (int d = 0; d < Dim; ++d) force[i][d] = s.found[k] != 0 ? scale * s.gradient[d][k] : 0.0;
      }
    }
  }
}

template <int Dim>
void SolidParticipant<Dim>::advance(double window) {
  mark_window_start();
  const double start = solver_.time(), end = start + window;
  last_window_ = {0};
  while (!reached(solver_.time(), end, window)) {
    const double dt = std::min(fixed_time_step_ ? *fixed_time_step_ : solver_.stable_time_step(), end - solver_.time());
    // The force at the middle of the step (explicit steps are short: the
    // pressure barely changes over one).
    const double before = omp_get_wtime();
    set_gas_force((solver_.time() + 0.5 * dt - start) / window);
    gas_force_seconds_ += omp_get_wtime() - before;
    const auto info = solver_.step(dt);
    last_window_.dt = info.dt;
    last_window_.removed += info.removed;
  }
  felt_change_ = pressure_end_ - pressure_start_;
  pressure_start_ = pressure_end_;
  averages_.reset();
}

template <int Dim>
void SolidParticipant<Dim>::save_between_windows(checkpoint::Out out) const {
  out.numbers("pressure_start", pressure_start_);
  out.numbers("pressure_end", pressure_end_);
  out.numbers("felt_change", felt_change_);
  out.counts("cell_hint", cell_hint_);
}

template <int Dim>
void SolidParticipant<Dim>::load_between_windows(const checkpoint::In& in) {
  const auto nodes = static_cast<std::size_t>(pressure_start_.size());
  pressure_start_ = in.vector("pressure_start", nodes);
  pressure_end_ = in.vector("pressure_end", nodes);
  felt_change_ = in.vector("felt_change", nodes);
  cell_hint_ = in.counts<int>("cell_hint");
  averages_.reset();
}

template <int Dim>
void SolidParticipant<Dim>::save() {
  saved_ = solver_.save_state();
  saved_pressure_ = pressure_start_;
}

template <int Dim>
void SolidParticipant<Dim>::restore() {
  solver_.restore_state(saved_);
  pressure_start_ = saved_pressure_;
  averages_.reset();
}

template class SeepageParticipant<2>;
template class SeepageParticipant<3>;
template class SolidParticipant<2>;
template class SolidParticipant<3>;

}  // namespace outburst::coupling
