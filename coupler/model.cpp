#include "coupler/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace outburst::coupling {

CoupledSetup read_coupled_setup(scene::Table root) {
  CoupledSetup s;
  s.header = read_scene_header(root);
  require_solvers(root, s.header, {"seepage", "mpm"}, "outburst");
  if (s.header.solvers.size() != 2)
    root.table("scene", "", true)->fail("solvers", "outburst couples \"seepage\" and \"mpm\"; run seepage-fe or "
                                                   "mpm-solid for one alone");
  s.seepage = seepage::read_setup(*root.table("seepage", "the gas seepage solver", true), false);
  s.solid = mpm::read_setup(*root.table("mpm", "the material point solver", true));
  const auto coupling = root.table("coupling", "the gas-solid coupling", true);
  s.coupling = read_coupling(*coupling);
  if (s.coupling.gas_solid.biot_storage && s.seepage.model.law != seepage::Law::linear)
    coupling->fail("biot_storage", "the Biot storage term is written for the linear Darcy law: set seepage.law = "
                                   "\"linear\" or drop the key");
  // Seepage cells off the MPM grid never hold coal: they would read as open
  // space and release their gas at once.
  Eigen::Vector2d lo = s.seepage.mesh.nodes.front(), hi = lo;
  for (const auto& x : s.seepage.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  if (const auto past = mpm::overhang(s.solid.grid, lo, hi); !past.empty()) {
    const auto mesh = root.table("seepage", "", true)->table("mesh", "", true);
    mesh->fail(mesh->has("file") ? "file" : "origin",
               fmt::format("the seepage mesh, [{:g}, {:g}] x [{:g}, {:g}] m, reaches {}: its cells there hold no coal "
                           "and would read as open space",
                           lo.x(), hi.x(), lo.y(), hi.y(), past));
  }
  // Every seepage cell the coal fills must read as coal: one without a
  // particle, or with fewer than open_below of its area in particles, reads as
  // open space and misses the coal's volume change (measured: Mandel's
  // pressure grows without bound with particles 0.0625 m apart on 0.05 m
  // cells; the outburst's seam opened whole with particles 1/6 m apart on
  // 0.25 m cells, one to a row in some: 44 % full).
  double spacing = 0, narrowest = std::numeric_limits<double>::infinity();
  for (double w : s.solid.particles.half_width) spacing = std::max(spacing, 2 * w * s.solid.grid.h);
  for (std::size_t c = 0; c < s.seepage.mesh.num_cells(); ++c) {
    const auto x = s.seepage.mesh.corners(c);
    for (int k = 0; k < 4; ++k) narrowest = std::min(narrowest, (x[(k + 1) % 4] - x[k]).norm());
  }
  const double per_row = std::floor(narrowest / spacing * (1 + 1e-9));
  const double least_fill = std::pow(per_row * spacing / narrowest, 2);
  if (per_row < 1 || least_fill < s.coupling.gas_solid.open_below)
    root.table("mpm", "", true)->fail(
        "grid.cell_size",
        fmt::format("particles {:.4g} m apart fill a seepage cell {:.4g} m wide to as little as {:.0f} % (cells "
                    "below coupling.open_below = {:g} read as open space and miss the coal's volume change): "
                    "refine the MPM (grid.cell_size, bodies' particles_per_cell) or coarsen the seepage mesh",
                    spacing, narrowest, 100 * least_fill, s.coupling.gas_solid.open_below));
  return s;
}

CoupledModel::CoupledModel(CoupledSetup setup) : setup_(std::move(setup)) {
  auto& seep = setup_.seepage;
  auto& solid = setup_.solid;
  const CouplingSetup& cs = setup_.coupling;
  seepage_ = std::make_unique<seepage::Solver>(seep.mesh, seep.model, seep.settings);
  solid_ = std::make_unique<mpm::Solver>(solid.grid, std::move(solid.materials), std::move(solid.particles),
                                         solid.settings);
  mapping_ = std::make_unique<MeshMapping>(seep.mesh);
  GasSolidSettings gas_solid = cs.gas_solid;
  if (cs.fixed_stress_split) {
    double bulk = std::numeric_limits<double>::infinity();
    for (const auto& m : solid_->materials()) {
      const auto& e = m->elasticity();
      bulk = std::min(bulk, e.lame_lambda() + 2.0 / 3.0 * e.shear_modulus());
    }
    gas_solid.fixed_stress = gas_solid.biot * gas_solid.biot / bulk;
  }
  seepage_side_ = std::make_unique<SeepageParticipant>(*seepage_, gas_solid);
  solid_side_ = std::make_unique<SolidParticipant>(*solid_, *mapping_, gas_solid, seepage_side_->read("pressure"),
                                                   solid.fixed_time_step);
  if (cs.total_initial_stress) {
    std::vector<double> cell_pressure;
    for (const int region : mapping_->mesh().cell_region)
      cell_pressure.push_back(seep.model.materials[static_cast<std::size_t>(region)].initial_pressure);
    solid_side_->make_initial_stress_effective(cell_pressure);
  }
  // The gas pressure starts uniform in each region: no gas force while settling.
  if (solid.settling.duration > 0) settled_ = solid_->settle(solid.settling, solid.fixed_time_step);
  coupling_ = std::make_unique<Coupling>(*seepage_side_, *solid_side_, cs.scheme);
}

const WindowRecord& CoupledModel::advance(double limit) {
  return coupling_->advance(std::min(setup_.coupling.window, limit - coupling_->time()));
}

}  // namespace outburst::coupling
