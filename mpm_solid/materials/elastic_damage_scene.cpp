// The scene keys of the elastic-damage law (model = "elastic_damage" in
// [[mpm.materials]]): strengths, the regularisation (a crack band or
// nonlocal damage), bulking and heterogeneity, and its registration.
#include <optional>
#include <string>

#include <fmt/format.h>

#include "mpm_solid/materials/elastic_damage.hpp"

namespace outburst::mpm {

namespace {

using scene::Range;

// A crack band (fracture_energy) or nonlocal damage (internal_length), each
// refused where the grid cannot resolve it; else the paper's local law.
void read_regularisation(const scene::Table& m, const MaterialContext& c, DamageParameters& d) {
  // The two regularised laws exclude each other: said before either checks
  // its resolution.
  if (m.has("fracture_energy") && m.has("internal_length"))
    m.fail("internal_length", "give a fracture_energy (a crack band) or an internal_length (nonlocal damage), "
                              "not both");
  if (m.has("fracture_energy")) {
    // Crack band: the ultimate strain follows from G_f and the width of the
    // narrowest band the grid's velocity field can open.
    if (m.has("ultimate_strain_ratio"))
      m.fail("ultimate_strain_ratio", "give the ultimate strain ratio (the paper's local law) or a "
                                      "fracture_energy (a crack band), not both");
    d.fracture_energy = m.quantity({"fracture_energy", "G_f, energy per unit crack area dissipated in tension "
                                                       "(K_Ic^2 / E): a crack band as wide as a crack opens on "
                                                       "the grid (a cell; two under B-splines) softens linearly "
                                                       "so that it dissipates G_f whatever the cell size",
                                    "", Range::positive()},
                                   units::energy_per_area);
    d.band_width = c.crack_cells * c.cell_size;
    if (const double widest = largest_band_width(d, c.elasticity); d.band_width > widest)
      m.refuse("fracture_energy",
               fmt::format("cells of {:g} m are too coarse for a crack band with G_f = {:g} J/m2: a band {} wide "
                           "(as wide as a crack opens under these shape functions) would dissipate more at its "
                           "peak, f_t^2 / (2 E) per unit volume, than G_f allows; refine mpm.grid.cell_size to at "
                           "most 2 E G_f / f_t^2 / {} = {:.4g} m, or raise G_f",
                           c.cell_size, *d.fracture_energy,
                           c.crack_cells == 1 ? std::string("one cell") : fmt::format("{} cells", c.crack_cells),
                           c.crack_cells, widest / c.crack_cells));
  } else {
    d.ultimate_ratio = m.number({"ultimate_strain_ratio", "eta = ultimate tensile strain / strain at f_t, beyond "
                                                          "which D = 1 (the paper gives none; 5-10 is common); "
                                                          "or give a fracture_energy",
                                 "5", Range::at_least(1)});
  }
  if (m.has("internal_length")) {
    d.internal_length = m.quantity({"internal_length", "R, radius over which nonlocal damage averages its driving "
                                                       "strain (a bell-shaped weight): the crack spreads over a zone "
                                                       "a few R wide, softening linearly to nothing at eta",
                                    "", Range::positive()},
                                   units::length);
    if (d.ultimate_ratio <= 1)
      m.fail("ultimate_strain_ratio", fmt::format("must be > 1 with an internal_length (nonlocal damage softens from "
                                                  "1 to eta), got {:g}",
                                                  d.ultimate_ratio));
    // Fewer than two cells across R: too few particles to average over, and
    // the zone would follow the cell again.
    if (*d.internal_length < 2 * c.cell_size)
      m.refuse("internal_length",
               fmt::format("an internal length of {:g} m is not resolved by cells of {:g} m: refine "
                           "mpm.grid.cell_size to at most R / 2 = {:.4g} m, or lengthen R",
                           *d.internal_length, c.cell_size, *d.internal_length / 2));
  }
}

std::optional<DamageParameters::Heterogeneity> read_heterogeneity(const scene::Table& m) {
  const auto h = m.table("heterogeneity", "heterogeneous coal: each particle's strengths and moduli scaled by "
                                          "Weibull draws of mean 1 (RFPA's approach)",
                         false);
  if (!h) return std::nullopt;
  const double index = h->number({"homogeneity_index", "Weibull shape m of the strengths: the larger, the more "
                                                       "uniform the coal (1.5-5 is typical of RFPA models of coal "
                                                       "and rock)",
                                  "", Range::at_least(1)});
  const std::string same_as_strength = fmt::format("{}", index);  // shortest, and read back exactly
  return DamageParameters::Heterogeneity{
      index,
      static_cast<std::uint64_t>(h->integer<std::int64_t>(
          {"seed", "seed of the draw: the same seed, the same coal", "1", Range::non_negative()})),
      h->number({"modulus_homogeneity_index", "Weibull shape m_E of the elastic moduli, drawn apart from the "
                                              "strengths (default: the homogeneity_index); the stiffest particle "
                                              "sets the stable step",
                 same_as_strength, Range::at_least(1)}),
      h->has("grain_size")
          ? std::optional(h->quantity({"grain_size", "side of the squares (cubes in 3D) of coal that share one "
                                                     "draw (a grid through the origin): the random field's correlation "
                                                     "length, so that refining the particles keeps the same "
                                                     "coal; without it each particle draws its own, and a finer "
                                                     "grid makes a finer-grained coal",
                                       "", Range::positive()},
                                      units::length))
          : std::nullopt};
}

template <int Dim>
std::unique_ptr<Material<Dim>> read(const scene::Table& m, const MaterialContext& c) {
  DamageParameters d{};
  d.cohesion = m.quantity({"cohesion", "Mohr-Coulomb cohesion c of the intact coal", "", Range::positive()},
                          units::pressure);
  d.friction_angle = m.quantity({"friction_angle", "Mohr-Coulomb friction angle (also of the fragments)", "",
                                 Range{0.0, 1.5, true, false}},
                                units::angle);
  d.tensile_strength = m.quantity({"tensile_strength", "tensile strength f_t", "", Range::positive()},
                                  units::pressure);
  d.residual_ratio = m.number({"residual_ratio", "residual strength / strength, in compression, and in tension "
                                                 "under the local law (the paper gives none; 0.1 is common "
                                                 "for RFPA models)",
                               "0.1", Range{0.0, 1.0, true, false}});
  read_regularisation(m, c, d);
  d.bulking_factor = m.number({"bulking_factor", "largest volume of fully damaged coal over its volume at t = 0: "
                                                 "broken coal bulks to a loose heap, its fragments then part "
                                                 "(1.3-1.6 is typical of broken coal)",
                               "1.5", Range::at_least(1)});
  d.heterogeneity = read_heterogeneity(m);
  return std::make_unique<ElasticDamage<Dim>>(c.name, c.elasticity, d);
}

[[maybe_unused]] const bool registered =
    register_material({"elastic_damage", "brittle, leaving granular fragments", read<2>, read<3>});

}  // namespace

}  // namespace outburst::mpm
