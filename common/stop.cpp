#include "common/stop.hpp"

#include <signal.h>

#include <csignal>

#include <spdlog/spdlog.h>

namespace outburst {

namespace {

volatile std::sig_atomic_t requested = 0;  // the signal received, 0 if none

extern "C" void on_stop_signal(int signal) {
  if (requested) {
    // The second: the default action (termination) once this handler returns.
    struct sigaction fallback {};
    fallback.sa_handler = SIG_DFL;
    ::sigaction(signal, &fallback, nullptr);
    ::raise(signal);
    return;
  }
  requested = signal;
}

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  ::sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // reads and writes in progress carry on
  for (const int signal : {SIGINT, SIGTERM}) ::sigaction(signal, &action, nullptr);
}

bool stop_requested() { return requested != 0; }

int report_stop(double time, const std::filesystem::path& index) {
  spdlog::warn("stopped by {} at t = {:.9g} s: the state there is the last snapshot in {} and the checkpoint "
               "--restart continues from",
               requested == SIGINT ? "SIGINT" : "SIGTERM", time, std::filesystem::absolute(index).string());
  return exit_stopped;
}

int report_settling_stop(double time, double duration, const std::filesystem::path& checkpoint) {
  spdlog::warn("stopped by {} while settling, at {:.9g} s of the {:.9g} s stage (before t = 0: no snapshot yet): "
               "the state there is the checkpoint {}, which --restart continues from",
               requested == SIGINT ? "SIGINT" : "SIGTERM", time, duration,
               std::filesystem::absolute(checkpoint).string());
  return exit_stopped;
}

}  // namespace outburst
