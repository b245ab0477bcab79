#pragma once
// The BLAS behind CHOLMOD. Debian resolves libblas.so.3 through its alternatives;
// with OpenBLAS installed it is OpenBLAS, whose threads pay off only for large
// factorisations (on small ones their start-up and spinning cost more than the
// work: 10x in our seepage tests), so solvers set the count from their size.

#include <omp.h>

#include <string>

namespace outburst::blas {

// "OpenBLAS 0.3.21 ..." or a note that the reference BLAS is in use.
std::string description();
// Runs f with OpenMP regions serialised. Debian's CHOLMOD opens OpenMP regions
// of 4 threads inside each supernodal factorisation, whatever the machine; on
// top of OpenBLAS's own threads that oversubscribes 2 cores (2-3x slower, worse
// under load). Its BLAS calls, where the work is, keep their threads.
template <typename F>
void without_openmp_regions(F&& f);

// Sets OpenBLAS's thread count; does nothing with another BLAS.
void set_threads(int threads);
// One thread below `unknowns_per_thread` unknowns per thread, else all cores.
void set_threads_for(long unknowns);

template <typename F>
void without_openmp_regions(F&& f) {
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(0);
  f();
  omp_set_max_active_levels(levels);
}

}  // namespace outburst::blas
