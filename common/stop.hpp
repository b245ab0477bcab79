#pragma once
// Stopping a run on request. SIGINT or SIGTERM only sets a flag (async-signal
// safe); each program's run loop checks it after every step (or coupling
// window, or settling step), writes a snapshot and a checkpoint of the state
// it reached (a settling stage only the checkpoint), says so and exits with
// exit_stopped. The histories are flushed line by line anyway. A second
// signal ends the process at once, as the signal would by default.

#include <filesystem>

namespace outburst {

// The exit code of a run stopped by SIGINT or SIGTERM.
inline constexpr int exit_stopped = 3;

// Installed by run_program() for every program.
void install_stop_handlers();
bool stop_requested();

// Logs that the run stopped at `time` [s] with its last snapshot listed in
// `index` (and its checkpoint written); returns exit_stopped.
int report_stop(double time, const std::filesystem::path& index);
// Logs that the solid's settling stage stopped at `time` [s] of `duration`
// [s], its state in `checkpoint`; returns exit_stopped.
int report_settling_stop(double time, double duration, const std::filesystem::path& checkpoint);

}  // namespace outburst
