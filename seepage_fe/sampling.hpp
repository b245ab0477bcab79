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

class Sampler {
 public:
  // Refers to `mesh`, which must outlive it and stay put.
  explicit Sampler(const Mesh& mesh);
  Sampler(const Sampler&) = delete;
  Sampler& operator=(const Sampler&) = delete;

  const Mesh& mesh() const { return mesh_; }
  // The area of each cell [m2].
  const std::vector<double>& cell_area() const { return area_; }

  struct Value {
    double value;
    Eigen::Vector2d gradient;
  };
  // A nodal field (indexed by node) and its gradient at x, by the bilinear
  // shape functions of the cell holding it; nullopt outside the mesh. `hint`:
  // a cell to try first, updated to the cell found (any hint is safe; a wrong
  // one costs one test).
  std::optional<Value> sample(const Eigen::VectorXd& nodal, const Eigen::Vector2d& x, int* hint = nullptr) const;
  // The cell holding x, or -1.
  int cell_of(const Eigen::Vector2d& x, int* hint = nullptr) const;

 private:
  const Mesh& mesh_;
  CellLocator locator_;
  std::vector<double> area_;
};

}  // namespace outburst::seepage
