#include "coupler/acceleration.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "common/registry.hpp"

namespace outburst::coupling {

void Acceleration::start_window(const std::vector<FieldSlice>& fields) {
  fields_ = fields;
  iteration_ = 0;
}

void Acceleration::scale_from(const Eigen::VectorXd& residual, const Eigen::VectorXd& output) {
  weight_.resize(residual.size());
  for (const auto& f : fields_) {
    const auto offset = static_cast<Eigen::Index>(f.offset), size = static_cast<Eigen::Index>(f.size);
    // A field already converged at the first iteration is scaled by its size
    // instead, so that it cannot dominate later iterations.
    double norm = residual.segment(offset, size).norm();
    if (!(norm > 0)) norm = output.segment(offset, size).norm();
    if (!(norm > 0)) norm = 1;
    weight_.segment(offset, size).setConstant(1 / norm);
  }
}

bool register_acceleration(const AccelerationModel& model) {
  return Registry<AccelerationModel>::add(model, "accelerations");
}

const std::vector<AccelerationModel>& acceleration_models() { return Registry<AccelerationModel>::all(); }

std::unique_ptr<Acceleration> make_acceleration(const AccelerationSettings& settings) {
  for (const auto& model : acceleration_models())
    if (model.name == settings.kind) return model.make(settings);
  throw std::invalid_argument(fmt::format("no acceleration named \"{}\"", settings.kind));
}

}  // namespace outburst::coupling
