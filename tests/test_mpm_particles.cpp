// The particle field table: every member once, and removal keeps every field
// aligned, the optional ones included.
#include <catch2/catch.hpp>

#include <set>

#include "mpm_solid/particles.hpp"

using namespace outburst::mpm;

TEST_CASE("the particle field table names every member once", "[mpm][particles]") {
  Particles<2> p;
  std::set<const void*> members;
  std::size_t fields = 0;
  p.for_each_field([&](const auto&, const auto& values) {
    members.insert(&values);
    ++fields;
  });
  CHECK(members.size() == fields);
  CHECK(fields * sizeof(std::vector<double>) == sizeof(Particles<2>));
}

TEST_CASE("removing particles keeps every field aligned, optional ones at their initial values", "[mpm][particles]") {
  Particles<2> p;
  for (int k = 0; k < 5; ++k) p.add(Vec<2>(k, 0), Vec<2>(0, k), 1.0 + k, 1, 0.5, Mat<2>::Identity() * k, k, 0);
  p.need_damage();
  p.need("heterogeneity");
  p.need_loads();
  for (int k = 0; k < 5; ++k) p.damage[k] = 0.1 * k;
  p.add(Vec<2>(5, 0), Vec<2>(0, 5), 6.0, 1, 0.5, Mat<2>::Identity() * 5, 5, 0);  // grows the optional fields
  CHECK(p.strength_scale.back() == 1.0);
  CHECK(p.effective_stress.back() == Mat<2>::Identity() * 5);
  CHECK(p.external_force.back() == Vec<2>::Zero());
  p.keep({1, 0, 1, 0, 0, 1});
  REQUIRE(p.size() == 3);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const int k = p.id[i];
    CHECK(p.x[i].x() == k);
    CHECK(p.mass[i] == 1.0 + k);
    CHECK(p.stress_zz[i] == k);
    CHECK(p.damage[i] == Approx(k < 5 ? 0.1 * k : 0.0));
    CHECK(p.effective_stress[i](0, 0) == k);
    CHECK(p.strength_scale[i] == 1.0);
  }
  // Every field present has one value per particle (pore pressure and
  // plastic strain were never created).
  p.for_each_field([&](const auto& field, const auto& values) {
    INFO(field.name);
    CHECK(values.size() == (values.empty() && field.optional() ? 0 : p.size()));
    if (!field.optional()) CHECK(!values.empty());
  });
}
