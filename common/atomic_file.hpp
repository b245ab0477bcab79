#pragma once
// Files replaced atomically: written under a temporary name beside the target
// ("<name>.partial-<pid>") and renamed into place, so a run that dies leaves
// the previous complete file or none, never a truncated one. Errors
// (std::runtime_error) name the file and the reason, such as a full disk.

#include <filesystem>
#include <string>
#include <string_view>

namespace outburst::output {

// Writes `bytes` under a temporary name beside `path`; returns that name.
std::filesystem::path write_beside(const std::filesystem::path& path, std::string_view bytes);
// Renames a file write_beside() made over `path`.
void move_into_place(const std::filesystem::path& temp, const std::filesystem::path& path);
// Replaces `path` with `bytes`.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

// Throws the std::runtime_error of a write of `path` that failed with errno
// `error`: the reason and disk_note(path).
[[noreturn]] void fail_to_write(const std::filesystem::path& path, int error);
// " (N MB free on its disk)" for the folder of `path`, or " (the folder ...
// no longer exists ...)" when it is gone.
std::string disk_note(const std::filesystem::path& path);
// Whether errno `error` says the disk (or the space a process may use) is full.
bool out_of_space(int error);

}  // namespace outburst::output
