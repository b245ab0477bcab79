#pragma once
// Constitutive models. A material updates the stress of its own particles from
// their velocity gradient over one step; the solver calls it for a whole
// material or a chunk of its particles, never per particle, so the particle
// loop has no virtual call.
//
// Each model lives in its own file under mpm_solid/materials/: its class, the
// reader of its scene keys and its registration (register_material), so that
// a new model is one file and its test.

#include <algorithm>
#include <cassert>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/scene.hpp"
#include "mpm_solid/particles.hpp"

namespace outburst::mpm {

struct Elasticity {
  double density;          // [kg/m^3]
  double youngs_modulus;   // [Pa]
  double poisson_ratio;

  double shear_modulus() const { return youngs_modulus / (2 * (1 + poisson_ratio)); }
  double lame_lambda() const {
    return youngs_modulus * poisson_ratio / ((1 + poisson_ratio) * (1 - 2 * poisson_ratio));
  }
  // Speed of the fastest (P) wave, which bounds the explicit time step.
  double p_wave_speed() const;
};

// Energy a stress update turns into heat and cracks [J; per m of depth in 2D].
struct Dissipation {
  double plastic = 0;  // plastic work
  double damage = 0;   // strain energy released as damage grows, Y dD
  Dissipation& operator+=(const Dissipation& o) {
    plastic += o.plastic;
    damage += o.damage;
    return *this;
  }
};

// Everything below is written once for plane strain (Dim = 2) and 3D: the
// plane forms are the 3D ones with d_zz = 0. A plane-strain stress is the
// in-plane matrix and the out-of-plane normal stress s_zz beside it; a 3D
// stress matrix holds all of it, and the functions below that take an s_zz
// touch it only in 2D (out_of_plane gives 3D updates a value to pass).
template <int Dim>
class Material {
 public:
  virtual ~Material() = default;
  explicit Material(std::string name, Elasticity elasticity)
      : name_(std::move(name)),
        elasticity_(elasticity),
        lambda_(elasticity.lame_lambda()),
        shear_(elasticity.shear_modulus()) {}

  const std::string& name() const { return name_; }
  const Elasticity& elasticity() const { return elasticity_; }
  // The Lame constants, divided out once: the updates read them per particle.
  double lame_lambda() const { return lambda_; }
  double shear_modulus() const { return shear_; }

  // Creates the optional particle fields the model keeps (plastic strain,
  // damage) and sets those of its own particles, `members`; the solver calls
  // it before the first step.
  virtual void create_fields(Particles<Dim>&, const std::vector<int>& /*members*/) const {}

  // Update the stresses of particles `members` over a step dt from their
  // velocity gradients (objective: Jaumann rate, paper eqs. 31-33), and carry
  // their deformation gradients and volumes over the step. Returns the energy
  // dissipated in the step. All of a material's particles at once, in
  // parallel: by default update_chunk over chunks of them; a law whose
  // update reads other particles (a nonlocal average) overrides this.
  virtual Dissipation update_stress(Particles<Dim>& p, const std::vector<int>& members, double dt) const;

  // The same for a few particles, serially, for a pointwise() material: the
  // solver calls it from inside its own parallel pass, between gathering the
  // chunk's velocity gradients and scattering its forces, while the chunk's
  // fields are still in cache. `gradients`: where the members' velocity
  // gradients are (at most chunk_size members when given; see chunk_size).
  virtual Dissipation update_chunk(Particles<Dim>& p, std::span<const int> members, double dt,
                                   const double* gradients) const = 0;
  // Whether a particle's update reads only its own fields.
  virtual bool pointwise() const { return true; }

  // Strain energy stored in particles `members` [J; per m of depth in 2D].
  virtual double strain_energy(const Particles<Dim>& p, const std::vector<int>& members) const;

  // a : C0^-1 : b for two stress states (C0 the undamaged stiffness); half
  // of it with a = b is the elastic strain energy density.
  double compliance_product(const Mat<Dim>& a, double a_zz, const Mat<Dim>& b, double b_zz) const;

