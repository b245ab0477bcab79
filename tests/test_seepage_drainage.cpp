// Gas drainage of a half-space through a face (model-notes section 1): pressure
// profile and cumulative emission against the self-similar solution, for the
// paper's face ratio p_f/p0 = 1/30 and for a milder 1/3.
#include <catch2/catch.hpp>

#include <cmath>

#include "convergence.hpp"
#include "seepage_fixtures.hpp"
#include "similarity.hpp"

using namespace outburst;
using namespace outburst::testing;

namespace {

// Nondimensional: lambda = 1, A = 4, p0 = 1, so D0 = 1; the strip is 10 long
// and the front reaches about z = 5 by t = 1, far from the closed far end.
struct DrainageResult {
  double profile_error;   // max |P_h - P| / P0 over the nodes at t = 1
  double emission_error;  // relative error of the gas released by t = 1
};

DrainageResult drain(double face_ratio, const DrainageSimilarity& exact, int cells) {
  auto s = rectangle_solver(seepage::Law::gas, {10, 1}, {cells, 1}, {1.0, 4.0, 1.0},
                            {fixed_pressure("left", face_ratio)}, {}, {20.0, 1.0});
  drain_to_unit_time(s, cells);
  double profile_error = 0;
  for (std::size_t i = 0; i < s.mesh().num_nodes(); ++i)
    profile_error = std::max(profile_error, std::abs(s.unknown()[i] - exact.f(s.mesh().nodes[i].x())));
  const double emitted_exact = 2 * exact.slope_at_face();  // 2 lambda P0 f'(0) sqrt(t/D0), height 1
  return {profile_error, std::abs(s.balance().total_outflow() - emitted_exact) / emitted_exact};
}

}  // namespace

TEST_CASE("the similarity solution is self-consistent", "[seepage][drainage]") {
  for (double ratio : {1.0 / 30, 1.0 / 3}) {
    const DrainageSimilarity exact(ratio * ratio);
    // Emission from the face flux equals the gas missing from the seam: A P0^(1/4)
    // sqrt(D0 t) int (1 - f^(1/4)) dz = 2 lambda P0 f'(0) sqrt(t / D0) with A = 4.
    CHECK(4 * exact.deficit_integral() == Approx(2 * exact.slope_at_face()).epsilon(1e-5));
    CHECK(exact.f(9.0) == Approx(1.0).epsilon(1e-8));
  }
}

TEST_CASE("drainage through a face follows the self-similar solution", "[seepage][drainage]") {
  for (double ratio : {1.0 / 30, 1.0 / 3}) {
    const DrainageSimilarity exact(ratio * ratio);
    std::vector<ConvergenceRow> profile, emission;
    for (int cells : {50, 100, 200}) {
      const auto r = drain(ratio, exact, cells);
      profile.push_back({10.0 / cells, r.profile_error});
      emission.push_back({10.0 / cells, r.emission_error});
    }
    print_convergence("drainage p_f/p0 = " + std::to_string(ratio) + ": max |P_h - P| / P0", "h (mean)",
                      profile);
    print_convergence("drainage p_f/p0 = " + std::to_string(ratio) + ": emission, relative", "h (mean)",
                      emission);
    CHECK(profile.back().error < 5e-5);
    CHECK(emission.back().error < 1e-3);
    for (double order : observed_orders(profile)) CHECK(order > 1.8);
    for (double order : observed_orders(emission)) CHECK(order > 1.5);
  }
}
