#pragma once
// Minimal RAII access to HDF5 files for results and checkpoints.
//
// Writing is crash-safe: H5Writer builds the file in memory, and commit()
// writes it under a temporary name beside the target and renames it into
// place. A run that dies mid-write, or finds its disk full, leaves the
// previous complete file (or none), never a truncated one.
//
// A file written with checksummed metadata (HDF5's 1.8 format on: superblock,
// object headers and heaps carry checksums, which the library verifies as it
// reads them) refuses a damaged structure before parsing it; its data, the
// writer's own checksums cover (checkpoint.hpp).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace outburst::hdf5 {

// What the library could not do with a file, naming it.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class H5Writer {
 public:
  enum class Metadata { compatible, checksummed };
  explicit H5Writer(std::filesystem::path final_path, Metadata metadata = Metadata::compatible);
  ~H5Writer();
  H5Writer(const H5Writer&) = delete;
  H5Writer& operator=(const H5Writer&) = delete;

  // Datasets are created with intermediate groups ("fields/p"); dims is the shape
  // (rows, columns) or (rows). A non-empty unit becomes a "unit" attribute.
  void write(const std::string& path, const double* data, const std::vector<std::size_t>& dims,
             const std::string& unit = {});
  void write(const std::string& path, const std::int64_t* data,
             const std::vector<std::size_t>& dims);
  void write(const std::string& path, const std::vector<double>& data,
             const std::string& unit = {}) {
    write(path, data.data(), {data.size()}, unit);
  }
  // A text dataset (one variable-length UTF-8 string).
  void write_text(const std::string& path, const std::string& text);
  // String and number attributes on the root group ("/") or an existing object.
  void attribute(const std::string& object, const std::string& name, const std::string& value);
  void attribute(const std::string& object, const std::string& name, double value);
  void attribute(const std::string& object, const std::string& name, std::int64_t value);

  // Close the file and move it to its final name.
  void commit();

  const std::filesystem::path& final_path() const { return final_path_; }

 private:
  std::filesystem::path final_path_;
  std::int64_t file_ = -1;
};

class H5Reader {
 public:
  explicit H5Reader(const std::filesystem::path& path);
  ~H5Reader();
  H5Reader(const H5Reader&) = delete;
  H5Reader& operator=(const H5Reader&) = delete;

  bool exists(const std::string& path) const;
  std::vector<std::size_t> shape(const std::string& path) const;
  std::vector<double> read_doubles(const std::string& path) const;
  std::vector<std::int64_t> read_integers(const std::string& path) const;
  std::string read_text(const std::string& path) const;
  std::string string_attribute(const std::string& object, const std::string& name) const;
  double number_attribute(const std::string& object, const std::string& name) const;
  // Empty when the object has no such attribute.
  std::optional<std::int64_t> integer_attribute(const std::string& object, const std::string& name) const;

 private:
  std::filesystem::path path_;
  std::int64_t file_ = -1;
};

}  // namespace outburst::hdf5
