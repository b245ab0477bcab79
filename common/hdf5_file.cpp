#include "common/hdf5_file.hpp"

#include <hdf5.h>

#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "common/atomic_file.hpp"

namespace outburst::hdf5 {

namespace {

// HDF5 prints its own error stack to stderr by default; we report errors ourselves.
void silence_hdf5() {
  static const bool once = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)once;
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw Error(fmt::format("HDF5 file {}: {}", file.string(), what));
}

// What the library found wrong, from the innermost entry of its error stack
// ("incorrect metadata checksum after all read attempts"), as ": ..."; empty
// when it recorded nothing.
std::string library_says() {
  std::string innermost;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* entry, void* data) -> herr_t {
        if (n == 0 && entry->desc) *static_cast<std::string*>(data) = entry->desc;
        return 0;
      },
      &innermost);
  return innermost.empty() ? std::string() : ": HDF5 says \"" + innermost + "\"";
}

// Closes an HDF5 identifier with the matching close function on scope exit.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Variable-length UTF-8 strings (h5py reads them as str).
hid_t string_type() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}

void write_dataset(hid_t file, const std::filesystem::path& name, const std::string& path,
                   hid_t file_type, hid_t memory_type, const void* data,
                   const std::vector<std::size_t>& dims) {
  std::vector<hsize_t> h(dims.begin(), dims.end());
  Handle space(H5Screate_simple(static_cast<int>(h.size()), h.data(), nullptr), H5Sclose);
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl, 1);
  Handle ds(H5Dcreate2(file, path.c_str(), file_type, space, lcpl, H5P_DEFAULT, H5P_DEFAULT),
            H5Dclose);
  if (!ds.valid()) fail(name, fmt::format("cannot create dataset {}", path));
  std::size_t count = 1;
  for (auto d : dims) count *= d;
  if (count == 0) return;  // an empty dataset has nothing to write, and may come without a buffer
  if (H5Dwrite(ds, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    fail(name, fmt::format("cannot write dataset {}", path));
}

// Jenkins' lookup3 hash (hashlittle, byte by byte), which the HDF5 format
// takes for its metadata checksums.
std::uint32_t lookup3(const unsigned char* k, std::size_t length) {
  const auto rot = [](std::uint32_t x, int n) { return (x << n) | (x >> (32 - n)); };
  const auto word = [&](std::size_t at, std::size_t available) {
    std::uint32_t w = 0;
    for (std::size_t i = 0; i < 4 && at + i < available; ++i) w |= std::uint32_t{k[at + i]} << (8 * i);
    return w;
  };
  std::uint32_t a, b, c;
  a = b = c = 0xdeadbeef + static_cast<std::uint32_t>(length);
  std::size_t at = 0;
  for (; length - at > 12; at += 12) {
    a += word(at, length), b += word(at + 4, length), c += word(at + 8, length);
    a -= c, a ^= rot(c, 4), c += b;
    b -= a, b ^= rot(a, 6), a += c;
    c -= b, c ^= rot(b, 8), b += a;
    a -= c, a ^= rot(c, 16), c += b;
    b -= a, b ^= rot(a, 19), a += c;
    c -= b, c ^= rot(b, 4), b += a;
  }
  if (length == at) return c;
  a += word(at, length), b += word(at + 4, length), c += word(at + 8, length);
  c ^= b, c -= rot(b, 14);
  a ^= c, a -= rot(c, 11);
  b ^= a, b -= rot(a, 25);
  c ^= b, c -= rot(b, 16);
  a ^= c, a -= rot(c, 4);
  b ^= a, b -= rot(a, 14);
  c ^= b, c -= rot(b, 24);
  return c;
}

// The image HDF5 1.10.8 gives of a file open for writing carries a version 2
// superblock (checksummed metadata) whose checksum does not match its bytes,
// and the library then refuses the file it wrote ("incorrect metadata
// checksum"). The checksum is set here as the file format defines it: lookup3
// of the superblock's bytes before it (44, with 8-byte addresses).
void fix_superblock_checksum(std::string& image) {
  constexpr std::size_t before = 8 + 4 + 4 * 8;
  if (image.size() < before + 4 || (image[8] != 2 && image[8] != 3) || image[9] != 8) return;
  const std::uint32_t sum = lookup3(reinterpret_cast<const unsigned char*>(image.data()), before);
  for (int i = 0; i < 4; ++i) image[before + i] = static_cast<char>((sum >> (8 * i)) & 0xff);
}

}  // namespace

