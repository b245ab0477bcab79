// The Newton systems' linear solvers: every CHOLMOD mode and ordering the
// benchmark measures must solve the Jacobian, with the ordering asked for.
#include <catch2/catch.hpp>

#include "seepage_fixtures.hpp"

using namespace outburst;
using namespace outburst::testing;

TEST_CASE("every CHOLMOD mode and ordering solves the seepage Jacobian", "[seepage][direct]") {
  auto s = rectangle_solver(seepage::Law::gas, {1, 1}, {30, 30}, {0.1, 2.0, 3.0}, {fixed_pressure("left", 1.0)});
  s.advance(1e-3);
  const auto& j = s.jacobian();
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(j.rows(), 1.0, 2.0);
  const Eigen::VectorXd b = j.selfadjointView<Eigen::Lower>() * x;
  using F = seepage::Factorisation;
  for (auto mode : {F::Mode::simplicial, F::Mode::supernodal})
    for (auto ordering : {F::Ordering::amd, F::Ordering::metis, F::Ordering::nesdis, F::Ordering::cholmod_default}) {
      const F f{mode, ordering};
      seepage::Cholmod factor;
      seepage::configure(factor, f);
      factor.compute(j);
      INFO(f.name());
      REQUIRE(factor.info() == Eigen::Success);
      CHECK((factor.solve(b) - x).lpNorm<Eigen::Infinity>() < 1e-12);
      // The ordering CHOLMOD used, and its mode, are the ones asked for.
      const cholmod_common& c = factor.cholmod();
      const int used = c.method[c.selected].ordering;
      if (ordering == F::Ordering::cholmod_default)
        CHECK((used == CHOLMOD_AMD || used == CHOLMOD_METIS));
      else
        CHECK(used == (ordering == F::Ordering::amd     ? CHOLMOD_AMD
                       : ordering == F::Ordering::metis ? CHOLMOD_METIS
                                                        : CHOLMOD_NESDIS));
      CHECK(c.supernodal == (mode == F::Mode::simplicial ? CHOLMOD_SIMPLICIAL : CHOLMOD_SUPERNODAL));
    }
}
