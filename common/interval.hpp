#pragma once
// When a sum of step sizes has reached the end of an interval: the one
// tolerance every time loop uses (the programs' runs, a coupling window's MPM
// sub-steps, a settling stage).

namespace outburst {

// True once `time` has reached `end`, to a rounding tolerance of the span of
// the interval it ends (a sum of steps lands on the end only to round-off).
inline bool reached(double time, double end, double span) { return time >= end - 1e-12 * span; }

}  // namespace outburst
