#include "common/manifest.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <map>
#include <mutex>

#include "common/atomic_file.hpp"

namespace outburst::output {

namespace {

const char* const header = "# The files the run in this folder wrote here, each before its first byte; --overwrite "
                           "removes these and no others.\n";

// The folders whose manifests runs of this process keep, by absolute path,
// with the names listed.
std::mutex guard;
std::map<std::filesystem::path, std::set<std::string>> started;

std::filesystem::path key(const std::filesystem::path& directory) {
  std::error_code ignored;
  auto path = std::filesystem::absolute(directory, ignored).lexically_normal();
  return path.has_filename() ? path : path.parent_path();  // "dir/" as "dir"
}

void append(const std::filesystem::path& manifest, const std::string& text, bool truncate) {
  const int fd = ::open(manifest.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (truncate ? O_TRUNC : O_APPEND), 0644);
  if (fd < 0) fail_to_write(manifest, errno);
  for (std::size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      ::close(fd);
      fail_to_write(manifest, error);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) fail_to_write(manifest, errno);
}

}  // namespace

std::set<std::string> read_manifest(const std::filesystem::path& directory) {
  std::set<std::string> names;
  std::ifstream in(directory / manifest_name);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line.front() != '#') names.insert(line);
  return names;
}

void start_manifest(const std::filesystem::path& directory, bool keep) {
  std::set<std::string> names = keep ? read_manifest(directory) : std::set<std::string>{};
  if (!keep) append(directory / manifest_name, header, true);
  const std::lock_guard lock(guard);
  started[key(directory)] = std::move(names);
}

void stop_manifest(const std::filesystem::path& directory) {
  const std::lock_guard lock(guard);
  started.erase(key(directory));
}

void record_written(const std::filesystem::path& file) {
  const std::lock_guard lock(guard);
  const auto folder = started.find(key(file.parent_path()));
  if (folder == started.end()) return;
  const std::string name = file.filename().string();
  if (folder->second.count(name)) return;
  append(folder->first / manifest_name, name + "\n", false);
  folder->second.insert(name);
}

}  // namespace outburst::output
