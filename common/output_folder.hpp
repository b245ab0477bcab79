#pragma once
// The output folder of a run, taken by one run at a time.
//
// The folder's lock file, .run.lock, is flock()ed while a run writes there
// and names that run (program, pid, start time). The kernel releases the
// lock when the process ends, even by kill -9, so a stale lock never blocks.
// A second run into a folder whose run is still going is refused, naming it.
// A run into a folder holding an earlier run's files (the XDMF indexes and
// HDF5 files, the history CSVs, temporary .partial- files) is refused unless
// asked to overwrite them, which removes them first: otherwise an earlier
// run's later snapshots would stay beside the new run's.
// Errors are scene::Error (bad command line: exit code 2).

#include <filesystem>
#include <string>

namespace outburst {

class OutputFolder {
 public:
  OutputFolder(std::filesystem::path directory, const std::string& program, bool overwrite);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  const std::filesystem::path& path() const { return directory_; }

 private:
  std::filesystem::path directory_;
  int lock_ = -1;  // the lock file, open (and locked) for the run's lifetime
};

}  // namespace outburst
