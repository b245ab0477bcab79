#pragma once
// Measured convergence orders: the slope of log(error) against log(h) between
// successive refinements, printed as the table a reader checks.

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace outburst::testing {

struct ConvergenceRow {
  double h;
  double error;
};

// Orders between successive rows (rows ordered coarse to fine).
inline std::vector<double> observed_orders(const std::vector<ConvergenceRow>& rows) {
  std::vector<double> orders;
  for (std::size_t i = 1; i < rows.size(); ++i)
    orders.push_back(std::log(rows[i - 1].error / rows[i].error) / std::log(rows[i - 1].h / rows[i].h));
  return orders;
}

inline void print_convergence(const std::string& title, const std::string& h_name,
                              const std::vector<ConvergenceRow>& rows) {
  const auto orders = observed_orders(rows);
  std::printf("\n%s\n  %12s  %12s  %6s\n", title.c_str(), h_name.c_str(), "error", "order");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (i == 0)
      std::printf("  %12.4e  %12.4e  %6s\n", rows[i].h, rows[i].error, "");
    else
      std::printf("  %12.4e  %12.4e  %6.3f\n", rows[i].h, rows[i].error, orders[i - 1]);
  }
}

}  // namespace outburst::testing
