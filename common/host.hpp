#pragma once
// The processor a benchmark ran on. A kernel vectorised over particles gains
// more from wide vectors than from narrow ones, so a throughput, or a ratio
// of two builds' throughputs, is a figure of the processor as much as of the
// code (docs/performance/index.md#hosts).

#include <string>

namespace outburst {

// Its model (with family and model numbers where the system gives them: a
// virtual machine may report a brand alone), its widest vector extension and
// the logical CPUs this process may use, e.g. "AMD EPYC (family 23, model 1),
// AVX2, 2 CPUs". scripts/builds.py's host() gives the same words to the
// comparison scripts, so that cases/readme_tables.py names the host above a
// table from either. Taken at the first call.
std::string host_description();

// The same as one CSV field (quoted: it holds commas).
std::string host_csv_field();

}  // namespace outburst
