#include "coupler/accelerations/iqn_ils.hpp"

#include <Eigen/QR>
#include <fmt/format.h>

namespace outburst::coupling {

void IqnIls::start_window(const std::vector<FieldSlice>& fields) {
  Acceleration::start_window(fields);
  v_.clear();
  w_.clear();
}

Eigen::VectorXd IqnIls::next(const Eigen::VectorXd& y, const Eigen::VectorXd& x) {
  const Eigen::VectorXd r = x - y;
  if (iteration_ == 0) {
    scale_from(r, x);
  } else {
    v_.push_front(r - previous_residual_);
    w_.push_front(x - previous_output_);
  }
  previous_residual_ = r;
  previous_output_ = x;
  ++iteration_;

  // Candidate columns, newest first: this window's, then past windows'.
  std::vector<const Eigen::VectorXd*> cv, cw;
  const auto take = [&](const std::deque<Eigen::VectorXd>& v, const std::deque<Eigen::VectorXd>& w) {
    for (std::size_t i = 0; i < v.size() && static_cast<int>(cv.size()) < settings_.max_columns; ++i) {
      if (v[i].size() != r.size()) continue;  // a past window with other field sizes
      cv.push_back(&v[i]);
      cw.push_back(&w[i]);
    }
  };
  take(v_, w_);
  for (std::size_t k = 0; k < past_v_.size(); ++k) take(past_v_[k], past_w_[k]);

  // QR2 filter by modified Gram-Schmidt on the scaled columns: a column
  // (nearly) in the span of newer ones makes the least-squares problem
  // ill-conditioned, and goes.
  std::vector<Eigen::VectorXd> q;
  std::vector<std::size_t> kept;
  for (std::size_t j = 0; j < cv.size(); ++j) {
    Eigen::VectorXd a = weight_.cwiseProduct(*cv[j]);
    const double length = a.norm();
    if (!(length > 0)) continue;
    for (const auto& qi : q) a -= qi.dot(a) * qi;
    const double rest = a.norm();
    if (rest < settings_.filter * length) continue;
    q.push_back(a / rest);
    kept.push_back(j);
  }
  if (kept.empty()) return y + settings_.relaxation * r;

  Eigen::MatrixXd v(r.size(), static_cast<Eigen::Index>(kept.size()));
  for (std::size_t j = 0; j < kept.size(); ++j)
    v.col(static_cast<Eigen::Index>(j)) = weight_.cwiseProduct(*cv[kept[j]]);
  const Eigen::VectorXd c = v.householderQr().solve(-weight_.cwiseProduct(r));
  Eigen::VectorXd next = x;
  for (std::size_t j = 0; j < kept.size(); ++j) next += c[static_cast<Eigen::Index>(j)] * *cw[kept[j]];
  return next;
}

void IqnIls::end_window(bool converged) {
  if (settings_.reuse_windows > 0 && converged && !v_.empty()) {
    past_v_.push_front(std::move(v_));
    past_w_.push_front(std::move(w_));
    while (static_cast<int>(past_v_.size()) > settings_.reuse_windows) {
      past_v_.pop_back();
      past_w_.pop_back();
    }
  }
  v_.clear();
  w_.clear();
}

void IqnIls::save(checkpoint::Out out) const {
  out.count("windows", static_cast<std::int64_t>(past_v_.size()));
  for (std::size_t k = 0; k < past_v_.size(); ++k) {
    const auto window = out.group(fmt::format("window_{}", k));
    window.count("columns", static_cast<std::int64_t>(past_v_[k].size()));
    for (std::size_t j = 0; j < past_v_[k].size(); ++j) {
      window.numbers(fmt::format("v_{}", j), past_v_[k][j]);
      window.numbers(fmt::format("w_{}", j), past_w_[k][j]);
    }
  }
}

void IqnIls::load(const checkpoint::In& in) {
  past_v_.clear();
  past_w_.clear();
  const auto windows = in.count("windows");
  for (std::int64_t k = 0; k < windows; ++k) {
    const auto window = in.group(fmt::format("window_{}", k));
    auto& v = past_v_.emplace_back();
    auto& w = past_w_.emplace_back();
    const auto columns = window.count("columns");
    for (std::int64_t j = 0; j < columns; ++j) {
      v.push_back(window.vector(fmt::format("v_{}", j)));
      w.push_back(window.vector(fmt::format("w_{}", j), static_cast<std::size_t>(v.back().size())));
    }
  }
}

namespace {

[[maybe_unused]] const bool registered = register_acceleration(
    {"iqn_ils", "quasi-Newton, least-squares secants",
     [](const AccelerationSettings& s) -> std::unique_ptr<Acceleration> { return std::make_unique<IqnIls>(s); }});

}  // namespace

}  // namespace outburst::coupling
