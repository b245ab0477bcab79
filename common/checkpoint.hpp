#pragma once
// Checkpoints: a run's complete state in one HDF5 file of its output folder,
// checkpoint.h5, replaced atomically (hdf5::H5Writer), from which --restart
// continues the run as if it had never stopped.
//
// Each class that holds state writes its own fields into a group (save) and
// reads them back (load), so the knowledge of what a class must keep stays
// with the class. Numbers are stored as 64-bit datasets, so a value read back
// is the value written, bit for bit. A checkpoint records the program, its
// version and a fingerprint of its program file, the scene text and the
// overrides; a restart by another program or build, or with another scene, is
// refused (scene::Error: exit code 2).
//
// A damaged checkpoint is refused too, naming the file and the dataset: its
// metadata carries HDF5's checksums, each dataset a CRC-32 (zlib's) of its
// bytes as written (little-endian, in a "crc32" attribute), and each number
// read back must be finite, as every number of a run's state is.
//
// A checkpoint holds one of two stages: the settling stage of an MPM solid
// (before t = 0, no output written yet), or the run itself.

#include <concepts>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <fmt/format.h>

#include "common/field_output.hpp"
#include "common/hdf5_file.hpp"

namespace outburst::checkpoint {

// The file name in the output folder.
inline constexpr const char* file_name = "checkpoint.h5";

enum class Stage { settling, run };

// FNV-1a over bytes: a cheap identity for inputs a checkpoint must match (a
// mesh file's content, the program file), not a defence against tampering.
class Fingerprint {
 public:
  void add(const void* data, std::size_t bytes);
  template <class T>
  void add(const std::vector<T>& values) {
    add(values.data(), values.size() * sizeof(T));
  }
  std::int64_t value() const { return static_cast<std::int64_t>(hash_); }

 private:
  std::uint64_t hash_ = 14695981039346656037ull;
};

// One group of a checkpoint being written ("/seepage/balance").
class Out {
 public:
  Out(hdf5::H5Writer& file, std::string path) : file_(&file), path_(std::move(path)) {}
  Out group(const std::string& name) const { return {*file_, path_ + "/" + name}; }

  void number(const std::string& name, double value) const;
  void count(const std::string& name, std::int64_t value) const;
  void flag(const std::string& name, bool value) const { count(name, value ? 1 : 0); }
  void text(const std::string& name, const std::string& value) const;
  void numbers(const std::string& name, const std::vector<double>& values) const;
  void numbers(const std::string& name, const Eigen::VectorXd& values) const;
  template <std::integral Int>
  void counts(const std::string& name, const std::vector<Int>& values) const {
    write_counts(name, std::vector<std::int64_t>(values.begin(), values.end()));
  }
  // Fixed-size Eigen vectors and matrices, one row of R * C values each.
  template <int R, int C>
  void matrices(const std::string& name, const std::vector<Eigen::Matrix<double, R, C>>& values) const {
    write_rows(name, values.empty() ? nullptr : values.front().data(), values.size(), R * C);
  }

 private:
  // columns 0: a list (a dataset of one dimension).
  void write_rows(const std::string& name, const double* data, std::size_t rows, std::size_t columns) const;
  void write_counts(const std::string& name, const std::vector<std::int64_t>& values) const;
  hdf5::H5Writer* file_;
  std::string path_;
};

// One group of a checkpoint being read. Errors (std::runtime_error) name the
// file and the dataset, and what was expected of it.
class In {
 public:
  In(const hdf5::H5Reader& file, std::filesystem::path name, std::string path)
      : file_(&file), name_(std::move(name)), path_(std::move(path)) {}
  In group(const std::string& name) const { return {*file_, name_, path_ + "/" + name}; }
  bool has(const std::string& name) const;

  double number(const std::string& name) const;
  std::int64_t count(const std::string& name) const;
  bool flag(const std::string& name) const { return count(name) != 0; }
  std::string text(const std::string& name) const;
  // `size`, when given, is the length the caller's state needs.
  std::vector<double> numbers(const std::string& name, std::optional<std::size_t> size = {}) const;
  Eigen::VectorXd vector(const std::string& name, std::optional<std::size_t> size = {}) const;
  template <std::integral Int>
  std::vector<Int> counts(const std::string& name, std::optional<std::size_t> size = {}) const {
    const auto values = read_counts(name, size);
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::in_range<Int>(values[i]))
        fail(name, fmt::format("holds {} in row {}, beyond the integers this state holds there", values[i], i));
    return {values.begin(), values.end()};
  }
  template <int R, int C>
  std::vector<Eigen::Matrix<double, R, C>> matrices(const std::string& name,
                                                    std::optional<std::size_t> size = {}) const {
    const auto flat = read_rows(name, R * C, size);
    std::vector<Eigen::Matrix<double, R, C>> values(flat.size() / (R * C));
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = Eigen::Map<const Eigen::Matrix<double, R, C>>(flat.data() + i * R * C);
    return values;
  }
  // A scene::Error (exit code 2) naming the file and the dataset: a damaged
  // checkpoint.
  [[noreturn]] void fail(const std::string& name, const std::string& what) const;
  // A scene::Error (exit code 2) naming the file: a checkpoint of another
  // input than this run's.
  [[noreturn]] void refuse(const std::string& why) const;

 private:
  std::vector<std::int64_t> read_counts(const std::string& name, std::optional<std::size_t> size) const;
  std::vector<double> read_rows(const std::string& name, std::size_t columns, std::optional<std::size_t> rows) const;
  // Refuses data other than the bytes written under `name`.
  void verify(const std::string& name, const void* data, std::size_t bytes) const;
  // read(), with what the HDF5 library could not read (a damaged structure:
  // its metadata checksums) refused as a damaged `name`.
  template <class Read>
  auto readable(const std::string& name, Read&& read) const -> decltype(read()) {
    try {
      return read();
    } catch (const hdf5::Error& e) {
      fail(name, fmt::format("cannot read it: the checkpoint is damaged ({})", e.what()));
    }
  }
  const hdf5::H5Reader* file_;
  std::filesystem::path name_;
  std::string path_;
};

// History files (CSV, appended and flushed line by line): their length at a
// checkpoint, and on restart the file cut back to it and opened for appending,
// so that no row after the checkpoint's time stays and none comes twice.
void save_length(Out out, const std::string& name, const std::filesystem::path& file);
void cut_back(const In& in, const std::string& name, const std::filesystem::path& file, std::ofstream& stream);

// A checkpoint being written: provenance and stage on its root, state in
// groups.
class Writer {
 public:
  Writer(const std::filesystem::path& directory, const output::RunInfo& info, Stage stage);
  Out root() { return {file_, ""}; }
  // Replaces the folder's checkpoint with this one.
  void commit() { file_.commit(); }

 private:
  hdf5::H5Writer file_;
};

// The checkpoint of an output folder, checked against this run: refuses
// (scene::Error) a folder without one, or one another program, another build
// or another scene text or set of overrides wrote.
class Reader {
 public:
  Reader(const std::filesystem::path& directory, const output::RunInfo& info);
  In root() const { return {*file_, path_, ""}; }
  const std::filesystem::path& path() const { return path_; }
  Stage stage() const { return stage_; }

 private:
  std::filesystem::path path_;
  std::unique_ptr<hdf5::H5Reader> file_;
  Stage stage_ = Stage::run;
};

}  // namespace outburst::checkpoint
