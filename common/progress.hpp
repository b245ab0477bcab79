#pragma once
// Progress of a long run: one self-overwriting line on a terminal (step, simulated
// time, step size, wall-clock ETA), nothing at all when stderr is a log file.

#include <chrono>
#include <string>

namespace outburst {

// "3.2 s", "12 min", "4.5 h", "2.1 d": a duration a person reads at a glance.
std::string format_duration(double seconds);

class Progress {
 public:
  Progress(std::string label, double t_start, double t_end, bool enabled);
  ~Progress();
  void update(long step, double t, double dt, const std::string& extra = {});
  // Ends the line so that later log output starts on a fresh one.
  void finish();

 private:
  std::string label_;
  double t_start_, t_end_;
  bool enabled_;
  bool line_open_ = false;
  std::chrono::steady_clock::time_point wall_start_, last_print_;
};

// True when stderr is a terminal and progress lines make sense.
bool stderr_is_terminal();

}  // namespace outburst
