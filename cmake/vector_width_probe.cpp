// Compiled, not run, by cmake/VectorWidth.cmake: the width GCC's vectoriser
// reports for this loop is the width it prefers for doubles under the build's
// flags.
void scaled_add(double* __restrict y, const double* __restrict x, double a, int n) {
  for (int i = 0; i < n; ++i) y[i] += a * x[i];
}
