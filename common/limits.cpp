#include "common/limits.hpp"

#include <unistd.h>

#include <fmt/format.h>

namespace outburst::limits {

double physical_memory() {
  return static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
}

void refuse_count(const scene::Table& table, std::string_view key, double count, double bound,
                  std::string_view what, const std::string& how) {
  if (!(count <= bound))
    table.fail(key, fmt::format("the run would take an estimated {:.3g} {} ({}), more than the {:g} a run may take",
                                count, what, how, bound));
}

void refuse_memory(const scene::Table& table, std::string_view key, double bytes, const std::string& what) {
  const double memory = physical_memory();
  if (!(bytes <= memory))
    table.fail(key, fmt::format("{} would need at least {:.3g} GB, more than this machine's {:.3g} GB of memory",
                                what, bytes * 1e-9, memory * 1e-9));
}

}  // namespace outburst::limits