H5Writer::H5Writer(std::filesystem::path final_path, Metadata metadata) : final_path_(std::move(final_path)) {
  silence_hdf5();
  // The file is built in memory and written out in one piece by commit(): a
  // full disk then fails a plain write. When HDF5 wrote it and its closing
  // write failed, the library was left half torn down, and closing the file
  // again (the destructor did, as does HDF5's own cleanup at exit) crashed.
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fapl_core(access, 1 << 20, false);
  if (metadata == Metadata::checksummed) H5Pset_libver_bounds(access, H5F_LIBVER_V18, H5F_LIBVER_V18);
  file_ = H5Fcreate(final_path_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access);
  if (file_ < 0) fail(final_path_, "cannot create it (in memory)");
}

H5Writer::~H5Writer() {
  if (file_ >= 0) H5Fclose(file_);
}

void H5Writer::write(const std::string& path, const double* data,
                     const std::vector<std::size_t>& dims, const std::string& unit) {
  write_dataset(file_, final_path_, path, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data, dims);
  if (!unit.empty()) attribute(path, "unit", unit);
}

void H5Writer::write(const std::string& path, const std::int64_t* data,
                     const std::vector<std::size_t>& dims) {
  write_dataset(file_, final_path_, path, H5T_STD_I64LE, H5T_NATIVE_INT64, data, dims);
}

void H5Writer::write_text(const std::string& path, const std::string& text) {
  Handle type(string_type(), H5Tclose);
  const char* data = text.c_str();
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl, 1);
  Handle ds(H5Dcreate2(file_, path.c_str(), type, space, lcpl, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  if (!ds.valid() || H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &data) < 0)
    fail(final_path_, fmt::format("cannot write text dataset {}", path));
}

