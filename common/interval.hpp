#pragma once
// When a sum of step sizes has reached the end of an interval: the one
// tolerance every time loop uses (the programs' runs, a coupling window's MPM
// sub-steps, a settling stage).

namespace outburst {

// True once `time` has reached `end`, to a rounding tolerance of `span` (a
// sum of steps lands on the end only to round-off): the interval's own length
// where it is short beside the clock (a coupling window's sub-steps), else
// the end time itself (a run from t = 0).
inline bool reached(double time, double end, double span) { return time >= end - 1e-12 * span; }

}  // namespace outburst
