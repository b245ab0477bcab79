#include "coupler/scene_reader.hpp"

#include <map>
#include <string_view>

#include <fmt/format.h>

#include "common/units.hpp"

namespace outburst::coupling {

using scene::Key;
using scene::Range;

namespace {

// Defaults are the settings structs' own, written here as a scene would.
std::string text(double v) { return fmt::format("{:g}", v); }

// What the solid sends back (the fields the scene's physics use, solid_fields)
// and when it has converged; and the Biot storage coupling's own choices.
void read_exchange(const scene::Table& c, CouplingSetup& s) {
  SchemeSettings& sc = s.scheme;
  const GasSolidSettings gas_default;
  // The keys of the iterated schemes are read whatever the scheme, so that one
  // scene can be swept over schemes (--set coupling.scheme=...). One relative
  // measure for every field, and absolute floors for fields that start at
  // zero (damage) or may vanish (stress in open space).
  const double rel = c.number({"tolerance", "implicit: relative convergence of each field the solid sends: |r| <= "
                                            "tolerance |value|",
                               text(Convergence{}.relative), Range::positive()});
  const double stress_floor = c.quantity({"stress_floor", "absolute convergence of the stress field (norm over cells)",
                                          "1 kPa", Range::non_negative()},
                                         units::pressure);
  const double fraction_floor = c.number({"fraction_floor", "absolute convergence of occupancy and damage (norm "
                                                            "over cells)",
                                          "1e-6", Range::non_negative()});
  GasSolidSettings& g = s.gas_solid;
  g.biot_storage = c.boolean({"biot_storage", "the solid's volume change feeds the seepage: source -alpha "
                                              "d(eps_v)/dt (linear Darcy law only; for poroelastic checks)",
                              gas_default.biot_storage ? "true" : "false"});
  const bool fixed_stress_named = c.has("fixed_stress");
  const bool fixed_stress = c.boolean({"fixed_stress", "with biot_storage: stabilise the split by the fixed-stress "
                                                      "extra storage alpha^2 / K_dr (K_dr the smallest drained bulk "
                                                      "modulus of the materials); unset, window_pressure \"auto\" "
                                                      "turns it on where it picks \"end\"",
                                       "false"});
  if (fixed_stress && !g.biot_storage)
    c.fail("fixed_stress", "stabilises the Biot storage coupling: set biot_storage = true or drop the key");
  if (fixed_stress_named) s.fixed_stress_split = fixed_stress;
  const std::string pressure = c.choice(
      {"window_pressure", "with biot_storage, the pore pressure the solid feels within a window: \"ramp\" (linear "
                          "between the window's ends), \"end\" (the window's end value throughout: backward Euler "
                          "in the coupling, stable for any window and fluid once iterated) or \"auto\" (the ramp "
                          "where coupler/stability.hpp predicts the scheme stable, else the end value, iterated, "
                          "with the fixed-stress split unless fixed_stress is set)",
       "auto"},
      {"auto", "ramp", "end"});
  s.allow_unstable = c.boolean({"allow_unstable", "with biot_storage: run a scheme coupler/stability.hpp predicts "
                                                  "unstable (with a warning) instead of refusing it, to measure "
                                                  "the prediction (cases/terzaghi/stability_map.py)",
                                "false"});
  if (pressure != "auto") {
    if (!g.biot_storage)
      c.fail("window_pressure", "chooses what the solid feels of the Biot storage coupling: set biot_storage = true "
                                "or drop the key");
    s.window_pressure = pressure == "ramp" ? stability::Pressure::ramp : stability::Pressure::end;
  }
  const double dilatation_floor = c.number({"dilatation_floor", "absolute convergence of the dilatation field "
                                                                "(volume change per cell area over a window)",
                                            "1e-12", Range::non_negative()});
  g.permeability_coupling = c.boolean({"permeability_coupling", "lambda follows stress and damage (paper eqs. 12, "
                                                                "14); false: the scene's lambda throughout",
                                       gas_default.permeability_coupling ? "true" : "false"});
  // Only what the seepage uses crosses over (and is iterated on).
  if (sc.kind != SchemeSettings::Kind::one_way) {
    const std::map<std::string_view, double> floors{
        {"fraction_floor", fraction_floor}, {"stress_floor", stress_floor}, {"dilatation_floor", dilatation_floor}};
    for (const auto& f : solid_fields)
      if (f.sent(g)) sc.to_first.push_back({std::string(f.name), rel, floors.at(f.floor_key)});
  }
}

// How an implicit window iterates: its acceleration and its limits.
void read_iteration(const scene::Table& c, SchemeSettings& sc) {
  const SchemeSettings scheme_default;
  const AccelerationSettings acceleration_default;
  auto& a = sc.acceleration;
  a.kind = c.model("acceleration", "implicit: what proposes each sub-iteration's input", a.kind,
                   acceleration_models())
               .name;
  a.relaxation = c.number({"relaxation", "constant: the factor; Aitken and IQN-ILS: that of a window's first "
                                         "iteration",
                           text(acceleration_default.relaxation), Range{0.0, 1.0, false, true}});
  a.reuse_windows = c.integer<int>({"reuse_windows", "past windows whose secant columns IQN-ILS reuses",
                                                text(acceleration_default.reuse_windows), Range::between(0, 100)});
  a.max_columns = c.integer<int>({"max_columns", "most secant columns of IQN-ILS",
                                              text(acceleration_default.max_columns), Range::between(1, 10000)});
  a.filter = c.number({"filter", "IQN-ILS QR2 filter: drop a column whose new part is below this fraction of it",
                       text(acceleration_default.filter), Range{0.0, 1.0, false, false}});
  sc.min_iterations = c.integer<int>({"min_iterations", "sub-iterations at least",
                                                  text(scheme_default.min_iterations), Range::between(1, 1000)});
  sc.max_iterations = c.integer<int>({"max_iterations", "sub-iterations at most",
                                                  text(scheme_default.max_iterations), Range::between(1, 10000)});
  if (sc.max_iterations < sc.min_iterations) c.fail("max_iterations", "must not be below min_iterations");
  sc.stop_on_divergence = c.choice({"on_divergence", "a window not converged in max_iterations: \"stop\" the run, "
                                                     "or \"continue\" with its last iterate (recorded)",
                                    scheme_default.stop_on_divergence ? "stop" : "continue"},
                                   {"stop", "continue"}) == "stop";

}

// How the gas loads the coal, and how the coal's state sets the permeability.
void read_gas_solid(const scene::Table& c, CouplingSetup& s) {
  GasSolidSettings& g = s.gas_solid;
  const GasSolidSettings gas_default;
  g.biot = c.number({"biot_coefficient", "alpha: total stress = effective - alpha p I (the paper's pore pressure "
                                         "coefficient)",
                     text(gas_default.biot), Range::between(0, 1)});
  g.force = c.choice({"gas_force", "how the pressure loads the coal: \"body\" (-alpha grad(p) V_p per particle, the "
                                    "paper's) or \"stress\" (alpha p in each particle's total stress: also pushes on "
                                    "surfaces the gas cannot drain through, such as a loading plate)",
                       gas_default.force == GasForce::body ? "body" : "stress"},
                      {"body", "stress"}) == "stress"
                ? GasForce::stress
                : GasForce::body;
  s.total_initial_stress = c.boolean({"total_initial_stress", "the MPM bodies' initial stresses are total: alpha p0 "
                                                              "is added to make them effective",
                                      CouplingSetup{}.total_initial_stress ? "true" : "false"});
  if (const auto p = c.table("permeability", "lambda = lambda0 exp(-beta sigma') f(D)", false)) {
    const PermeabilityLaw law;
    g.permeability.beta = p->quantity({"beta", "stress sensitivity (the paper's coupling coefficient)",
                                       fmt::format("{:g} MPa^-1", law.beta * 1e6), Range::non_negative()},
                                      units::inverse_pressure);
    g.permeability.xi = p->number({"xi", "factor for damaged coal, 0 < D < 1 (the paper gives none)", text(law.xi),
                                   Range::at_least(1)});
    g.permeability.xi_full = p->number({"xi_full", "factor for fragmented coal, D = 1 (the paper gives none)",
                                        text(law.xi_full), Range::at_least(1)});
    g.permeability.max_exponent = p->number({"max_exponent", "clamp of |beta sigma'|", text(law.max_exponent),
                                             Range::positive()});
  }
  g.open_below = c.number({"open_below", "a seepage cell holding less solid than this volume fraction is open "
                                         "space (tunnel, cavity)",
                           text(gas_default.open_below), Range{0.0, 1.0, false, false}});
  g.open_pressure = c.quantity({"open_pressure", "gas pressure of open space",
                                fmt::format("{:g} MPa", gas_default.open_pressure * 1e-6), Range::positive()},
                               units::pressure);
}

}  // namespace

CouplingSetup read_coupling(const scene::Table& c) {
  CouplingSetup s;
  SchemeSettings& sc = s.scheme;
  sc.kind = c.choice<SchemeSettings::Kind>(
      {"scheme", "\"one_way\" (seepage drives the solid), \"explicit\" (one staggered pass per window) or "
                 "\"implicit\" (sub-iterations to convergence)",
       "implicit"},
      {{"one_way", SchemeSettings::Kind::one_way},
       {"explicit", SchemeSettings::Kind::explicit_staggered},
       {"implicit", SchemeSettings::Kind::implicit}});
  s.window = c.quantity({"window", "coupling window: one seepage step, many MPM steps", "", Range::positive()},
                        units::time);
  sc.to_second = {std::string(pressure_field)};

  read_exchange(c, s);
  read_iteration(c, sc);
  read_gas_solid(c, s);
  return s;
}

}  // namespace outburst::coupling
