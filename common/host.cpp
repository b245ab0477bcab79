#include "common/host.hpp"

#include <fmt/format.h>
#include <sched.h>
#include <sys/utsname.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

namespace outburst {

namespace {

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t"), last = s.find_last_not_of(" \t");
  return first == std::string::npos ? std::string() : s.substr(first, last - first + 1);
}

// The first processor's entry of /proc/cpuinfo (empty where there is none).
std::map<std::string, std::string> first_processor() {
  std::map<std::string, std::string> fields;
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) {
      if (!fields.empty()) break;
      continue;
    }
    fields.emplace(trimmed(line.substr(0, colon)), trimmed(line.substr(colon + 1)));
  }
  return fields;
}

std::string describe() {
  const auto fields = first_processor();
  const auto field = [&](const char* key) {
    const auto it = fields.find(key);
    return it == fields.end() ? std::string() : it->second;
  };
  std::string model = field("model name");
  if (model.empty()) {
    utsname system{};
    model = uname(&system) == 0 ? system.machine : "unknown processor";
  }
  // As builds.py's host(): present keys count, empty or not.
  if (fields.count("cpu family") && fields.count("model"))
    model += fmt::format(" (family {}, model {})", field("cpu family"), field("model"));
  std::istringstream flag_words(fields.count("flags") ? field("flags") : field("Features"));
  std::vector<std::string> flags{std::istream_iterator<std::string>(flag_words), {}};
  std::string vectors = "vector extensions unknown";
  for (const auto& [flag, name] : std::vector<std::pair<std::string, std::string>>{
           {"avx512f", "AVX-512"}, {"avx2", "AVX2"}, {"avx", "AVX"}, {"sse2", "SSE2"}, {"sve", "SVE"},
           {"asimd", "NEON"}})
    if (std::find(flags.begin(), flags.end(), flag) != flags.end()) {
      vectors = name;
      break;
    }
  cpu_set_t allowed;
  const int cpus = sched_getaffinity(0, sizeof allowed, &allowed) == 0
                       ? CPU_COUNT(&allowed)
                       : static_cast<int>(std::thread::hardware_concurrency());
  return fmt::format("{}, {}, {} CPUs", model, vectors, cpus);
}

}  // namespace

// Read once: a benchmark names it in every row of its CSVs.
std::string host_description() {
  static const std::string description = describe();
  return description;
}

std::string host_csv_field() {
  std::string quoted = "\"";
  for (const char c : host_description()) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace outburst
