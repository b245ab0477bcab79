#include "coupler/accelerations/constant.hpp"

namespace outburst::coupling {

Eigen::VectorXd ConstantRelaxation::next(const Eigen::VectorXd& y, const Eigen::VectorXd& x) {
  ++iteration_;
  return y + omega_ * (x - y);
}

namespace {

[[maybe_unused]] const bool registered = register_acceleration(
    {"constant", "under-relaxation by the factor `relaxation`",
     [](const AccelerationSettings& s) -> std::unique_ptr<Acceleration> {
       return std::make_unique<ConstantRelaxation>(s.relaxation);
     }});

}  // namespace

}  // namespace outburst::coupling
