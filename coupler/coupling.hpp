#pragma once
// Partitioned coupling of two solvers by windows, preCICE's serial schemes:
//
//   one-way:   first advances, its data goes to second, second advances; no
//              data comes back.
//   explicit:  as one-way, then second's data goes back to first for the next
//              window (one pass, no repetition).
//   implicit:  the window is repeated (both solvers restored to its start) until
//              the data second sends first stops changing; an acceleration
//              proposes each new guess.
//
// The coupler knows only the Participant interface: named fields of doubles,
// advance by a window, save and restore. It never sees a solver's insides.

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "coupler/acceleration.hpp"

namespace outburst::coupling {

class Participant {
 public:
  virtual ~Participant() = default;
  virtual std::string name() const = 0;
  // Take the named field (the other participant's data for this window).
  virtual void write(const std::string& field, const Eigen::VectorXd& values) = 0;
  // Give the named field as it stands after the last advance.
  virtual Eigen::VectorXd read(const std::string& field) const = 0;
  virtual void advance(double window) = 0;
  // Checkpoint at a window's start, and roll back to it.
  virtual void save() = 0;
  virtual void restore() = 0;
};

class CouplingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A field sent from second to first and the measure of its convergence: the
// residual r (output minus input of an iteration) is small enough when
// |r| <= absolute or |r| <= relative |output| (Euclidean norms; a zero
// tolerance is not used).
struct Convergence {
  std::string field;
  double relative = 1e-3;
  double absolute = 0;
};

struct SchemeSettings {
  enum class Kind { one_way, explicit_staggered, implicit };
  Kind kind = Kind::implicit;
  std::vector<std::string> to_second;  // fields first -> second
  std::vector<Convergence> to_first;   // fields second -> first (the iterated ones)
  AccelerationSettings acceleration;
  int min_iterations = 1;
  int max_iterations = 50;
  // A window that does not converge in max_iterations: stop the run with a
  // message (true), or keep its last iterate, record it and go on.
  bool stop_on_divergence = true;
};

struct WindowRecord {
  double start = 0, size = 0;
  int iterations = 0;
  bool converged = false;
  std::vector<double> residuals;  // per to_first field, |r| / max(|output|, tiny), last iteration
  double first_seconds = 0, second_seconds = 0, coupler_seconds = 0;
};

class Coupling {
 public:
  Coupling(Participant& first, Participant& second, SchemeSettings settings);
  // One window of the given size; returns its record (also kept in records()).
  const WindowRecord& advance(double window);
  double time() const { return time_; }
  const std::vector<WindowRecord>& records() const { return records_; }
  const SchemeSettings& settings() const { return settings_; }

  // The coupling's own state between windows (time, records, the data second
  // last sent first and the acceleration's history), to and from a
  // checkpoint; the participants save theirs.
  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

 private:
  Eigen::VectorXd read_to_first(WindowRecord& record);
  void write_to_first(const Eigen::VectorXd& y, WindowRecord& record);
  void pass(double window, const Eigen::VectorXd* y, WindowRecord& record);
  bool converged(const Eigen::VectorXd& y, const Eigen::VectorXd& x, WindowRecord& record) const;
  void check_finite(const Eigen::VectorXd& values, const std::string& what) const;

  Participant& first_;
  Participant& second_;
  SchemeSettings settings_;
  std::unique_ptr<Acceleration> acceleration_;
  std::vector<FieldSlice> slices_;
  Eigen::VectorXd y_;  // the data second last sent first
  bool have_y_ = false;
  double time_ = 0;
  std::vector<WindowRecord> records_;
};

}  // namespace outburst::coupling
