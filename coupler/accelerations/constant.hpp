#pragma once
#include "coupler/acceleration.hpp"

namespace outburst::coupling {

// y + omega r: under-relaxation by a fixed factor.
class ConstantRelaxation final : public Acceleration {
 public:
  explicit ConstantRelaxation(double omega) : omega_(omega) {}
  Eigen::VectorXd next(const Eigen::VectorXd& y, const Eigen::VectorXd& x) override;

 private:
  double omega_;
};

}  // namespace outburst::coupling
