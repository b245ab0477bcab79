#include "common/checkpoint.hpp"

#include <omp.h>
#include <zlib.h>

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/atomic_file.hpp"
#include "common/manifest.hpp"
#include "common/scene.hpp"

namespace outburst::checkpoint {

namespace {

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

[[noreturn]] void refuse(const std::filesystem::path& file, const std::string& why) {
  throw scene::Error(fmt::format("--restart: {}: {}", file.string(), why));
}

const char* stage_name(Stage stage) { return stage == Stage::settling ? "settling" : "run"; }

// Text read from a checkpoint, for a message: a damaged one may hold any
// byte, shown as \xNN but for printable ASCII and newlines.
std::string shown(const std::string& text) {
  std::string out;
  for (const char c : text)
    out += (c >= 0x20 && c < 0x7f) || c == '\n' ? std::string(1, c)
                                                : fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
  return out;
}

std::int64_t crc32_of(const void* data, std::size_t bytes) {
  return static_cast<std::int64_t>(::crc32_z(0, static_cast<const Bytef*>(data), bytes));
}

const char* const checksum = "crc32";

// The version string names a commit, but not edits made since, nor the
// compiler and flags: only the same program file computes bit for bit alike.
std::string build_fingerprint() {
  static const std::string fingerprint = [] {
    std::ifstream program("/proc/self/exe", std::ios::binary);
    if (!program) return std::string("unknown");
    Fingerprint f;
    std::vector<char> chunk(1 << 16);
    while (program.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || program.gcount() > 0)
      f.add(chunk.data(), static_cast<std::size_t>(program.gcount()));
    return fmt::format("{:016x}", static_cast<std::uint64_t>(f.value()));
  }();
  return fingerprint;
}

}  // namespace

void Fingerprint::add(const void* data, std::size_t bytes) {
  const auto* byte = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) hash_ = (hash_ ^ byte[i]) * 1099511628211ull;
}

void Out::number(const std::string& name, double value) const { write_rows(name, &value, 1, 0); }

void Out::count(const std::string& name, std::int64_t value) const { write_counts(name, {value}); }

void Out::text(const std::string& name, const std::string& value) const {
  file_->write_text(path_ + "/" + name, value);
  file_->attribute(path_ + "/" + name, checksum, crc32_of(value.data(), value.size()));
}

void Out::numbers(const std::string& name, const std::vector<double>& values) const {
  write_rows(name, values.data(), values.size(), 0);
}

void Out::numbers(const std::string& name, const Eigen::VectorXd& values) const {
  write_rows(name, values.data(), static_cast<std::size_t>(values.size()), 0);
}

void Out::write_rows(const std::string& name, const double* data, std::size_t rows, std::size_t columns) const {
  file_->write(path_ + "/" + name, data, columns == 0 ? std::vector<std::size_t>{rows} : std::vector{rows, columns});
  file_->attribute(path_ + "/" + name, checksum, crc32_of(data, rows * std::max<std::size_t>(columns, 1) * sizeof(double)));
}

void Out::write_counts(const std::string& name, const std::vector<std::int64_t>& values) const {
  file_->write(path_ + "/" + name, values.data(), {values.size()});
  file_->attribute(path_ + "/" + name, checksum, crc32_of(values.data(), values.size() * sizeof(std::int64_t)));
}

void In::fail(const std::string& name, const std::string& what) const {
  throw scene::Error(fmt::format("--restart: checkpoint {}: dataset {}/{}: {}", name_.string(), path_, name, what));
}

bool In::has(const std::string& name) const {
  return readable(name, [&] { return file_->exists(path_ + "/" + name); });
}

void In::verify(const std::string& name, const void* data, std::size_t bytes) const {
  const auto written = readable(name, [&] { return file_->integer_attribute(path_ + "/" + name, checksum); });
  if (!written) fail(name, "has no checksum (a \"crc32\" attribute): not a checkpoint of this version, or damaged");
  if (*written != crc32_of(data, bytes))
    fail(name, "its data do not match the checksum written with them: the checkpoint is damaged; continue from an "
               "intact copy of it, or start afresh with --overwrite");
}

void In::refuse(const std::string& why) const { checkpoint::refuse(name_, why); }

double In::number(const std::string& name) const {
  const auto v = numbers(name, 1);
  return v[0];
}

std::int64_t In::count(const std::string& name) const { return read_counts(name, 1)[0]; }

std::string In::text(const std::string& name) const {
  if (!has(name)) fail(name, "missing");
  auto text = readable(name, [&] { return file_->read_text(path_ + "/" + name); });
  verify(name, text.data(), text.size());
  return text;
}

std::vector<double> In::numbers(const std::string& name, std::optional<std::size_t> size) const {
  return read_rows(name, 1, size);
}