 private:
  std::string name_;
  Elasticity elasticity_;
  double lambda_, shear_;
};

// What a model's reader has beyond its own keys: the material's name and the
// elasticity every model reads, and the grid's cell size [m].
struct MaterialContext {
  std::string name;
  Elasticity elasticity;
  double cell_size;
  int crack_cells;  // cells one crack spreads over (crack_cells in solver.hpp)
};

// A constitutive model a scene can name (`model = "<name>"` in
// [[mpm.materials]]): the reader takes the material's table, reads the
// model's own keys with located errors and returns the material.
struct MaterialModel {
  std::string_view name;
  std::string_view description;  // a few words for the key's help
  std::unique_ptr<Material<2>> (*read_plane)(const scene::Table& table, const MaterialContext& context);
  std::unique_ptr<Material<3>> (*read_solid)(const scene::Table& table, const MaterialContext& context);
  template <int Dim>
  std::unique_ptr<Material<Dim>> read(const scene::Table& table, const MaterialContext& context) const {
    if constexpr (Dim == 2)
      return read_plane(table, context);
    else
      return read_solid(table, context);
  }
};

// The models registered, in a fixed order (by name). The list is taken at the
// first call: not to be called during static initialisation.
const std::vector<MaterialModel>& material_models();
// Adds a model; each model's file calls it once, at static initialisation:
// `[[maybe_unused]] const bool registered = register_material({...});`.
// Two models of one name are a programming error (std::logic_error).
bool register_material(const MaterialModel& model);

// Particle i's out-of-plane stress under plane strain (zz its field); a 3D
// update passes `none`, which the functions below leave alone.
template <int Dim>
[[gnu::always_inline]] inline double& out_of_plane(std::vector<double>& zz, int i, double& none) {
  if constexpr (Dim == 2)
    return zz[static_cast<std::size_t>(i)];
  else
    return none;
}

// Particles per chunk of a pass that runs a material's update between
// other work on the same particles: a chunk's fields and stencils stay in
// the first cache levels (quadratic B-spline stencils, as StencilLanes holds
// them, take 7 kB in the plane and 11 kB in 3D at this size).
//
// Where a stress update reads the velocity gradients of a chunk's members:
// null, each particle's own p.velocity_gradient (the solver's split passes
// store it); else a chunk's, one SIMD lane per member, entry e = r + Dim c
// (Eigen's order) of member k at gradients[e * chunk_size + k]. The fused
// pass keeps them so, out of the particles' arrays, whose stores were a
// measurable share of its step (docs/performance/log.md#the-mpm-kernel).
inline constexpr int chunk_size = 64;

// A split pass's stress update reads p.velocity_gradient, which only runs
// whose transfer stores it carry (Particles::need_velocity_gradients): a
// clear error before the parallel loop, rather than a read of an empty field.
template <int Dim>
void require_velocity_gradients(const Particles<Dim>& p, const std::vector<int>& members) {
  if (!members.empty() && p.velocity_gradient.size() != p.size())
    throw std::logic_error("a material's update_stress: the particles store no velocity gradients "
                           "(Particles::need_velocity_gradients)");
}

// f(std::integral_constant<int, 0>{}), ..., f(std::integral_constant<int, N - 1>{}):
// a small loop written out at compile time.
template <int N, class F>
[[gnu::always_inline]] inline void unrolled(F&& f) {
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (f(std::integral_constant<int, I>{}), ...);
  }(std::make_integer_sequence<int, N>{});
}

