#include "common/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "common/manifest.hpp"

namespace outburst::output {

std::string disk_note(const std::filesystem::path& path) {
  const std::filesystem::path folder = path.parent_path().empty() ? "." : path.parent_path();
  std::error_code unknown;
  if (!std::filesystem::exists(folder, unknown) && !unknown)
    return fmt::format(" (the folder {} no longer exists: removed while the run wrote there?)", folder.string());
  if (const auto space = std::filesystem::space(folder, unknown); !unknown)
    return fmt::format(" ({} MB free on its disk)", space.available / 1000000);
  return {};
}

void fail_to_write(const std::filesystem::path& path, int error) {
  throw std::runtime_error(fmt::format("cannot write {}: {}{}", path.string(), std::strerror(error), disk_note(path)));
}

bool out_of_space(int error) { return error == ENOSPC || error == EDQUOT || error == EFBIG; }

std::filesystem::path write_beside(const std::filesystem::path& path, std::string_view bytes) {
  record_written(path);
  std::filesystem::path temp = path;
  temp += fmt::format(".partial-{}", ::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail_to_write(path, errno);
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      ::close(fd);
      ::unlink(temp.c_str());
      fail_to_write(path, error);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temp.c_str());
    fail_to_write(path, error);
  }
  return temp;
}

void move_into_place(const std::filesystem::path& temp, const std::filesystem::path& path) {
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temp.c_str());
    fail_to_write(path, error);
  }
}

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  move_into_place(write_beside(path, bytes), path);
}

}  // namespace outburst::output
