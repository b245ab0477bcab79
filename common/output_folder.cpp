#include "common/output_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>
#include <vector>

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/atomic_file.hpp"
#include "common/checkpoint.hpp"
#include "common/scene.hpp"

namespace outburst {

namespace {

// What the programs write into an output folder.
bool written_by_a_run(const std::string& name) {
  const auto ends_with = [&](std::string_view end) { return name.ends_with(end); };
  return ends_with(".xdmf") || ends_with(".h5") || name.find(".partial-") != std::string::npos ||
         name == "seepage_history.csv" || name == "mpm_history.csv" || name == "tracers.csv" || name == "coupling.csv" ||
         name == "wall_times.csv";
}

// The run a lock file names ("outburst, pid 1234, started ..."), or empty.
std::string holder(int fd) {
  std::string text(512, '\0');
  const ssize_t n = ::pread(fd, text.data(), text.size(), 0);
  text.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\0')) text.pop_back();
  return text;
}

[[noreturn]] void refuse(const std::filesystem::path& directory, const std::string& why) {
  throw scene::Error(fmt::format("output folder {}: {}", directory.string(), why));
}

// A folder the run cannot write: exit code 1 on a full disk (the run could
// not go on), 2 for a folder it may not write (the command line's -o).
[[noreturn]] void cannot_write(const std::filesystem::path& directory, const std::string& what, int error) {
  const std::string why = fmt::format("{}: {}", what, std::strerror(error));
  if (output::out_of_space(error))
    throw std::runtime_error(
        fmt::format("output folder {}: {}{}", directory.string(), why, output::disk_note(directory / "-")));
  refuse(directory, why);
}

}  // namespace

OutputFolder::OutputFolder(std::filesystem::path directory, const std::string& program, Earlier earlier_files)
    : directory_(std::move(directory)) {
  std::error_code error;
  if (std::filesystem::exists(directory_, error) && !std::filesystem::is_directory(directory_, error))
    refuse(directory_, "it exists and is not a folder; give a folder with -o");
  if (earlier_files == Earlier::restart && !std::filesystem::exists(directory_, error))
    refuse(directory_, "--restart: there is no such folder, so no run to continue; give the folder of the stopped "
                       "run with -o, or run without --restart");
  std::filesystem::create_directories(directory_, error);
  if (error) cannot_write(directory_, "cannot create it", error.value());

  int fd = ::open((directory_ / ".run.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) cannot_write(directory_, "cannot write in it", errno);
  // Closing the lock file releases the lock: done here unless the folder is taken.
  struct Closer {
    int& fd;
    ~Closer() {
      if (fd >= 0) ::close(fd);
    }
  } closer{fd};
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const std::string running = holder(fd);
    refuse(directory_, fmt::format("a run is still writing there ({}); wait for it, stop it, or choose another "
                                   "folder with -o",
                                   running.empty() ? "its lock is held" : running));
  }
  const std::string earlier = holder(fd);

  std::filesystem::directory_iterator entries(directory_, error);
  if (error) refuse(directory_, fmt::format("cannot list it: {}", error.message()));
  std::vector<std::filesystem::path> files;
  for (const auto& entry : entries) {
    const std::string name = entry.path().filename().string();
    const bool remove = earlier_files == Earlier::restart ? name.find(".partial-") != std::string::npos
                                                          : written_by_a_run(name);
    if (remove) files.push_back(entry.path());
  }
  if (!files.empty() && earlier_files == Earlier::refuse) {
    const bool resumable = std::filesystem::exists(directory_ / checkpoint::file_name, error);
    refuse(directory_, fmt::format("it holds the output of an earlier run ({}, {} files); pass --overwrite to "
                                   "replace it, {}or choose another folder with -o",
                                   earlier.empty() ? "of unknown origin" : earlier, files.size(),
                                   resumable ? "--restart to continue it from its checkpoint, " : ""));
  }
  for (const auto& f : files)
    if (!std::filesystem::remove(f, error) && error)
      refuse(directory_, fmt::format("cannot remove {} of the earlier run: {}", f.filename().string(), error.message()));
  if (!files.empty())
    spdlog::info("removed the {} {} of an earlier run ({}) from {}", files.size(),
                 earlier_files == Earlier::restart ? "unfinished files" : "files",
                 earlier.empty() ? "of unknown origin" : earlier, directory_.string());

  const std::string record = fmt::format("{}, pid {}, started {:%Y-%m-%d %H:%M:%S}\n", program, ::getpid(),
                                         fmt::localtime(std::chrono::system_clock::to_time_t(
                                             std::chrono::system_clock::now())));
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, record.data(), record.size(), 0) < 0)
    cannot_write(directory_, "cannot write its lock file", errno);
  lock_ = std::exchange(fd, -1);
}

OutputFolder::~OutputFolder() {
  if (lock_ >= 0) ::close(lock_);
}

}  // namespace outburst
