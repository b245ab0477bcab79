#pragma once
// Files replaced atomically: written under a temporary name beside the target
// ("<name>.partial-<pid>") and renamed into place, so a run that dies leaves
// the previous complete file or none, never a truncated one. Errors
// (std::runtime_error) name the file and the reason, such as a full disk.

#include <filesystem>
#include <string_view>

namespace outburst::output {

// Writes `bytes` under a temporary name beside `path`; returns that name.
std::filesystem::path write_beside(const std::filesystem::path& path, std::string_view bytes);
// Renames a file write_beside() made over `path`.
void move_into_place(const std::filesystem::path& temp, const std::filesystem::path& path);
// Replaces `path` with `bytes`.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace outburst::output
