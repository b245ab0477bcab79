#include "common/blas.hpp"

#include <dlfcn.h>
#include <omp.h>

#include <algorithm>

namespace outburst::blas {

namespace {

template <typename F>
F lookup(const char* name) {
  return reinterpret_cast<F>(::dlsym(RTLD_DEFAULT, name));
}

}  // namespace

std::string description() {
  if (const auto config = lookup<char* (*)()>("openblas_get_config")) return std::string("OpenBLAS ") + config();
  return "not OpenBLAS (reference BLAS is 4-8x slower for CHOLMOD: apt-get install libopenblas-dev)";
}

void set_threads(int threads) {
  if (const auto set = lookup<void (*)(int)>("openblas_set_num_threads")) set(std::max(1, threads));
}

void set_threads_for(long unknowns) {
  constexpr long unknowns_per_thread = 100000;
  set_threads(static_cast<int>(std::clamp<long>(unknowns / unknowns_per_thread, 1, omp_get_max_threads())));
}

}  // namespace outburst::blas
