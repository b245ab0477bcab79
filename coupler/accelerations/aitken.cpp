#include "coupler/accelerations/aitken.hpp"

namespace outburst::coupling {

void Aitken::start_window(const std::vector<FieldSlice>& fields) {
  Acceleration::start_window(fields);
  omega_ = initial_;
}

Eigen::VectorXd Aitken::next(const Eigen::VectorXd& y, const Eigen::VectorXd& x) {
  const Eigen::VectorXd r = x - y;
  if (iteration_ == 0) {
    scale_from(r, x);
  } else {
    const Eigen::VectorXd change = weight_.cwiseProduct(r - previous_residual_);
    const double denominator = change.squaredNorm();
    // An unchanged residual leaves no secant information: keep the factor.
    if (denominator > 0) omega_ = -omega_ * weight_.cwiseProduct(previous_residual_).dot(change) / denominator;
  }
  previous_residual_ = r;
  ++iteration_;
  return y + omega_ * r;
}

namespace {

[[maybe_unused]] const bool registered = register_acceleration(
    {"aitken", "dynamic relaxation from the last two residuals",
     [](const AccelerationSettings& s) -> std::unique_ptr<Acceleration> {
       return std::make_unique<Aitken>(s.relaxation);
     }});

}  // namespace

}  // namespace outburst::coupling
