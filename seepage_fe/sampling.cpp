#include "seepage_fe/sampling.hpp"

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
int SamplerOf<Dim>::cell_of(const Point& x, int* hint) const {
  const auto hit = locator_.locate(x, hint);
  return hit ? hit->cell : -1;
}

template class SamplerOf<2>;
template class SamplerOf<3>;

}  // namespace outburst::seepage
