#pragma once
// The BLAS behind CHOLMOD. Debian resolves libblas.so.3 through its alternatives;
// with OpenBLAS installed it is OpenBLAS, whose threads pay off only for large
// factorisations (on small ones their start-up and spinning cost more than the
// work: 10x in our seepage tests), so solvers set the count from their size.

#include <string>

namespace outburst::blas {

// "OpenBLAS 0.3.21 ..." or a note that the reference BLAS is in use.
std::string description();
// Sets OpenBLAS's thread count; does nothing with another BLAS.
void set_threads(int threads);
// One thread below `unknowns_per_thread` unknowns per thread, else all cores.
void set_threads_for(long unknowns);

}  // namespace outburst::blas
