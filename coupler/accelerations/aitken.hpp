#pragma once
#include "coupler/acceleration.hpp"

namespace outburst::coupling {

// Aitken's dynamic relaxation: the factor from the secant of the last two
// residuals, started afresh in each window.
class Aitken final : public Acceleration {
 public:
  explicit Aitken(double initial) : initial_(initial) {}
  void start_window(const std::vector<FieldSlice>& fields) override;
  Eigen::VectorXd next(const Eigen::VectorXd& y, const Eigen::VectorXd& x) override;

 private:
  double initial_, omega_ = 0;
  Eigen::VectorXd previous_residual_;
};

}  // namespace outburst::coupling
