#include "coupler/coupling.hpp"

#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace outburst::coupling {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Coupling::Coupling(Participant& first, Participant& second, SchemeSettings settings)
    : first_(first), second_(second), settings_(std::move(settings)) {
  if (settings_.kind == SchemeSettings::Kind::implicit) {
    if (settings_.to_first.empty()) throw std::invalid_argument("an implicit coupling needs data from second to first");
    if (settings_.min_iterations < 1 || settings_.max_iterations < settings_.min_iterations)
      throw std::invalid_argument("coupling: need 1 <= min_iterations <= max_iterations");
    for (const auto& c : settings_.to_first)
      if (!(c.relative > 0) && !(c.absolute > 0))
        throw std::invalid_argument(fmt::format("coupling: field '{}' has no positive tolerance", c.field));
    acceleration_ = make_acceleration(settings_.acceleration);
  }
}

void Coupling::check_finite(const Eigen::VectorXd& values, const std::string& what) const {
  for (Eigen::Index i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw CouplingError(fmt::format("coupling: window at t = {:.6g} s: {} has a non-finite value ({}) at entry {}",
                                      time_, what, values[i], i));
}

// The fields second sends first, stacked; the slices record where each sits.
Eigen::VectorXd Coupling::read_to_first(WindowRecord& record) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<Eigen::VectorXd> parts;
  std::size_t total = 0;
  slices_.clear();
  for (const auto& c : settings_.to_first) {
    parts.push_back(second_.read(c.field));
    check_finite(parts.back(), fmt::format("field '{}' from {}", c.field, second_.name()));
    slices_.push_back({c.field, total, static_cast<std::size_t>(parts.back().size())});
    total += parts.back().size();
  }
  Eigen::VectorXd stacked(static_cast<Eigen::Index>(total));
  for (std::size_t k = 0; k < parts.size(); ++k)
    stacked.segment(static_cast<Eigen::Index>(slices_[k].offset), parts[k].size()) = parts[k];
  record.coupler_seconds += seconds_since(start);
  return stacked;
}

void Coupling::write_to_first(const Eigen::VectorXd& y, WindowRecord& record) {
  const auto start = std::chrono::steady_clock::now();
  for (const auto& s : slices_)
    first_.write(s.name, y.segment(static_cast<Eigen::Index>(s.offset), static_cast<Eigen::Index>(s.size)));
  record.coupler_seconds += seconds_since(start);
}

// First advances (with y, if given), its fields go to second, second advances.
void Coupling::pass(double window, const Eigen::VectorXd* y, WindowRecord& record) {
  if (y) write_to_first(*y, record);
  auto start = std::chrono::steady_clock::now();
  first_.advance(window);
  record.first_seconds += seconds_since(start);
  start = std::chrono::steady_clock::now();
  for (const auto& field : settings_.to_second) {
    const Eigen::VectorXd values = first_.read(field);
    check_finite(values, fmt::format("field '{}' from {}", field, first_.name()));
    second_.write(field, values);
  }
  record.coupler_seconds += seconds_since(start);
  start = std::chrono::steady_clock::now();
  second_.advance(window);
  record.second_seconds += seconds_since(start);
}

bool Coupling::converged(const Eigen::VectorXd& y, const Eigen::VectorXd& x, WindowRecord& record) const {
  bool all = true;
  record.residuals.clear();
  for (std::size_t k = 0; k < slices_.size(); ++k) {
    const auto offset = static_cast<Eigen::Index>(slices_[k].offset), size = static_cast<Eigen::Index>(slices_[k].size);
    const double r = (x.segment(offset, size) - y.segment(offset, size)).norm();
    const double scale = x.segment(offset, size).norm();
    const auto& c = settings_.to_first[k];
    record.residuals.push_back(r / std::max(scale, 1e-300));
    const bool ok = (c.absolute > 0 && r <= c.absolute) || (c.relative > 0 && r <= c.relative * scale);
    all = all && ok;
  }
  return all;
}

const WindowRecord& Coupling::advance(double window) {
  if (!(window > 0)) throw std::invalid_argument(fmt::format("coupling: window {} is not positive", window));
  WindowRecord record;
  record.start = time_;
  record.size = window;
  using Kind = SchemeSettings::Kind;

  if (settings_.kind != Kind::implicit) {
    pass(window, have_y_ ? &y_ : nullptr, record);
    if (settings_.kind == Kind::explicit_staggered && !settings_.to_first.empty()) {
      y_ = read_to_first(record);
      have_y_ = true;
    }
    record.iterations = 1;
    record.converged = true;
  } else {
    first_.save();
    second_.save();
    // The first window starts from what second holds before any advance.
    if (!have_y_) {
      y_ = read_to_first(record);
      have_y_ = true;
    }
    acceleration_->start_window(slices_);
    Eigen::VectorXd y = y_;
    for (int k = 1;; ++k) {
      pass(window, &y, record);
      const Eigen::VectorXd x = read_to_first(record);
      record.iterations = k;
      if (k >= settings_.min_iterations && converged(y, x, record)) {
        record.converged = true;
        y_ = x;
        break;
      }
      if (k == settings_.max_iterations) {
        y_ = x;
        break;
      }
      const auto start = std::chrono::steady_clock::now();
      y = acceleration_->next(y, x);
      check_finite(y, "the accelerated coupling data");
      record.coupler_seconds += seconds_since(start);
      first_.restore();
      second_.restore();
    }
    acceleration_->end_window(record.converged);
    if (!record.converged) {
      std::string residuals;
      for (std::size_t k = 0; k < slices_.size(); ++k)
        residuals += fmt::format("{}'{}' {:.3g}", k ? ", " : "", slices_[k].name, record.residuals[k]);
      const std::string message = fmt::format(
          "coupling: the window at t = {:.6g} s (size {:.3g} s) did not converge in {} iterations; relative "
          "residuals: {}",
          time_, window, record.iterations, residuals);
      if (settings_.stop_on_divergence)
        throw CouplingError(message + ". Try a smaller window, more iterations, or another acceleration.");
      spdlog::warn("{}; going on with the last iterate", message);
    }
  }
  time_ += window;
  records_.push_back(record);
  return records_.back();
}

