#pragma once
// The command line shared by every program of the project:
//
//   <program> SCENE [--output DIR] [--overwrite | --restart] [--set key=value]...
//             [--check] [--explain [--format text|json]] [--quiet] [--log-level LEVEL] [--threads N]
//
// Checkpoints (common/checkpoint.hpp): every program writes its complete state
// to DIR/checkpoint.h5 every [output] checkpoint_interval of simulated time
// (default: at every snapshot; a settling stage by its own clock) and when a
// signal stops it. --restart continues the run of DIR from that checkpoint,
// with the same scene, overrides and build (otherwise exit code 2): the
// histories and indexes are cut back to the checkpoint's time and go on from
// there, and the run ends as it would have without the stop, bit for bit at
// the same thread count.
//
// and the one place that turns exceptions into exit codes: 2 for a bad scene or
// command line (with the file, line and key), 4 for a valid scene refused
// because what it asks for cannot work in its regime (scene::Refusal: a
// coupling scheme predicted unstable), 1 for a run that failed. A run
// stopped by SIGINT or SIGTERM ends with exit_stopped, 3 (common/stop.hpp).

#include <algorithm>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/checkpoint.hpp"
#include "common/field_output.hpp"
#include "common/interval.hpp"
#include "common/output_folder.hpp"
#include "common/scene.hpp"
#include "common/stop.hpp"

namespace outburst {

struct RunOptions {
  std::filesystem::path scene;
  std::filesystem::path output;  // empty: results/<scene name>
  std::vector<std::string> overrides;
  bool check_only = false;   // read and validate the scene, run nothing
  bool overwrite = false;    // replace an earlier run's files in the output folder
  bool restart = false;      // continue the output folder's run from its checkpoint
  bool explain = false;      // print every key the scene uses, with defaults, and stop
  std::string explain_format = "text";  // or "json"
  bool quiet = false;        // no progress line
  std::string log_level = "info";
  int threads = 0;           // 0: OpenMP's default

  std::filesystem::path output_directory() const;
  bool show_progress() const;
  // What the output folder does with an earlier run's files.
  OutputFolder::Earlier earlier_files() const;
};

// Parse the command line, set up logging and threads, load the scene, and call
// `run` with the loaded document. Returns the process exit code.
int run_program(const std::string& program, const std::string& description, int argc, char** argv,
                const std::function<int(const RunOptions&, scene::Document&)>& run);

// The [scene] and [output] sections every scene has.
struct SceneHeader {
  std::string title;
  std::vector<std::string> solvers;  // which solvers run: "seepage", "mpm"
  double end_time;                   // [s]
  double output_interval;            // simulated time between snapshots [s]
  double checkpoint_interval;        // simulated time between checkpoints [s]
  // Stop before end_time once the kinetic energy falls below this fraction of
  // its peak (scenes with the mpm solver): the coal has come to rest.
  std::optional<double> rest_fraction;
};
SceneHeader read_scene_header(const scene::Table& root);

// Watches a run's kinetic energy for the [scene] rest_fraction criterion.
class RestWatch {
 public:
  explicit RestWatch(std::optional<double> fraction) : fraction_(fraction) {}
  // True once `kinetic` [J] is below the fraction of the largest value seen so far.
  bool at_rest(double kinetic) {
    peak_ = std::max(peak_, kinetic);
    return fraction_ && peak_ > 0 && kinetic < *fraction_ * peak_;
  }
  double peak() const { return peak_; }
  void save(checkpoint::Out out) const { out.number("peak", peak_); }
  void load(const checkpoint::In& in) { peak_ = in.number("peak"); }
  // Without the criterion a run needs no kinetic energy summed per step.
  bool active() const { return fraction_.has_value(); }

 private:
  std::optional<double> fraction_;
  double peak_ = 0;
};

// When checkpoints are due: each time the simulated time passes another
// multiple of the interval.
class CheckpointClock {
 public:
  explicit CheckpointClock(double interval) : interval_(interval), next_(interval) {}
  // True when `time` [s] has reached the next checkpoint time, which then
  // moves past it.
  bool due(double time) {
    if (!reached(time, next_, next_)) return false;
    while (next_ <= time * (1 + 1e-12)) next_ += interval_;
    return true;
  }
  void save(checkpoint::Out out) const { out.number("next", next_); }
  void load(const checkpoint::In& in) { next_ = in.number("next"); }

 private:
  double interval_, next_;
};

// The checkpoints of a settling stage (before t = 0), for the programs that
// settle: `state` (a solver or a coupled model, with save and load) is written
// under `group` with the stage's own clock whenever one is due and when a
// signal asks the run to stop.
template <class State>
class SettlingCheckpoints {
 public:
  SettlingCheckpoints(std::filesystem::path folder, const output::RunInfo& info, double interval, State& state,
                      std::string group)
      : folder_(std::move(folder)), info_(info), clock_(interval), state_(state), group_(std::move(group)) {}
  // Continues a stage a settling checkpoint stopped.
  void resume(const checkpoint::Reader& restart) {
    const auto root = restart.root();
    state_.load(root.group(group_));
    clock_.load(root.group("settling").group("checkpoints"));
  }
  // The stage's pause at `time` [s]: true when a signal asks it to stop.
  bool pause(double time) {
    const bool stop = stop_requested();
    if (clock_.due(time) || stop) {
      checkpoint::Writer file(folder_, info_, checkpoint::Stage::settling);
      auto root = file.root();
      state_.save(root.group(group_));
      clock_.save(root.group("settling").group("checkpoints"));
      file.commit();
    }
    return stop;
  }

 private:
  std::filesystem::path folder_;
  const output::RunInfo& info_;
  CheckpointClock clock_;
  State& state_;
  std::string group_;
};

// Stops with a clear error when a program is given a scene for other solvers.
void require_solvers(const scene::Table& root, const SceneHeader& header,
                     const std::vector<std::string>& supported, const std::string& program);

// Provenance for output files of this run.
output::RunInfo run_info(const std::string& program, const scene::Document& doc,
                         const std::string& units);

// After reading: reject unknown keys and honour --explain / --check.
// Returns false when the program should stop here (--check, --explain).
bool finish_reading(const RunOptions& options, const scene::Document& doc);

}  // namespace outburst
