#pragma once
// The output folder of a run, taken by one run at a time.
//
// The folder's lock file, .run.lock, is flock()ed while a run writes there
// and names that run (program, pid, start time). The kernel releases the
// lock when the process ends, even by kill -9, so a stale lock never blocks.
// A second run into a folder whose run is still going is refused, naming it.
// Each run lists the files it writes in the folder's manifest (manifest.hpp).
// A run into a folder holding an earlier run's files is refused unless asked
// to overwrite them, which removes them first: otherwise an earlier run's
// later snapshots would stay beside the new run's. Files that look like a
// run's output (HDF5, XDMF, the history CSVs, temporary .partial- files) but
// that no manifest lists, such as a user's data, are never removed: a run into
// such a folder, --overwrite or not, is refused, naming them. A restart keeps
// the earlier run's files (the run continues them from its checkpoint) but for
// the temporary files a killed run left, and refuses a folder that does not
// exist. Errors are scene::Error (bad command line: exit code 2), but for a
// full disk (std::runtime_error: exit code 1).

#include <filesystem>
#include <string>

namespace outburst {

class OutputFolder {
 public:
  // What to do with an earlier run's files: refuse them, remove them, or keep
  // them for a restart.
  enum class Earlier { refuse, overwrite, restart };
  OutputFolder(std::filesystem::path directory, const std::string& program, Earlier earlier);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  const std::filesystem::path& path() const { return directory_; }

 private:
  std::filesystem::path directory_;
  int lock_ = -1;  // the lock file, open (and locked) for the run's lifetime
};

}  // namespace outburst