void Coupling::save(checkpoint::Out out) const {
  out.number("time", time_);
  out.flag("have_y", have_y_);
  out.numbers("y", y_);
  std::string names;
  std::vector<std::int64_t> extents;
  for (const auto& s : slices_) {
    names += s.name + "\n";
    extents.insert(extents.end(), {static_cast<std::int64_t>(s.offset), static_cast<std::int64_t>(s.size)});
  }
  out.text("slice_names", names);
  out.counts("slice_extents", extents);
  // The records, a column each; the residuals of all, one after another.
  const auto records = out.group("records");
  std::vector<double> start, size, first, second, coupler, residuals;
  std::vector<std::int64_t> iterations, converged, residual_counts;
  for (const auto& r : records_) {
    start.push_back(r.start);
    size.push_back(r.size);
    iterations.push_back(r.iterations);
    converged.push_back(r.converged);
    residual_counts.push_back(static_cast<std::int64_t>(r.residuals.size()));
    residuals.insert(residuals.end(), r.residuals.begin(), r.residuals.end());
    first.push_back(r.first_seconds);
    second.push_back(r.second_seconds);
    coupler.push_back(r.coupler_seconds);
  }
  records.numbers("start", start);
  records.numbers("size", size);
  records.counts("iterations", iterations);
  records.counts("converged", converged);
  records.counts("residual_counts", residual_counts);
  records.numbers("residuals", residuals);
  records.numbers("first_seconds", first);
  records.numbers("second_seconds", second);
  records.numbers("coupler_seconds", coupler);
  if (acceleration_) acceleration_->save(out.group("acceleration"));
}

void Coupling::load(const checkpoint::In& in) {
  time_ = in.number("time");
  have_y_ = in.flag("have_y");
  y_ = in.vector("y");
  const std::string names = in.text("slice_names");
  const auto extents = in.counts<std::int64_t>("slice_extents");
  slices_.clear();
  // The fields first reads, in the scheme's order, each a slice of y after
  // the one before: writing y to first reads them there.
  std::int64_t covered = 0;
  for (std::size_t start = 0, end, k = 0; (end = names.find('\n', start)) != std::string::npos; start = end + 1, ++k) {
    if (2 * k + 1 >= extents.size()) in.fail("slice_extents", "fewer extents than slice names");
    const std::string name = names.substr(start, end - start);
    if (k >= settings_.to_first.size() || name != settings_.to_first[k].field)
      in.fail("slice_names", fmt::format("field '{}' where this scheme's fields are {}", name, settings_.to_first.size()));
    const auto offset = extents[2 * k], size = extents[2 * k + 1];
    if (offset != covered || size < 0 || size > y_.size() - offset)
      in.fail("slice_extents", fmt::format("field '{}' at entries {} to {} of a y of {}, after the {} the fields before "
                                           "take",
                                           name, offset, offset + size, y_.size(), covered));
    covered += size;
    slices_.push_back({name, static_cast<std::size_t>(offset), static_cast<std::size_t>(size)});
  }
  if (!slices_.empty() && covered != y_.size())
    in.fail("slice_extents", fmt::format("the fields take {} entries of a y of {}", covered, y_.size()));
  const auto records = in.group("records");
  const auto start = records.numbers("start");
  const std::size_t n = start.size();
  const auto size = records.numbers("size", n);
  const auto iterations = records.counts<int>("iterations", n);
  const auto converged = records.counts<int>("converged", n);
  const auto residual_counts = records.counts<std::size_t>("residual_counts", n);
  const auto residuals = records.numbers("residuals");
  const auto first = records.numbers("first_seconds", n);
  const auto second = records.numbers("second_seconds", n);
  const auto coupler = records.numbers("coupler_seconds", n);
  records_.clear();
  std::size_t at = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (at + residual_counts[k] > residuals.size()) records.fail("residuals", "fewer residuals than counted");
    records_.push_back({start[k], size[k], iterations[k], converged[k] != 0,
                        {residuals.begin() + static_cast<std::ptrdiff_t>(at),
                         residuals.begin() + static_cast<std::ptrdiff_t>(at + residual_counts[k])},
                        first[k], second[k], coupler[k]});
    at += residual_counts[k];
  }
  if (acceleration_) acceleration_->load(in.group("acceleration"));
}

}  // namespace outburst::coupling
