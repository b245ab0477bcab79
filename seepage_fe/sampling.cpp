#include "seepage_fe/sampling.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "seepage_fe/q1.hpp"

namespace outburst::seepage {

template <int Dim>
SamplerOf<Dim>::SamplerOf(const MeshOf<Dim>& mesh) : mesh_(mesh), locator_(mesh), area_(mesh.num_cells()) {
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c) area_[c] = q1::integrals(mesh_.corners(c)).lumped.sum();
}

template <int Dim>
auto SamplerOf<Dim>::sample(const Eigen::VectorXd& nodal, const Point& x, int* hint) const -> std::optional<Value> {
  const auto hit = locator_.locate(x, hint);
  if (!hit) return std::nullopt;
  const auto c = static_cast<std::size_t>(hit->cell);
  const auto s = hit->inverse_jacobian
                     ? q1::sample_affine(mesh_.cells[c], nodal, hit->reference, *hit->inverse_jacobian)
                     : q1::sample(mesh_.corners(c), mesh_.cells[c], nodal, hit->reference);
  return Value{s.value, s.gradient};
}

template <int Dim>
void SamplerOf<Dim>::sample(const Eigen::VectorXd& nodal, const double* x, int count, int* hint, Batch& out) const {
  if (count < 0 || count > batch_lanes)
    throw std::invalid_argument(fmt::format("seepage sampler: a batch of {} points, expected 0 to {}", count,
                                            batch_lanes));
  const int cells = static_cast<int>(mesh_.num_cells());
  const auto* maps = locator_.affine_maps().data();
  const auto* nodes = mesh_.cells.data();
  const double* u = nodal.data();
  constexpr int corners = MeshOf<Dim>::cell_corners;
  // Each lane's cell map and corner values, copied one lane at a time: read
  // by cell inside the SIMD loop, they kept it scalar (GCC 12 found no
  // gather for them). A hint that names no cell reads cell 0, and the lane
  // fails.
  alignas(64) double centre[Dim][batch_lanes], inverse[Dim * Dim][batch_lanes], corner[corners][batch_lanes],
      known[batch_lanes];
  for (int k = 0; k < count; ++k) {
    const bool valid = hint[k] >= 0 && hint[k] < cells;
    const std::size_t c = valid ? static_cast<std::size_t>(hint[k]) : 0;
    known[k] = valid;
    for (int e = 0; e < Dim; ++e) centre[e][k] = maps[c].centre[e];
    for (int e = 0; e < Dim * Dim; ++e) inverse[e][k] = maps[c].inverse_jacobian.data()[e];
    for (int a = 0; a < corners; ++a) corner[a][k] = u[nodes[c][a]];
  }
  alignas(64) double ref[Dim][batch_lanes];
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    const auto g = [&](int r, int e) { return inverse[r + Dim * e][k]; };
    const auto at_corner = [&](int a) { return corner[a][k]; };
    const bool inside = CellLocatorOf<Dim>::reference_in([&](int e) { return x[Dim * k + e]; },
                                                         [&](int e) { return centre[e][k]; }, g,
                                                         [&](int r, double v) { ref[r][k] = v; });
    if constexpr (Dim == 2)
      q1::sample_affine(at_corner, ref[0][k], ref[1][k], g, out.value[k], out.gradient[0][k], out.gradient[1][k]);
    else
      q1::sample_affine(at_corner, ref[0][k], ref[1][k], ref[2][k], g, out.value[k], out.gradient[0][k],
                        out.gradient[1][k], out.gradient[2][k]);
    out.found[k] = inside ? known[k] : 0.0;
  }
  out.by_lanes = count;
  for (int k = 0; k < count; ++k) {
    if (out.found[k] != 0) continue;
    --out.by_lanes;
    const auto s = sample(nodal, Point(Eigen::Map<const Point>(x + Dim * k)), hint + k);
    out.found[k] = s.has_value();
    out.value[k] = s ? s->value : 0.0;
    for (int d = 0; d < Dim; ++d) out.gradient[d][k] = s ? s->gradient[d] : 0.0;
  }
}

template <int Dim>
int SamplerOf<Dim>::cell_of(const Point& x, int* hint) const {
  const auto hit = locator_.locate(x, hint);
  return hit ? hit->cell : -1;
}

template class SamplerOf<2>;
template class SamplerOf<3>;

}  // namespace outburst::seepage
