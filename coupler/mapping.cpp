#include "coupler/mapping.hpp"

namespace outburst::coupling {

template <int Dim>
typename MeshMapping<Dim>::Averages MeshMapping<Dim>::average(const std::vector<Point>& points,
                                                              const std::vector<double>& volume,
                                                              const std::vector<double>& values,
                                                              int components) const {
  const std::size_t nc = mesh().num_cells(), k = static_cast<std::size_t>(components);
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
    a.fraction[c] /= cell_area()[c];
  }
  return a;
}

template class MeshMapping<2>;
template class MeshMapping<3>;

}  // namespace outburst::coupling