Eigen::VectorXd In::vector(const std::string& name, std::optional<std::size_t> size) const {
  const auto v = numbers(name, size);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

std::vector<double> In::read_rows(const std::string& name, std::size_t columns, std::optional<std::size_t> rows) const {
  if (!has(name)) fail(name, "missing");
  const auto shape = readable(name, [&] { return file_->shape(path_ + "/" + name); });
  const std::size_t found_columns = shape.size() > 1 ? shape[1] : 1;
  if (shape.empty() || shape.size() > 2 || found_columns != columns)
    fail(name, fmt::format("expected {} value(s) per row", columns));
  if (rows && shape[0] != *rows) fail(name, fmt::format("holds {} rows, this run's state has {}", shape[0], *rows));
  auto values = readable(name, [&] { return file_->read_doubles(path_ + "/" + name); });
  verify(name, values.data(), values.size() * sizeof(double));
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      fail(name, fmt::format("holds {} in row {}, where a run's state is finite: the checkpoint is damaged", values[i],
                             i / columns));
  return values;
}

std::vector<std::int64_t> In::read_counts(const std::string& name, std::optional<std::size_t> size) const {
  if (!has(name)) fail(name, "missing");
  const auto shape = readable(name, [&] { return file_->shape(path_ + "/" + name); });
  if (shape.size() != 1) fail(name, "expected a list of integers");
  if (size && shape[0] != *size) fail(name, fmt::format("holds {} values, this run's state has {}", shape[0], *size));
  auto values = readable(name, [&] { return file_->read_integers(path_ + "/" + name); });
  verify(name, values.data(), values.size() * sizeof(std::int64_t));
  return values;
}

void save_length(Out out, const std::string& name, const std::filesystem::path& file) {
  std::error_code error;
  const auto length = std::filesystem::file_size(file, error);
  if (error)
    throw std::runtime_error(fmt::format("cannot read the length of {} for the checkpoint: {}{}", file.string(),
                                         error.message(), output::disk_note(file)));
  out.count(name, static_cast<std::int64_t>(length));
}

void cut_back(const In& in, const std::string& name, const std::filesystem::path& file, std::ofstream& stream) {
  const auto length = static_cast<std::uintmax_t>(in.count(name));
  std::error_code error;
  const auto now = std::filesystem::file_size(file, error);
  if (error || now < length)
    in.fail(name, fmt::format("{} holds {} bytes, fewer than the {} it held at the checkpoint: it was changed since",
                              file.string(), error ? 0 : now, length));
  std::filesystem::resize_file(file, length, error);
  if (error) in.fail(name, fmt::format("cannot cut {} back to {} bytes: {}", file.string(), length, error.message()));
  output::record_written(file);
  stream.open(file, std::ios::app);
  if (!stream) in.fail(name, fmt::format("cannot open {} to append to it", file.string()));
}

Writer::Writer(const std::filesystem::path& directory, const output::RunInfo& info, Stage stage)
    : file_(directory / file_name, hdf5::H5Writer::Metadata::checksummed) {
  file_.attribute("/", "program", info.program);
  file_.attribute("/", "version", info.version);
  file_.attribute("/", "build", build_fingerprint());
  file_.attribute("/", "stage", stage_name(stage));
  file_.attribute("/", "scene_file", info.scene_file);
  file_.attribute("/", "scene_text", info.scene_text);
  file_.attribute("/", "scene_overrides", joined(info.overrides));
  file_.attribute("/", "threads", static_cast<double>(omp_get_max_threads()));
}

Reader::Reader(const std::filesystem::path& directory, const output::RunInfo& info) : path_(directory / file_name) {
  const auto refuse = [&](const std::string& why) { checkpoint::refuse(path_, why); };
  if (!std::filesystem::is_regular_file(path_))
    refuse("no checkpoint there: the run in this folder wrote none (or the folder holds no run); run without "
           "--restart to start afresh");
  try {
    file_ = std::make_unique<hdf5::H5Reader>(path_);
  } catch (const std::runtime_error& e) {
    refuse(e.what());
  }
  const auto attribute = [&](const char* name) {
    try {
      return file_->string_attribute("/", name);
    } catch (const std::runtime_error&) {
      checkpoint::refuse(path_, fmt::format("not a checkpoint (no attribute '{}')", name));
    }
  };
  if (const auto program = attribute("program"); program != info.program)
    refuse(fmt::format("written by {}, not {}", shown(program), info.program));
  // Only the same build continues a run bit for bit: another version may
  // compute differently or keep other state.
  if (const auto version = attribute("version"); version != info.version)
    refuse(fmt::format("written by version {}, this is {}; finish the run with that build, or start afresh",
                       shown(version), info.version));
  if (attribute("build") != build_fingerprint())
    refuse(fmt::format("written by another build of version {} (the program file differs: rebuilt since, or "
                       "another build folder); finish the run with that build, or start afresh",
                       info.version));
  // Any change, even of end_time alone, changes what the run computes: the
  // default output interval is end_time / 10, and so the steps that land on
  // output times.
  if (attribute("scene_text") != info.scene_text)
    refuse(fmt::format("written for another scene text (the scene file {} changed since)", info.scene_file));
  if (const auto overrides = attribute("scene_overrides"); overrides != joined(info.overrides))
    refuse(fmt::format("written with other --set overrides: [{}]; give the same ones",
                       overrides.empty() ? "none" : shown(overrides.substr(0, overrides.size() - 1))));
  if (const auto stage = attribute("stage"); stage == stage_name(Stage::settling))
    stage_ = Stage::settling;
  else if (stage != stage_name(Stage::run))
    refuse(fmt::format("unknown stage '{}'", shown(stage)));
  double written_threads = 0;
  try {
    written_threads = file_->number_attribute("/", "threads");
  } catch (const hdf5::Error&) {
    refuse("not a checkpoint (no attribute 'threads')");
  }
  if (!(written_threads >= 1 && written_threads <= 1 << 20))
    refuse(fmt::format("written with {} threads, which no run has", written_threads));
  const int threads = static_cast<int>(written_threads);
  if (threads != omp_get_max_threads())
    spdlog::warn("--restart: the checkpoint was written with {} threads, this run has {}: the run continues "
                 "correctly, but not bit for bit as it would have with {} (docs/user-guide/restart.md)",
                 threads, omp_get_max_threads(), threads);
}

}  // namespace outburst::checkpoint
