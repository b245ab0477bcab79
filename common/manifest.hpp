#pragma once
// The manifest of an output folder, DIR/.run.manifest: the name of each file
// the run in that folder wrote there, one a line (lines starting with '#' are
// comments), each recorded before the file's first byte is written, so that a
// run killed at any point has listed every file it left. --overwrite removes
// the files the manifest lists, and no others (OutputFolder); a restart
// continues the list.

#include <filesystem>
#include <set>
#include <string>

namespace outburst::output {

inline constexpr const char* manifest_name = ".run.manifest";

// The names the manifest of `directory` lists; none when it has none.
std::set<std::string> read_manifest(const std::filesystem::path& directory);

// From now on the files written into `directory` are recorded in its
// manifest: after the names it lists (`keep`), or in a new one. Errors
// (std::runtime_error) name the manifest and the reason.
void start_manifest(const std::filesystem::path& directory, bool keep);
void stop_manifest(const std::filesystem::path& directory);

// Records `file` in the manifest of its folder, if a run started one there
// and it does not list the name yet. Errors: std::runtime_error.
void record_written(const std::filesystem::path& file);

}  // namespace outburst::output
