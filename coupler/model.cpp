#include "coupler/model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

namespace outburst::coupling {

namespace {

// The shortest edge of any cell: of a quadrilateral's four, or a hexahedron's
// twelve (corners 0-3 one face, 4-7 the opposite one, in Gmsh's order), and
// the centre of its cell.
template <int Dim>
struct Narrowest {
  double width = std::numeric_limits<double>::infinity();
  Eigen::Matrix<double, Dim, 1> centre;
};
template <int Dim>
Narrowest<Dim> narrowest_cell(const seepage::MeshOf<Dim>& mesh) {
  constexpr std::array<std::array<int, 2>, 12> edges{
      {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};
  Narrowest<Dim> narrowest;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const auto x = mesh.corners(c);
    for (int k = 0; k < (Dim == 2 ? 4 : 12); ++k)
      if (const double width = (x[edges[k][1]] - x[edges[k][0]]).norm(); width < narrowest.width) {
        narrowest.width = width;
        narrowest.centre.setZero();
        for (const auto& corner : x) narrowest.centre += corner / static_cast<double>(x.size());
      }
  }
  return narrowest;
}

// How far round-off may have moved the mesh's nodes: single precision's
// spacing at its largest coordinate, since meshers that store floats, or
// print seven digits, place a node so far from where it was meant.
template <int Dim>
double coordinate_round_off(const seepage::MeshOf<Dim>& mesh) {
  double largest = 0;
  for (const auto& x : mesh.nodes) largest = std::max(largest, x.template lpNorm<Eigen::Infinity>());
  return largest * 0x1p-23;
}

// The seepage mesh's bounding box.
template <int Dim>
std::pair<Eigen::Matrix<double, Dim, 1>, Eigen::Matrix<double, Dim, 1>> extent(const seepage::MeshOf<Dim>& mesh) {
  auto lo = mesh.nodes.front(), hi = lo;
  for (const auto& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return {lo, hi};
}

// The smallest and largest draw of the moduli among material m's particles
// (a heterogeneous material's; {1} for a uniform one): the softest and the
// stiffest coal bound the regimes the window scheme meets.
template <int Dim>
std::vector<double> modulus_scale_range(const mpm::Particles<Dim>& p, int m) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (std::size_t i = 0; i < p.modulus_scale.size(); ++i)
    if (p.material[i] == m) lo = std::min(lo, p.modulus_scale[i]), hi = std::max(hi, p.modulus_scale[i]);
  if (hi == 0) return {1.0};
  return {lo, hi};
}

}  // namespace

template <int Dim>
std::vector<stability::Regime> poroelastic_regimes(const CoupledSetup<Dim>& s) {
  const double cell = narrowest_cell(s.seepage.mesh).width;
  const auto [lo, hi] = extent(s.seepage.mesh);
  std::vector<stability::Regime> regimes;
  const auto& p = s.solid.particles;
  for (std::size_t m = 0; m < s.solid.materials.size(); ++m) {
    const auto& e = s.solid.materials[m]->elasticity();
    for (const double stiffness : modulus_scale_range(p, static_cast<int>(m)))
      for (const auto& region : s.seepage.model.materials)
        regimes.push_back({e.density, stiffness * (e.lame_lambda() + 2 * e.shear_modulus()),
                           stiffness * (e.lame_lambda() + 2.0 / 3.0 * e.shear_modulus()),
                           s.solid.settings.viscous_damping, s.coupling.gas_solid.biot, region.capacity,
                           region.conductivity, (hi - lo).maxCoeff(), cell});
  }
  return regimes;
}

namespace {

// The worst predicted growth over the regimes, and the regime it is in.
struct Prediction {
  stability::Growth growth;
  const stability::Regime* regime;
};
Prediction predict(const std::vector<stability::Regime>& regimes, const stability::Window& window) {
  Prediction worst{{-std::numeric_limits<double>::infinity(), 0}, nullptr};
  for (const auto& r : regimes)
    if (const auto g = stability::growth(r, window); g.rate > worst.growth.rate) worst = {g, &r};
  return worst;
}

std::string describe(const stability::Window& w) {
  return fmt::format("{} coupling{} with the solid feeling the pore pressure's {}",
                     w.iterated ? "the implicit" : "the explicit", w.fixed_stress ? " (fixed-stress split)" : "",
                     w.pressure == stability::Pressure::ramp ? "ramp over the window" : "end value");
}

// With Biot storage: resolves window_pressure "auto" to the ramp where the
// analysis predicts the scheme stable, else to the end value (iterated, with
// the fixed-stress split unless the scene sets it); refuses a scheme the scene
// names that cannot be stable at its window, naming the limit and the stable
// alternative.
template <int Dim>
void choose_window_pressure(const scene::Table& root, CoupledSetup<Dim>& s) {
  auto& cs = s.coupling;
  const auto coupling = root.table("coupling", "", true);
  using Kind = SchemeSettings::Kind;
  if (cs.scheme.kind == Kind::one_way) return;  // nothing comes back to the seepage
  const auto regimes = poroelastic_regimes(s);
  stability::Window w{cs.scheme.kind == Kind::implicit, cs.fixed_stress_split.value_or(false),
                      cs.window_pressure.value_or(stability::Pressure::ramp), cs.window};
  const Prediction p = predict(regimes, w);
  if (p.growth.rate <= 0) {
    cs.window_pressure = w.pressure;
    spdlog::debug("coupling: {} at a window of {:.3g} s is predicted stable (slowest decay {:.3g} 1/s)", describe(w),
                  cs.window, -p.growth.rate);
    return;
  }
  const double limit = stability::smallest_stable_window(*p.regime, w, cs.window, 1e4 * cs.window);
  const std::string why = fmt::format(
      "{} grows by {:.3g} 1/s at a window of {:.3g} s (the mode of wavelength {:.3g} m; coupler/stability.hpp); {}",
      describe(w), p.growth.rate, cs.window, 2 * std::numbers::pi / p.growth.wavenumber,
      limit > 0 ? fmt::format("it is stable from a window of about {:.3g} s", limit)
                : std::string("no window up to 1e4 times this one is stable"));
  const std::string stable = "scheme = \"implicit\" with window_pressure = \"end\" is stable for any window";
  if (!cs.window_pressure && !w.iterated) {
    // One pass: the end pressure may hold where the ramp does not.
    stability::Window end = w;
    end.pressure = stability::Pressure::end;
    if (predict(regimes, end).growth.rate <= 0) {
      cs.window_pressure = end.pressure;
      spdlog::info("coupling: {}; the solid feels the window's end pressure instead (window_pressure = \"auto\")",
                   why);
      return;
    }
  }
  if (cs.window_pressure || !w.iterated) {
    const std::string_view key = cs.window_pressure ? "window_pressure" : "scheme";
    if (!cs.allow_unstable)
      coupling->refuse(key, fmt::format("{}; {} (or take a larger coupling.window)", why, stable));
    cs.window_pressure = w.pressure;
    spdlog::warn("coupling: {}; run anyway (allow_unstable = true)", why);
    return;
  }
  cs.window_pressure = stability::Pressure::end;
  if (!cs.fixed_stress_split) cs.fixed_stress_split = true;
  spdlog::info("coupling: {}; the solid feels the window's end pressure instead (window_pressure = \"auto\"){}",
               why, *cs.fixed_stress_split ? ", with the fixed-stress split" : "");
}

}  // namespace

int coupled_dimension(scene::Table root) {
  return mpm::scene_dimension(*root.table("mpm", "the material point solver", true));
}

template <int Dim>
CoupledSetup<Dim> read_coupled_scene(scene::Table root) {
  CoupledSetup<Dim> s;
  s.header = read_scene_header(root);
  require_solvers(root, s.header, {"seepage", "mpm"}, "outburst");
  if (s.header.solvers.size() != 2)
    root.table("scene", "", true)->fail("solvers", "outburst couples \"seepage\" and \"mpm\"; run seepage-fe or "
                                                   "mpm-solid for one alone");
  const auto seepage_table = root.table("seepage", "the gas seepage solver", true);
  auto seepage_setup = seepage::read_any_setup(*seepage_table, false);
  if (auto* same = std::get_if<seepage::SetupOf<Dim>>(&seepage_setup)) {
    s.seepage = std::move(*same);
  } else {
    const auto mesh = seepage_table->table("mesh", "", true);
    mesh->fail(mesh->has("file") ? "file" : "type",
               fmt::format("a {} mesh, where the MPM grid is {} (its size has {} lengths): the two must be both "
                           "plane or both 3D",
                           Dim == 2 ? "3D" : "plane", Dim == 2 ? "plane" : "3D", Dim));
  }
  s.solid = mpm::read_setup<Dim>(*root.table("mpm", "the material point solver", true));
  const auto coupling = root.table("coupling", "the gas-solid coupling", true);
  s.coupling = read_coupling(*coupling);
  if (s.coupling.gas_solid.biot_storage && s.seepage.model.law != seepage::Law::linear)
    coupling->fail("biot_storage", "the Biot storage term is written for the linear Darcy law: set seepage.law = "
                                   "\"linear\" or drop the key");
  // Seepage cells off the MPM grid never hold coal: they would read as open
  // space and release their gas at once.
  const auto [lo, hi] = extent(s.seepage.mesh);
  if (const auto past = mpm::overhang<Dim>(s.solid.grid, lo, hi); !past.empty()) {
    const auto mesh = root.table("seepage", "", true)->table("mesh", "", true);
    std::vector<std::string> spans;
    for (int d = 0; d < Dim; ++d) spans.push_back(fmt::format("[{:g}, {:g}]", lo[d], hi[d]));
    mesh->fail(mesh->has("file") ? "file" : "origin",
               fmt::format("the seepage mesh, {} m, reaches {}: its cells there hold no coal and would read as open "
                           "space",
                           fmt::join(spans, " x "), past));
  }
  // Every seepage cell the coal fills must read as coal: one without a
  // particle, or with fewer than open_below of its area in particles, reads as
  // open space and misses the coal's volume change (measured: Mandel's
  // pressure grows without bound with particles 0.0625 m apart on 0.05 m
  // cells; the outburst's seam opened whole with particles 1/6 m apart on
  // 0.25 m cells, one to a row in some: 44 % full). A cell narrower than a
  // whole number of rows by no more than the nodes' round-off still holds
  // them, but for a particle that close to its edge, whose cell round-off
  // decides anyway.
  double spacing = 0;
  for (double w : s.solid.particles.half_width) spacing = std::max(spacing, 2 * w * s.solid.grid.h);
  const auto narrowest = narrowest_cell(s.seepage.mesh);
  const double per_row = std::floor((narrowest.width + coordinate_round_off(s.seepage.mesh)) / spacing);
  const double least_fill = std::pow(per_row * spacing / narrowest.width, Dim);
  if (per_row < 1 || least_fill < s.coupling.gas_solid.open_below) {
    std::vector<std::string> centre;
    for (int d = 0; d < Dim; ++d) centre.push_back(fmt::format("{:.6g}", narrowest.centre[d]));
    root.table("mpm", "", true)->fail(
        "grid.cell_size",
        fmt::format("the narrowest seepage cell, {:.6g} m wide (at ({}) m), holds {} {} of particles {:.4g} m "
                    "apart ({} rows need {:.6g} m): as little as {:.0f} % of it in particles, and cells below "
                    "coupling.open_below = {:g} read as open space and miss the coal's volume change; refine the "
                    "MPM (grid.cell_size, bodies' particles_per_cell) or coarsen the seepage mesh",
                    narrowest.width, fmt::join(centre, ", "), per_row, per_row == 1 ? "row" : "rows", spacing, per_row + 1,
                    (per_row + 1) * spacing, 100 * least_fill, s.coupling.gas_solid.open_below));
  }
  mpm::check_time_step(*root.table("mpm", "", true), s.solid);
  return s;
}

template <int Dim>
CoupledSetup<Dim> read_coupled_setup(scene::Table root) {
  CoupledSetup<Dim> s = read_coupled_scene<Dim>(root);
  if (s.coupling.gas_solid.biot_storage) choose_window_pressure(root, s);
  return s;
}

template <int Dim>
CoupledModel<Dim>::CoupledModel(CoupledSetup<Dim> setup, bool settle_later) : setup_(std::move(setup)) {
  auto& seep = setup_.seepage;
  auto& solid = setup_.solid;
  const CouplingSetup& cs = setup_.coupling;
  // The solver keeps the one copy of the mesh; the mapping reads it through
  // the solver's sampler.
  seepage_ = std::make_unique<seepage::SolverOf<Dim>>(std::move(seep.mesh), seep.model, seep.settings);
  solid_ = std::make_unique<mpm::Solver<Dim>>(solid.grid, std::move(solid.materials), std::move(solid.particles),
                                              solid.settings);
  mapping_ = std::make_unique<MeshMapping<Dim>>(seepage_->sampler());
  GasSolidSettings gas_solid = cs.gas_solid;
  if (cs.fixed_stress_split.value_or(false)) {
    // The softest coal's drained bulk modulus: the split's stabilisation must
    // hold there.
    double bulk = std::numeric_limits<double>::infinity();
    for (std::size_t m = 0; m < solid_->materials().size(); ++m) {
      const auto& e = solid_->materials()[m]->elasticity();
      const double softest = modulus_scale_range(solid_->particles(), static_cast<int>(m)).front();
      bulk = std::min(bulk, softest * (e.lame_lambda() + 2.0 / 3.0 * e.shear_modulus()));
    }
    gas_solid.fixed_stress = gas_solid.biot * gas_solid.biot / bulk;
  }
  gas_solid.window_pressure = cs.window_pressure.value_or(stability::Pressure::ramp);
  seepage_side_ = std::make_unique<SeepageParticipant<Dim>>(*seepage_, gas_solid);
  solid_side_ = std::make_unique<SolidParticipant<Dim>>(*solid_, *mapping_, gas_solid, seepage_side_->read(std::string(pressure_field)),
                                                   solid.fixed_time_step);
  if (cs.total_initial_stress) {
    std::vector<double> cell_pressure;
    for (const int region : mapping_->mesh().cell_region)
      cell_pressure.push_back(seep.model.materials[static_cast<std::size_t>(region)].initial_pressure);
    solid_side_->make_initial_stress_effective(cell_pressure);
  }
  coupling_ = std::make_unique<Coupling>(*seepage_side_, *solid_side_, cs.scheme);
  if (solid.settling.duration > 0 && !settle_later) settle({});
}

// The gas pressure starts uniform in each region: no gas force while settling.
template <int Dim>
bool CoupledModel<Dim>::settle(const std::function<bool()>& pause) {
  settled_ = solid_->settle(setup_.solid.settling, setup_.solid.fixed_time_step, pause);
  return settled_.has_value();
}

template <int Dim>
void CoupledModel<Dim>::save(checkpoint::Out out) const {
  seepage_->save(out.group("seepage"));
  solid_->save(out.group("mpm"));
  seepage_side_->save_between_windows(out.group("seepage_side"));
  solid_side_->save_between_windows(out.group("solid_side"));
  coupling_->save(out.group("coupling"));
}

template <int Dim>
void CoupledModel<Dim>::load(const checkpoint::In& in) {
  seepage_->load(in.group("seepage"));
  solid_->load(in.group("mpm"));
  seepage_side_->load_between_windows(in.group("seepage_side"));
  solid_side_->load_between_windows(in.group("solid_side"));
  coupling_->load(in.group("coupling"));
}

template <int Dim>
const WindowRecord& CoupledModel<Dim>::advance(double limit) {
  return coupling_->advance(std::min(setup_.coupling.window, limit - coupling_->time()));
}

template CoupledSetup<2> read_coupled_scene<2>(scene::Table);
template CoupledSetup<3> read_coupled_scene<3>(scene::Table);
template CoupledSetup<2> read_coupled_setup<2>(scene::Table);
template CoupledSetup<3> read_coupled_setup<3>(scene::Table);
template std::vector<stability::Regime> poroelastic_regimes(const CoupledSetup<2>&);
template std::vector<stability::Regime> poroelastic_regimes(const CoupledSetup<3>&);
template class CoupledModel<2>;
template class CoupledModel<3>;

}  // namespace outburst::coupling
