#pragma once
// Acceleration of the fixed-point iteration of an implicit coupling window.
//
// A window's sub-iterations solve y = H(y), with y the data the second
// participant sends the first (stacked fields) and H one pass through both
// solvers. Each iteration k gives the input y_k, the output x_k = H(y_k) and
// the residual r_k = x_k - y_k; an acceleration proposes y_(k+1).
//
//   constant:  y + omega r
//   Aitken:    y + omega_k r, omega_k = -omega_(k-1) r_(k-1).(r_k - r_(k-1)) / |r_k - r_(k-1)|^2
//   IQN-ILS:   x_k + W c, with c minimising |V c + r_k| (Degroote et al. 2009),
//              V and W the differences of residuals and outputs between
//              iterations, kept over a few past windows.
//
// Fields differ by orders of magnitude (pressure gradients against stresses
// and volume fractions), so every inner product runs on preconditioned data:
// each field is divided by the norm of its residual at the window's first
// iteration (a per-window scaling; V and W are kept unscaled).

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "common/checkpoint.hpp"

namespace outburst::coupling {

// Where each field sits in the stacked vector.
struct FieldSlice {
  std::string name;
  std::size_t offset = 0, size = 0;
};

struct AccelerationSettings {
  // A registered model's name (acceleration_models(); the scene key
  // `coupling.acceleration`).
  std::string kind = "iqn_ils";
  // constant: the factor; Aitken and IQN-ILS: the factor of each window's first
  // iteration (IQN-ILS only while it has no columns yet).
  double relaxation = 0.5;
  // IQN-ILS: past windows whose columns are reused, the most columns kept, and
  // the filter dropping a column whose part orthogonal to the newer ones is
  // below this fraction of its length (QR2 filter).
  int reuse_windows = 8;
  int max_columns = 100;
  double filter = 1e-2;
};

class Acceleration {
 public:
  virtual ~Acceleration() = default;
  // A new window; the slices describe the stacked vector of every call.
  virtual void start_window(const std::vector<FieldSlice>& fields);
  // The next input from this iteration's input y and output x = H(y).
  virtual Eigen::VectorXd next(const Eigen::VectorXd& y, const Eigen::VectorXd& x) = 0;
  // The window ended; converged windows feed reuse.
  virtual void end_window(bool /*converged*/) {}
  // What it carries from window to window, to and from a checkpoint (taken
  // between windows). Constant relaxation and Aitken carry nothing: each
  // window starts them afresh.
  virtual void save(checkpoint::Out /*out*/) const {}
  virtual void load(const checkpoint::In& /*in*/) {}

 protected:
  // Per-entry weights of the preconditioner, set at a window's first iteration.
  void scale_from(const Eigen::VectorXd& residual, const Eigen::VectorXd& output);
  std::vector<FieldSlice> fields_;
  Eigen::VectorXd weight_;
  int iteration_ = 0;  // within the window, counted by next()
};

// An acceleration a scene can name (`acceleration = "<name>"` in
// [coupling]), each in its own file under coupler/accelerations/ with its
// registration, so that a new one is one file and its test.
struct AccelerationModel {
  std::string_view name;
  std::string_view description;  // a few words for the key's help
  std::unique_ptr<Acceleration> (*make)(const AccelerationSettings& settings);
};

// The models registered, by name. The list is taken at the first call: not to
// be called during static initialisation.
const std::vector<AccelerationModel>& acceleration_models();
// Adds a model; each model's file calls it once, at static initialisation:
// `[[maybe_unused]] const bool registered = register_acceleration({...});`.
// Two models of one name are a programming error (std::logic_error).
bool register_acceleration(const AccelerationModel& model);
// The model `settings.kind` names (std::invalid_argument for an unknown name).
std::unique_ptr<Acceleration> make_acceleration(const AccelerationSettings& settings);

}  // namespace outburst::coupling
