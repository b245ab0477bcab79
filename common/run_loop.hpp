#pragma once
// The time loop every program runs (seepage-fe, mpm-solid, outburst): advance
// to the next output time or the end, write the snapshots due, stop once the
// material is at rest ([scene] rest_fraction), write checkpoints on their
// clock, and stop at the end of a step when SIGINT or SIGTERM asks, with a
// snapshot and a checkpoint. What one step is, and what is written, is the
// program's: a Driver.
//
//   struct Driver {
//     double time() const;                       // simulated time [s]
//     LoopStep advance(double target);           // one step (or window), not past target
//     double kinetic_energy() const;             // read only with a rest criterion
//     void snapshot();                           // write the state as a snapshot
//     void save(checkpoint::Out root, checkpoint::Out run) const;  // its state, at a checkpoint
//     void load(const checkpoint::In& root, const checkpoint::In& run);  // and back, on --restart
//     void failed() const;                       // optional: a step threw (the progress line is closed)
//   };

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>

#include "common/checkpoint.hpp"
#include "common/field_output.hpp"
#include "common/interval.hpp"
#include "common/program.hpp"
#include "common/progress.hpp"
#include "common/stop.hpp"

namespace outburst {

// What a step reports to the loop: its number, its size [s] and a few words
// for the progress line.
struct LoopStep {
  long count;
  double size;
  std::string note;
};

enum class RunEnd { end_time, at_rest, stopped };

class RunLoop {
 public:
  // Keeps `info` by reference: it outlives the run in every program.
  RunLoop(SceneHeader header, std::filesystem::path folder, const output::RunInfo& info)
      : header_(std::move(header)),
        folder_(std::move(folder)),
        info_(info),
        rest_(header_.rest_fraction),
        checkpoints_(header_.checkpoint_interval),
        next_output_(header_.output_interval) {}

  // Continues from a checkpoint of the run stage: the loop's state and the
  // driver's (its load mirrors its save).
  template <class Driver>
  void resume(const checkpoint::Reader& restart, Driver& driver) {
    const auto root = restart.root();
    const auto run = root.group("run");
    next_output_ = run.number("next_output");
    rest_.load(run.group("rest"));
    checkpoints_.load(run.group("checkpoints"));
    driver.load(root, run);
  }

  template <class Driver>
  RunEnd run(Driver& driver, const std::string& label, bool show_progress) {
    Progress progress(label, driver.time(), header_.end_time, show_progress);
    const double end = header_.end_time;
    while (!reached(driver.time(), end, end)) {
      const double target = std::min(next_output_, end);
      LoopStep step;
      try {
        step = driver.advance(target);
      } catch (...) {
        progress.finish();
        if constexpr (requires { driver.failed(); }) driver.failed();
        throw;
      }
      progress.update(step.count, driver.time(), step.size, step.note);
      const bool output_due = reached(driver.time(), target, target);
      const bool at_rest = rest_.active() && rest_.at_rest(driver.kinetic_energy());
      const bool stop = stop_requested();  // read once: a signal may come in between
      if (output_due || at_rest) {
        driver.snapshot();
        if (output_due) next_output_ += header_.output_interval;
      }
      if (checkpoints_.due(driver.time()) || stop) save(driver);
      if (stop) {
        // After the checkpoint: a restart drops this extra snapshot, and its
        // folder ends as the uninterrupted run's would.
        if (!output_due && !at_rest) driver.snapshot();
        progress.finish();
        return RunEnd::stopped;
      }
      if (at_rest) {
        progress.finish();
        return RunEnd::at_rest;
      }
    }
    progress.finish();
    return RunEnd::end_time;
  }

  // The kinetic energy's peak so far [J/m] (with a rest criterion).
  double peak_kinetic_energy() const { return rest_.peak(); }

 private:
  template <class Driver>
  void save(const Driver& driver) const {
    checkpoint::Writer file(folder_, info_, checkpoint::Stage::run);
    auto root = file.root();
    const auto run = root.group("run");
    run.number("next_output", next_output_);
    rest_.save(run.group("rest"));
    checkpoints_.save(run.group("checkpoints"));
    driver.save(root, run);
    file.commit();
  }

  SceneHeader header_;
  std::filesystem::path folder_;
  const output::RunInfo& info_;
  RestWatch rest_;
  CheckpointClock checkpoints_;
  double next_output_;
};

}  // namespace outburst