void H5Writer::attribute(const std::string& object, const std::string& name,
                         const std::string& value) {
  Handle obj(H5Oopen(file_, object.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) fail(final_path_, fmt::format("no object {} for attribute {}", object, name));
  // Variable length: the text lives in the file's heap, not in the object
  // header, whose 64 kB limit a fixed-length scene text overran.
  Handle type(string_type(), H5Tclose);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  const char* text = value.c_str();
  if (!attr.valid() || H5Awrite(attr, type, &text) < 0)
    fail(final_path_, fmt::format("cannot write attribute {} on {}", name, object));
}

void H5Writer::attribute(const std::string& object, const std::string& name, double value) {
  Handle obj(H5Oopen(file_, object.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) fail(final_path_, fmt::format("no object {} for attribute {}", object, name));
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  if (!attr.valid() || H5Awrite(attr, H5T_NATIVE_DOUBLE, &value) < 0)
    fail(final_path_, fmt::format("cannot write attribute {} on {}", name, object));
}

void H5Writer::attribute(const std::string& object, const std::string& name, std::int64_t value) {
  Handle obj(H5Oopen(file_, object.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) fail(final_path_, fmt::format("no object {} for attribute {}", object, name));
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name.c_str(), H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid() || H5Awrite(attr, H5T_NATIVE_INT64, &value) < 0)
    fail(final_path_, fmt::format("cannot write attribute {} on {}", name, object));
}

void H5Writer::commit() {
  const hid_t file = std::exchange(file_, -1);
  std::string image;
  const bool flushed = H5Fflush(file, H5F_SCOPE_LOCAL) >= 0;
  const ssize_t size = flushed ? H5Fget_file_image(file, nullptr, 0) : -1;
  if (size > 0) {
    image.resize(static_cast<std::size_t>(size));
    if (H5Fget_file_image(file, image.data(), image.size()) != size) image.clear();
  }
  H5Fclose(file);
  if (image.empty()) fail(final_path_, "cannot finish it in memory");
  fix_superblock_checksum(image);
  output::write_file_atomically(final_path_, image);
}

H5Reader::H5Reader(const std::filesystem::path& path) : path_(path) {
  silence_hdf5();
  file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file_ < 0) fail(path, "cannot open (missing, damaged, or not an HDF5 file)" + library_says());
}

H5Reader::~H5Reader() {
  if (file_ >= 0) H5Fclose(file_);
}

bool H5Reader::exists(const std::string& path) const {
  // Check each link along the path, as H5Lexists requires.
  const auto link = [&](const std::string& prefix) {
    const htri_t found = H5Lexists(file_, prefix.c_str(), H5P_DEFAULT);
    if (found < 0) fail(path_, fmt::format("cannot read the group holding {} (damaged?){}", prefix, library_says()));
    return found > 0;
  };
  std::size_t pos = 0;
  while ((pos = path.find('/', pos + 1)) != std::string::npos)
    if (!link(path.substr(0, pos))) return false;
  return link(path);
}

std::vector<std::size_t> H5Reader::shape(const std::string& path) const {
  Handle ds(H5Dopen2(file_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail(path_, fmt::format("no dataset {}{}", path, library_says()));
  Handle space(H5Dget_space(ds), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return {dims.begin(), dims.end()};
}

std::vector<double> H5Reader::read_doubles(const std::string& path) const {
  std::size_t n = 1;
  for (auto d : shape(path)) n *= d;
  std::vector<double> data(n);
  if (n == 0) return data;
  Handle ds(H5Dopen2(file_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    fail(path_, fmt::format("cannot read dataset {} as numbers{}", path, library_says()));
  return data;
}

std::vector<std::int64_t> H5Reader::read_integers(const std::string& path) const {
  std::size_t n = 1;
  for (auto d : shape(path)) n *= d;
  std::vector<std::int64_t> data(n);
  if (n == 0) return data;
  Handle ds(H5Dopen2(file_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (H5Dread(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    fail(path_, fmt::format("cannot read dataset {} as integers{}", path, library_says()));
  return data;
}

std::string H5Reader::read_text(const std::string& path) const {
  Handle ds(H5Dopen2(file_, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail(path_, fmt::format("no dataset {}{}", path, library_says()));
  Handle type(string_type(), H5Tclose);
  char* text = nullptr;
  if (H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text) < 0 || !text)
    fail(path_, fmt::format("cannot read dataset {} as text{}", path, library_says()));
  std::string value(text);
  H5free_memory(text);
  return value;
}

std::string H5Reader::string_attribute(const std::string& object, const std::string& name) const {
  Handle attr(H5Aopen_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  if (!attr.valid()) fail(path_, fmt::format("no attribute {} on {}", name, object));
  Handle type(H5Aget_type(attr), H5Tclose);
  if (H5Tis_variable_str(type) > 0) {
    Handle memory_type(string_type(), H5Tclose);
    char* text = nullptr;
    if (H5Aread(attr, memory_type, &text) < 0 || !text)
      fail(path_, fmt::format("cannot read attribute {} on {}", name, object));
    std::string value(text);
    H5free_memory(text);
    return value;
  }
  // Fixed length, as files of earlier versions hold.
  std::string value(H5Tget_size(type), '\0');
  if (H5Aread(attr, type, value.data()) < 0)
    fail(path_, fmt::format("cannot read attribute {} on {}", name, object));
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

double H5Reader::number_attribute(const std::string& object, const std::string& name) const {
  Handle attr(H5Aopen_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  double v = 0;
  if (!attr.valid() || H5Aread(attr, H5T_NATIVE_DOUBLE, &v) < 0)
    fail(path_, fmt::format("no number attribute {} on {}", name, object));
  return v;
}

std::optional<std::int64_t> H5Reader::integer_attribute(const std::string& object, const std::string& name) const {
  if (H5Aexists_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT) <= 0) return std::nullopt;
  Handle attr(H5Aopen_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  std::int64_t v = 0;
  if (!attr.valid() || H5Aread(attr, H5T_NATIVE_INT64, &v) < 0)
    fail(path_, fmt::format("cannot read the integer attribute {} on {}{}", name, object, library_says()));
  return v;
}

}  // namespace outburst::hdf5
