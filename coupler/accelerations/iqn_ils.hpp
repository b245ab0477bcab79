#pragma once
#include <deque>

#include "coupler/acceleration.hpp"

namespace outburst::coupling {

// Interface quasi-Newton with an inverse Jacobian from a least-squares fit
// of the secant columns (Degroote et al. 2009), past windows' columns reused.
class IqnIls final : public Acceleration {
 public:
  explicit IqnIls(const AccelerationSettings& settings) : settings_(settings) {}
  void start_window(const std::vector<FieldSlice>& fields) override;
  Eigen::VectorXd next(const Eigen::VectorXd& y, const Eigen::VectorXd& x) override;
  void end_window(bool converged) override;
  // The columns of the past windows kept for reuse.
  void save(checkpoint::Out out) const override;
  void load(const checkpoint::In& in) override;

 private:
  AccelerationSettings settings_;
  // Columns of this window, newest first, and of past windows.
  std::deque<Eigen::VectorXd> v_, w_;
  std::deque<std::deque<Eigen::VectorXd>> past_v_, past_w_;
  Eigen::VectorXd previous_residual_, previous_output_;
};

}  // namespace outburst::coupling
