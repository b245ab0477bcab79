#include "coupler/mapping.hpp"

namespace outburst::coupling {

MeshMapping::MeshMapping(seepage::Mesh mesh) : mesh_(std::move(mesh)), locator_(mesh_) {
  area_.resize(mesh_.num_cells());
  for (std::size_t c = 0; c < mesh_.num_cells(); ++c) area_[c] = seepage::q1::integrals(mesh_.corners(c)).lumped.sum();
}

std::optional<MeshMapping::Sample> MeshMapping::sample(const Eigen::VectorXd& nodal, const Eigen::Vector2d& x,
                                                      int* hint) const {
  const auto hit = locator_.locate(x, hint);
  if (!hit) return std::nullopt;
  const auto c = static_cast<std::size_t>(hit->cell);
  return seepage::q1::sample(mesh_.corners(c), mesh_.cells[c], nodal, hit->reference);
}

int MeshMapping::cell_of(const Eigen::Vector2d& x) const {
  const auto hit = locator_.locate(x);
  return hit ? hit->cell : -1;
}

MeshMapping::Averages MeshMapping::average(const std::vector<Eigen::Vector2d>& points,
                                           const std::vector<double>& volume, const std::vector<double>& values,
                                           int components) const {
  const std::size_t nc = mesh_.num_cells(), k = static_cast<std::size_t>(components);
  Averages a{std::vector<double>(nc, 0.0), std::vector<double>(nc * k, 0.0)};
  for (std::size_t p = 0; p < points.size(); ++p) {
    const int c = cell_of(points[p]);
    if (c < 0) continue;
    const auto cell = static_cast<std::size_t>(c);
    a.fraction[cell] += volume[p];
    for (std::size_t j = 0; j < k; ++j) a.mean[cell * k + j] += volume[p] * values[p * k + j];
  }
  for (std::size_t c = 0; c < nc; ++c) {
    if (a.fraction[c] > 0)
      for (std::size_t j = 0; j < k; ++j) a.mean[c * k + j] /= a.fraction[c];
    a.fraction[c] /= area_[c];
  }
  return a;
}

}  // namespace outburst::coupling
