#pragma once
// A seepage mesh's nodal fields read at arbitrary points (particle positions,
// probes), and the cell holding a point: the face the seepage shows other
// parts (the coupler), so that they need neither its cell search nor its
// element.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "seepage_fe/cell_locator.hpp"
#include "seepage_fe/mesh.hpp"

namespace outburst::seepage {

template <int Dim>
class SamplerOf {
 public:
  using Point = typename MeshOf<Dim>::Point;

  // Refers to `mesh`, which must outlive it and stay put.
  explicit SamplerOf(const MeshOf<Dim>& mesh);
  SamplerOf(const SamplerOf&) = delete;
  SamplerOf& operator=(const SamplerOf&) = delete;

  const MeshOf<Dim>& mesh() const { return mesh_; }
  // The area (3D: volume) of each cell [m2, m3].
  const std::vector<double>& cell_area() const { return area_; }

  struct Value {
    double value;
    Point gradient;
  };
  // A nodal field (indexed by node) and its gradient at x, by the Q1 shape
  // functions of the cell holding it; nullopt outside the mesh. `hint`: a
  // cell to try first, updated to the cell found (any hint is safe; a wrong
  // one costs one test).
  std::optional<Value> sample(const Eigen::VectorXd& nodal, const Point& x, int* hint = nullptr) const;
  // The cell holding x, or -1.
  int cell_of(const Point& x, int* hint = nullptr) const;

 private:
  const MeshOf<Dim>& mesh_;
  CellLocatorOf<Dim> locator_;
  std::vector<double> area_;
};

using Sampler = SamplerOf<2>;

}  // namespace outburst::seepage
