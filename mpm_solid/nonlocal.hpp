#pragma once
// Nonlocal averages over material points, for damage with an internal length
// (Pijaudier-Cabot & Bazant 1987; the bell-shaped weight of Bazant & Jirasek
// 2002): a particle's value is replaced by the mean of its neighbours' values
// within the radius R, each weighted by its own weight (its volume, or less)
// times (1 - r^2 / R^2)^2. The weights are normalised by their sum, so a
// uniform field stays uniform at a free surface, where a particle has fewer
// neighbours.

#include <array>
#include <cstdint>
#include <vector>

#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

// One 64-bit key for the integer coordinates of a square (a cube in 3D), to
// sort or hash bins by: two 32-bit coordinates in the plane, three of 21 bits
// in 3D, so that two bins share a key only two million bins apart.
template <int Dim>
std::uint64_t bin_key(const std::array<std::int64_t, Dim>& c) {
  if constexpr (Dim == 2) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c[0])) << 32) | static_cast<std::uint32_t>(c[1]);
  } else {
    const auto bits = [](std::int64_t i) { return static_cast<std::uint64_t>(i) & 0x1fffffu; };
    return (bits(c[0]) << 42) | (bits(c[1]) << 21) | bits(c[2]);
  }
}

// The averages of value[k], the value of particle members[k] of weight
// weight[k], over the members within `radius` of it [m] (itself included; its
// own value where every weight within R is zero); x is indexed by particle.
// O(n log n + n neighbours): the members are binned into squares (cubes in
// 3D) of side R by a sort, so a particle far from the rest costs no empty bins.
template <int Dim>
std::vector<double> nonlocal_average(const std::vector<Vec<Dim>>& x, const std::vector<int>& members,
                                     const std::vector<double>& weight, const std::vector<double>& value,
                                     double radius);

}  // namespace outburst::mpm
