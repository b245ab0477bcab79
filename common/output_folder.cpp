#include "common/output_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
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
#include "common/manifest.hpp"
#include "common/scene.hpp"

namespace outburst {

namespace {

// What looks like a run's output: the names the programs give their files.
bool like_a_run_output(const std::string& name) {
  const auto ends_with = [&](std::string_view end) { return name.ends_with(end); };
  return ends_with(".xdmf") || ends_with(".h5") || name.find(".partial-") != std::string::npos ||
         name == "seepage_history.csv" || name == "mpm_history.csv" || name == "tracers.csv" || name == "coupling.csv" ||
         name == "wall_times.csv";
}

// "particles.xdmf" for its temporary "particles.xdmf.partial-1234".
std::string written_as(const std::string& name) {
  const auto partial = name.rfind(".partial-");
  return partial == std::string::npos ? name : name.substr(0, partial);
}

std::string some_names(const std::vector<std::filesystem::path>& files) {
  std::string list;
  for (std::size_t k = 0; k < files.size() && k < 5; ++k)
    list += fmt::format("{}{}", k ? ", " : "", files[k].filename().string());
  if (files.size() > 5) list += fmt::format(" and {} more", files.size() - 5);
  return list;
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
  const std::string origin = earlier.empty() ? "of unknown origin" : earlier;

  // The earlier run's files are those its manifest lists (and their temporary
  // files); others that look like a run's output, no run listed.
  const auto listed = output::read_manifest(directory_);
  std::filesystem::directory_iterator entries(directory_, error);
  if (error) refuse(directory_, fmt::format("cannot list it: {}", error.message()));
  std::vector<std::filesystem::path> ours, unlisted;
  for (const auto& entry : entries) {
    const std::string name = entry.path().filename().string();
    if (name == ".run.lock" || name == output::manifest_name) continue;
    if (listed.count(written_as(name)))
      ours.push_back(entry.path());
    else if (like_a_run_output(name))
      unlisted.push_back(entry.path());
  }
  std::sort(ours.begin(), ours.end());
  std::sort(unlisted.begin(), unlisted.end());
  // "my_survey_data.h5 looks ... listed it" or "3 files look ... listed them: a.h5, ...".
  const bool one = unlisted.size() == 1;
  const std::string unlisted_files =
      one ? fmt::format("{} looks like a run's output, but no run listed it", some_names(unlisted))
          : fmt::format("{} files look like a run's output, but no run listed them: {}", unlisted.size(),
                        some_names(unlisted));
  const std::string whose = fmt::format("in {} (a file of yours, or one a version before the manifest wrote)",
                                        output::manifest_name);
  if (earlier_files == Earlier::refuse && !(ours.empty() && unlisted.empty())) {
    const bool resumable = std::filesystem::exists(directory_ / checkpoint::file_name, error);
    refuse(directory_, ours.empty()
                           ? fmt::format("{} {}: move {}, or choose another folder with -o", unlisted_files, whose,
                                         one ? "it" : "them")
                           : fmt::format("it holds the output of an earlier run ({}, {} files); pass --overwrite to "
                                         "replace it, {}or choose another folder with -o",
                                         origin, ours.size(),
                                         resumable ? "--restart to continue it from its checkpoint, " : ""));
  }
  if (earlier_files == Earlier::overwrite && !unlisted.empty())
    refuse(directory_, fmt::format("--overwrite removes only the files the earlier run listed, and {} {}: move or "
                                   "remove {} yourself, or choose another folder with -o",
                                   unlisted_files, whose, one ? "it" : "them"));
  // A restart continues the earlier run's files, but for the temporary ones a
  // killed run left.
  if (earlier_files == Earlier::restart)
    std::erase_if(ours, [](const auto& f) { return f.filename().string().find(".partial-") == std::string::npos; });
  for (const auto& f : ours)
    if (!std::filesystem::remove(f, error) && error)
      refuse(directory_, fmt::format("cannot remove {} of the earlier run: {}", f.filename().string(), error.message()));
  if (!ours.empty())
    spdlog::info("removed the {} {} of an earlier run ({}) from {}", ours.size(),
                 earlier_files == Earlier::restart ? "unfinished files" : "files", origin, directory_.string());

  const std::string record = fmt::format("{}, pid {}, started {:%Y-%m-%d %H:%M:%S}\n", program, ::getpid(),
                                         fmt::localtime(std::chrono::system_clock::to_time_t(
                                             std::chrono::system_clock::now())));
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, record.data(), record.size(), 0) < 0)
    cannot_write(directory_, "cannot write its lock file", errno);
  output::start_manifest(directory_, earlier_files == Earlier::restart);
  lock_ = std::exchange(fd, -1);
}

OutputFolder::~OutputFolder() {
  output::stop_manifest(directory_);
  if (lock_ >= 0) ::close(lock_);
}

}  // namespace outburst