// a b + c as Eigen's packet products form it: one rounding where the CPU
// fuses them (Eigen's pmadd), two where it does not.
[[gnu::always_inline]] inline double packet_madd(double a, double b, double c) {
#ifdef __FMA__
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

// The step's kinematics and elastic trial of particles index(0), ...,
// index(n - 1), shared by every model: F <- (I + dt L) F, V = V0 det F, and
// the Jaumann-rate linear elastic trial of `stress` (and, in the plane, its
// zz part) with Lame constants lambda and G, both scaled by the particle's
// stiffness(i) (a heterogeneous draw). In the plane one particle per SIMD
// lane, each particle's arithmetic Eigen's for the same expressions (its
// evaluation order, and its fused products for 2 x 2 matrices), so that the
// lanes move no result: the same bits, where the compiler fuses no products
// of its own (-DOUTBURST_NO_FP_CONTRACTION=ON, scripts/compare-builds.sh). In
// 3D one particle at a time: a particle's nine entries, 72 bytes apart, make
// GCC's vector loads gathers, and the lanes ran a linear elastic 3D step 9 %
// slower. The 3D order is Eigen's too, but for the Jaumann rotation's
// products, which Eigen fused in some contexts and not in others: a few
// stress entries moved by an ulp.
template <int Dim, class Index, class Stiffness, class Gradient>
[[gnu::always_inline]] inline void deform_and_trial(Particles<Dim>& p, int n, Index index, Stiffness stiffness,
                                                    Gradient gradient, double dt, double lambda, double shear,
                                                    Mat<Dim>* stress, double* stress_zz) {
  constexpr int entries = Dim * Dim;
  // Entry e = r + Dim c of a matrix is (r, c): Eigen's column-major order,
  // and the matrices of a field follow each other unpadded.
  static_assert(!Mat<Dim>::IsRowMajor && sizeof(Mat<Dim>) == entries * sizeof(double));
  constexpr auto at = [](int r, int c) { return r + Dim * c; };
  constexpr auto diagonal = [](int e) { return e % (Dim + 1) == 0 ? 1.0 : 0.0; };
  // Every field by a local pointer: read through the particles' vectors,
  // the volumes' base was loaded again in the loop, and GCC loaded and
  // stored them by gathers and scatters (a sixth of the elastic trial's
  // time, perf).
  double* const f_all = p.deformation.data()->data();
  double* const s_all = stress->data();
  double* const volume = p.volume.data();
  const double* const volume0 = p.volume0.data();
#pragma omp simd if(Dim == 2)
  for (int k = 0; k < n; ++k) {
    // Straight-line code (the small loops written out at compile time): GCC
    // vectorises it over the particles where it leaves nested loops alone.
    const std::ptrdiff_t i = index(k);
    double l[entries];
    unrolled<entries>([&](auto e) { l[e] = gradient(k, i, e); });
    double* f = f_all + entries * i;
    double* s = s_all + entries * i;
    // F <- (I + dt L) F as Eigen forms it: a column's leading pair of rows
    // in a packet (fused multiply-adds over the inner index), the third row
    // of a 3 x 3 coefficient-wise (the inner sum split in halves).
    double a[entries], g[entries];
    unrolled<entries>([&](auto e) { a[e] = diagonal(e) + dt * l[e]; });
    unrolled<entries>([&](auto e) {
      constexpr int r = e % Dim, c = e / Dim;
      if constexpr (Dim == 2)
        g[e] = packet_madd(a[at(r, 1)], f[at(1, c)], a[at(r, 0)] * f[at(0, c)]);
      else if constexpr (r < 2)
        g[e] = packet_madd(a[at(r, 2)], f[at(2, c)], packet_madd(a[at(r, 1)], f[at(1, c)], a[at(r, 0)] * f[at(0, c)]));
      else
        g[e] = a[at(r, 0)] * f[at(0, c)] + (a[at(r, 1)] * f[at(1, c)] + a[at(r, 2)] * f[at(2, c)]);
    });
    double det;
    if constexpr (Dim == 2) {
      det = g[at(0, 0)] * g[at(1, 1)] - g[at(1, 0)] * g[at(0, 1)];
    } else {
      const auto minor = [&](int a0, int b, int c) {
        return g[at(0, a0)] * (g[at(1, b)] * g[at(2, c)] - g[at(1, c)] * g[at(2, b)]);
      };
      det = minor(0, 1, 2) - minor(1, 0, 2) + minor(2, 0, 1);
    }
    unrolled<entries>([&](auto e) { f[e] = g[e]; });
    volume[i] = volume0[i] * det;
    // sigma' = sigma + dt (lambda tr(D) I + 2 G D + W sigma - sigma W), D and
    // W the symmetric and skew parts of L (plane strain: d_zz = 0).
    const double scale = stiffness(i);
    const double lam = scale * lambda, g2 = 2 * (scale * shear);
    double d[entries], w[entries], rot[entries];
    unrolled<entries>([&](auto e) {
      constexpr int r = e % Dim, c = e / Dim;
      d[e] = 0.5 * (l[e] + l[at(c, r)]);
      w[e] = 0.5 * (l[e] - l[at(c, r)]);
    });
    const double trace = Dim == 2 ? d[0] + d[3] : d[0] + (d[4] + d[8]);
    const double volumetric = lam * trace;
    unrolled<entries>([&](auto e) {
      constexpr int r = e % Dim, c = e / Dim;
      // W sigma - sigma W: Eigen's packet products in the plane (a fused
      // multiply-add over the inner index), coefficient ones in 3D.
      if constexpr (Dim == 2)
        rot[e] = packet_madd(w[at(r, 1)], s[at(1, c)], w[at(r, 0)] * s[at(0, c)]) -
                 packet_madd(s[at(r, 1)], w[at(1, c)], s[at(r, 0)] * w[at(0, c)]);
      else
        rot[e] = (w[at(r, 0)] * s[at(0, c)] + (w[at(r, 1)] * s[at(1, c)] + w[at(r, 2)] * s[at(2, c)])) -
                 (s[at(r, 0)] * w[at(0, c)] + (s[at(r, 1)] * w[at(1, c)] + s[at(r, 2)] * w[at(2, c)]));
    });
    unrolled<entries>([&](auto e) { s[e] += dt * (volumetric * diagonal(e) + g2 * d[e] + rot[e]); });
    if constexpr (Dim == 2) stress_zz[i] += dt * lam * trace;
  }
}

// f(index), index(k) the particle of a chunk's k-th member (none empty):
// consecutive members (every material, unless bodies of two interleave) by
// position, so that SIMD lanes load them as a block, the rest from the list.
template <class F>
[[gnu::always_inline]] inline decltype(auto) by_position(std::span<const int> members, F&& f) {
  const int first = members.front();
  if (members.back() - first == static_cast<int>(members.size()) - 1) return f([first](int k) { return first + k; });
  return f([members](int k) { return members[static_cast<std::size_t>(k)]; });
}

// The same over a chunk of a material's members, in increasing order, none
// twice (as material_members lists them): the lanes write each its own
// particle.
// The members' velocity gradients as `gradients` says (null: their own;
// see chunk_size), and at most chunk_size members when they are a chunk's.
template <int Dim>
void deform_and_trial(Particles<Dim>& p, std::span<const int> members, double dt, double lambda, double shear,
                      const std::vector<double>* stiffness, std::vector<Mat<Dim>>& stress,
                      std::vector<double>& stress_zz, const double* gradients = nullptr) {
  assert(std::adjacent_find(members.begin(), members.end(), std::greater_equal<>()) == members.end());
  assert(!gradients || members.size() <= static_cast<std::size_t>(chunk_size));
  if (members.empty()) return;
  const int n = static_cast<int>(members.size());
  double* zz = Dim == 2 ? stress_zz.data() : nullptr;
  const auto with_gradients = [&](auto index, auto scale) __attribute__((always_inline)) {
    if (gradients) {
      deform_and_trial(
          p, n, index, scale, [gradients](int k, std::ptrdiff_t, int e) { return gradients[e * chunk_size + k]; },
          dt, lambda, shear, stress.data(), zz);
    } else {
      const double* own = p.velocity_gradient.data()->data();
      deform_and_trial(
          p, n, index, scale, [own](int, std::ptrdiff_t i, int e) { return own[Dim * Dim * i + e]; }, dt, lambda,
          shear, stress.data(), zz);
    }
  };
  by_position(members, [&](auto index) {
    if (stiffness)
      with_gradients(index, [scale = stiffness->data()](std::ptrdiff_t i) { return scale[i]; });
    else
      with_gradients(index, [](std::ptrdiff_t) { return 1.0; });
  });
}

// Mean stress and deviator (plane strain: zz included in both).
template <int Dim>
struct Invariants {
  double mean;          // I1 / 3
  Mat<Dim> deviator;    // of the matrix part of the stress
  double deviator_zz;   // plane strain's; 0 in 3D
  double sqrt_j2;
};
template <int Dim>
inline Invariants<Dim> invariants(const Mat<Dim>& s, double s_zz) {
  Invariants<Dim> r;
  if constexpr (Dim == 2) {
    r.mean = (s.trace() + s_zz) / 3;
    r.deviator = s - r.mean * Mat<Dim>::Identity();
    r.deviator_zz = s_zz - r.mean;
    r.sqrt_j2 = std::sqrt(0.5 * (r.deviator.squaredNorm() + r.deviator_zz * r.deviator_zz));
  } else {
    r.mean = s.trace() / 3;
    r.deviator = s - r.mean * Mat<Dim>::Identity();
    r.deviator_zz = 0;
    r.sqrt_j2 = std::sqrt(0.5 * r.deviator.squaredNorm());
  }
  return r;
}

template <int Dim>
inline double Material<Dim>::compliance_product(const Mat<Dim>& a, double a_zz, const Mat<Dim>& b,
                                                double b_zz) const {
  const auto ia = invariants<Dim>(a, a_zz), ib = invariants<Dim>(b, b_zz);
  const double g = shear_, bulk = lambda_ + 2.0 / 3.0 * g;
  const double deviatoric = ia.deviator.cwiseProduct(ib.deviator).sum() + ia.deviator_zz * ib.deviator_zz;
  return deviatoric / (2 * g) + ia.mean * ib.mean / bulk;
}

// Drucker-Prager cones fitted to Mohr-Coulomb (paper eqs. 36-37):
//   f = alpha I1/3 + sqrt(J2) - k,   tension positive.
struct DruckerPragerFit {
  enum class Kind { outer, inner, plane_strain };
  // alpha and k of f = alpha I1/3 + sqrt(J2) - k.
  static std::pair<double, double> coefficients(Kind kind, double cohesion, double friction_angle);
};

// Return a trial stress to the cone f = alpha I1/3 + sqrt(J2) - k (or its apex)
// with the potential's alpha_dilation; G and K the elastic moduli. Returns the
// plastic multiplier and, if asked, the plastic work density [J/m^3].
template <int Dim>
inline double drucker_prager_return(double alpha, double k, double alpha_dilation, double g, double bulk,
                                    Mat<Dim>& s, double& s_zz, double* work_density) {
  const auto inv = invariants<Dim>(s, s_zz);
  const double f = alpha * inv.mean + inv.sqrt_j2 - k;
  if (f <= 0) return 0;
  // Flow along dg/dsigma = (alpha_d / 3) I + s / (2 sqrt(J2)): the mean stress
  // drops by K alpha_d dlambda and sqrt(J2) by G dlambda.
  double dlambda = f / (g + bulk * alpha * alpha_dilation);
  double mean = inv.mean - bulk * alpha_dilation * dlambda;
  double sqrt_j2 = inv.sqrt_j2 - g * dlambda;
  if (sqrt_j2 < 0) {
    // Past the tip: the only admissible state is hydrostatic, at the apex of a
    // cone (alpha > 0). A cylinder (alpha = 0, no friction) gets here only by
    // round-off, when its radius k is 0 (no cohesion either: a fluid's
    // strength): the deviator goes, the mean stress stays (k / alpha was 0 / 0).
    if (alpha > 0) mean = k / alpha;
    sqrt_j2 = 0;
    dlambda = inv.sqrt_j2 / g;
  }
  const double scale = inv.sqrt_j2 > 0 ? sqrt_j2 / inv.sqrt_j2 : 0.0;
  s = mean * Mat<Dim>::Identity() + scale * inv.deviator;
  if constexpr (Dim == 2) s_zz = mean + scale * inv.deviator_zz;
  // Plastic work sigma : C^-1 : (sigma_trial - sigma): the deviator only shrinks
  // along itself, so its part is sqrt(J2) (sqrt(J2)_trial - sqrt(J2)) / G.
  if (work_density) *work_density = sqrt_j2 * (inv.sqrt_j2 - sqrt_j2) / g + mean * (inv.mean - mean) / bulk;
  return dlambda;
}

// Runs update(i), what remains of particle i's stress update after
// deform_and_trial, returning what it dissipated, over `members` in turn.
template <class Update>
Dissipation each_member(std::span<const int> members, Update&& update) {
  Dissipation total;
  for (const int i : members) total += update(i);
  return total;
}

// Runs chunk(part), returning what it dissipated, over chunks of `members`
// in parallel, and sums what they dissipated.
template <class Chunk>
Dissipation over_chunks(const std::vector<int>& members, Chunk&& chunk) {
  const int n = static_cast<int>(members.size()), chunks = (n + chunk_size - 1) / chunk_size;
  const std::span<const int> all(members);
  double plastic = 0, damage = 0;
#pragma omp parallel for schedule(static) reduction(+ : plastic, damage)
  for (int c = 0; c < chunks; ++c) {
    const int first = c * chunk_size;
    const Dissipation d = chunk(all.subspan(first, std::min(chunk_size, n - first)));
    plastic += d.plastic;
    damage += d.damage;
  }
  return {plastic, damage};
}

// Sum of f(i) over the members, in parallel.
template <class F>
double sum_over(const std::vector<int>& members, F&& f) {
  const int n = static_cast<int>(members.size());
  double sum = 0;
#pragma omp parallel for schedule(static) reduction(+ : sum)
  for (int k = 0; k < n; ++k) sum += f(members[k]);
  return sum;
}

}  // namespace outburst::mpm
