#pragma once
// The energy books of an MPM run: every energy the step stores, dissipates,
// takes numerically or receives, and the audit that says whether they close.
// docs/theory/energies.md derives them.

#include <optional>
#include <string>

#include "common/checkpoint.hpp"

namespace outburst::mpm {

// Energies [J; J/m in 2D, per metre of depth]. Stored ones are computed from the current
// state; dissipated and external ones accumulate over the run. With the
// gravitational potential measured from the grid's lower edge,
//   kinetic + strain + gravity + plastic + damage + damping + walls + transfer
//   + integration + left - external
// stays constant but for the balance error. The two numerical terms:
// `transfer`, the kinetic energy the grid-to-particle transfer takes from
// what the grid's update gave (the velocity increment, interpolated, is
// smoother than on the nodes; a PIC share or APIC also replaces the
// particles' sub-cell velocity differences with the grid's field), and
// `integration`, what the explicit step itself took (negative: gave): the
// work of the grid's update along the grid's velocities against the change of
// the stored, dissipated and external energies it should equal; it falls
// with the time step. `walls` is the work of wall friction and what walls and
// platens take from the mapped momenta; `left` what particles carried off the
// grid. The balance error is then round-off, unless a velocity changes where
// no book sees it.
struct Energies {
  double kinetic = 0, strain = 0, gravity = 0;
  double plastic = 0, damage = 0, damping = 0, walls = 0;  // dissipated so far
  double transfer = 0;                                     // lost in grid-to-particle transfers so far
  double integration = 0;                                  // taken by the explicit step so far
  double left = 0;                                         // carried off by particles that left the grid
  double external = 0;                                     // work of the external forces so far
  // The books behind `integration`: the kinetic energy the grid's update gave
  // pure FLIP particles before the transfer, the kinetic share of `left`, and
  // the strain and gravitational energy when the books opened.
  double grid_work = 0, left_kinetic = 0, stored_start = 0;
  double total() const {
    return kinetic + strain + gravity + plastic + damage + damping + walls + transfer + integration + left -
           external;
  }
  void save(checkpoint::Out out, const std::string& name) const;
  static Energies load(const checkpoint::In& in, const std::string& name);
};

// Whether a run's energy books close: over the states recorded, the largest
// balance error against the largest change of any term (the stored energies'
// changes from the first state, the dissipated and external ones' totals).
class EnergyAudit {
 public:
  void record(const Energies& e, double time);
  // Largest |balance error| over the largest term; 0 before two records.
  double open_share() const { return largest_term_ > 0 ? worst_error_ / largest_term_ : 0.0; }
  // The balance error of the last state recorded over the largest term.
  double final_share() const { return largest_term_ > 0 ? last_error_ / largest_term_ : 0.0; }
  // Largest |integration| over the largest term: the step's own error, which
  // a step near the stable limit, or a run going unstable, drives up.
  double integration_share() const { return largest_term_ > 0 ? worst_integration_ / largest_term_ : 0.0; }
  double largest_term() const { return largest_term_; }
  double worst_time() const { return worst_time_; }
  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

 private:
  std::optional<Energies> first_;
  double largest_term_ = 0, worst_error_ = 0, worst_time_ = 0, last_error_ = 0, worst_integration_ = 0;
};

}  // namespace outburst::mpm
