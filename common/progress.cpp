#include "common/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

namespace outburst {

std::string format_duration(double s) {
  const double a = std::abs(s);
  if (a == 0) return "0 s";
  if (a < 1e-3) return fmt::format("{:.3g} us", s * 1e6);
  if (a < 1) return fmt::format("{:.3g} ms", s * 1e3);
  if (a < 120) return fmt::format("{:.3g} s", s);
  if (a < 7200) return fmt::format("{:.3g} min", s / 60);
  if (a < 3 * 86400) return fmt::format("{:.3g} h", s / 3600);
  return fmt::format("{:.4g} d", s / 86400);
}

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

Progress::Progress(std::string label, double t_start, double t_end, bool enabled)
    : label_(std::move(label)),
      t_start_(t_start),
      t_end_(t_end),
      enabled_(enabled),
      wall_start_(std::chrono::steady_clock::now()),
      last_print_(wall_start_) {}

Progress::~Progress() { finish(); }

void Progress::update(long step, double t, double dt, const std::string& extra) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (line_open_ && now - last_print_ < std::chrono::milliseconds(200)) return;
  last_print_ = now;
  const double fraction = t_end_ > t_start_ ? (t - t_start_) / (t_end_ - t_start_) : 1.0;
  const double elapsed = std::chrono::duration<double>(now - wall_start_).count();
  const std::string eta =
      fraction > 1e-6 ? format_duration(elapsed * (1 - fraction) / fraction) : std::string("?");
  std::fprintf(stderr, "\r\033[K[%s] step %ld  t = %s / %s (%.0f%%)  dt = %s  ETA %s  %s",
               label_.c_str(), step, format_duration(t).c_str(), format_duration(t_end_).c_str(),
               100 * fraction, format_duration(dt).c_str(), eta.c_str(), extra.c_str());
  std::fflush(stderr);
  line_open_ = true;
}

void Progress::finish() {
  if (line_open_) {
    std::fprintf(stderr, "\n");
    line_open_ = false;
  }
}

}  // namespace outburst
