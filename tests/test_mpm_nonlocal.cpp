// The nonlocal average (mpm_solid/nonlocal.hpp) against its definition: a
// uniform field stays uniform, up to a free surface; a linear field is kept
// where a particle's neighbourhood is whole (the bell weight is symmetric);
// and on scattered particles the binned sum equals the sum over every pair.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "mpm_solid/nonlocal.hpp"

using namespace outburst::mpm;

namespace {

struct Cloud {
  std::vector<Vec<2>> x;
  std::vector<int> members;
  std::vector<double> weight;  // per member
};

// A lattice of n x n particles of spacing a, the members every particle but
// the first `skip` (particles outside the material).
Cloud lattice(int n, double a, int skip = 0) {
  Cloud c;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      c.x.emplace_back((i + 0.5) * a, (j + 0.5) * a);
    }
  for (int k = skip; k < n * n; ++k) {
    c.members.push_back(k);
    c.weight.push_back(a * a);
  }
  return c;
}

}  // namespace

TEST_CASE("nonlocal average: a uniform field stays uniform, a linear one inside the body too", "[mpm][nonlocal]") {
  const double a = 0.01, radius = 0.037;
  const Cloud c = lattice(40, a, 3);
  std::vector<double> uniform(c.members.size(), 2.5), linear;
  for (const int i : c.members) linear.push_back(3 * c.x[i].x() - 7 * c.x[i].y());
  const auto u = nonlocal_average(c.x, c.members, c.weight, uniform, radius);
  const auto l = nonlocal_average(c.x, c.members, c.weight, linear, radius);
  int inside = 0;
  for (std::size_t k = 0; k < c.members.size(); ++k) {
    CHECK(u[k] == Approx(2.5).epsilon(1e-14));
    const Vec<2>& x = c.x[c.members[k]];
    if (x.minCoeff() > radius && x.maxCoeff() < 40 * a - radius) {
      ++inside;
      CHECK(l[k] == Approx(linear[k]).margin(1e-12));
    }
  }
  CHECK(inside > 500);
  // At a corner the neighbourhood lies on one side: the average is pulled
  // into the body.
  CHECK(l[0] != Approx(linear[0]).margin(1e-6));
}

TEST_CASE("nonlocal average: binned neighbours give the sum over every pair, on scattered particles of mixed weight",
          "[mpm][nonlocal]") {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> along(-1.0, 2.0), size(0.5, 1.5);
  Cloud c;
  for (int k = 0; k < 1500; ++k) {
    c.x.emplace_back(along(random), along(random));
    if (k % 3 == 0) continue;  // a third belong to another material
    c.members.push_back(k);
    c.weight.push_back(k % 7 ? 1e-3 * size(random) : 0.0);  // some broken: no share in their neighbours' averages
  }
  c.x.emplace_back(1e6, -1e6);  // a fragment far from the rest: no bins between
  c.members.push_back(1500);
  c.weight.push_back(1e-3);
  const double radius = GENERATE(0.05, 0.2, 1.0);
  std::vector<double> value;
  for (const int i : c.members) value.push_back(std::sin(3 * c.x[i].x()) + c.x[i].y() * c.x[i].y());
  const auto binned = nonlocal_average(c.x, c.members, c.weight, value, radius);
  for (std::size_t k = 0; k < c.members.size(); ++k) {
    double weighted = 0, weights = 0;
    for (std::size_t j = 0; j < c.members.size(); ++j) {
      const double r2 = (c.x[c.members[j]] - c.x[c.members[k]]).squaredNorm() / (radius * radius);
      if (r2 >= 1) continue;
      const double w = c.weight[j] * (1 - r2) * (1 - r2);
      weighted += w * value[j];
      weights += w;
    }
    INFO("member " << k << ", radius " << radius);
    CHECK(binned[k] == Approx(weights > 0 ? weighted / weights : value[k]).epsilon(1e-12));
  }
  CHECK(binned.back() == value.back());  // alone within R
}
