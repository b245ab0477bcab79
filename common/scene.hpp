#pragma once
// Scene files: TOML, read through typed getters that know each key's unit,
// default, range and meaning.
//
// Every getter records what it read (value, whether defaulted, the doc string) so
// `--explain` can print the full effective configuration of a run, and marks the
// key as used, so keys that no code read (misspellings, keys of a solver the scene
// does not run) are reported at the end of parsing instead of being ignored.
// Errors name the file, line, column and dotted key path, and what was expected.

#include <array>
#include <concepts>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/time_function.hpp"
#include "common/units.hpp"

namespace toml {
inline namespace v3 {
class node;
class table;
}  // namespace v3
}  // namespace toml

namespace outburst::scene {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A well-formed scene that asks for what cannot work in its regime (a
// coupling scheme its stability analysis predicts unstable): refused before
// the first step with its own exit code, so that a sweep can tell a refused
// setting from a mistake.
class Refusal : public Error {
 public:
  using Error::Error;
};

// A numeric range, checked after conversion to SI.
struct Range {
  std::optional<double> min, max;
  bool min_inclusive = true, max_inclusive = true;

  static Range positive() { return {0.0, std::nullopt, false, true}; }
  static Range non_negative() { return {0.0, std::nullopt, true, true}; }
  static Range at_least(double v) { return {v, std::nullopt, true, true}; }
  static Range between(double lo, double hi) { return {lo, hi, true, true}; }
  // Limits are shown divided by `scale`, followed by `unit` ("30 deg").
  std::string describe(double scale = 1, std::string_view unit = {}) const;
  bool contains(double v) const;
};

// Why `path` cannot be read as a file ("a directory", "a device", "a pipe",
// "missing"); nullopt for a regular file.
std::optional<std::string> not_a_regular_file(const std::filesystem::path& path);

// One key a scene may hold. `fallback` is the default as it would be written in
// the scene (for example "1 h"); empty means the key is required.
struct Key {
  std::string_view name;
  std::string_view doc;
  std::string_view fallback = {};
  Range range = {};
};

// What `--explain` prints for each key the run read.
struct ReadRecord {
  std::string path;
  std::string value;  // as TOML would write it
  bool defaulted;
  std::string doc;
  std::string fallback;              // the default as a scene would write it; empty: required
  std::string expects;               // what the key takes ("a pressure", "a number", "one of")
  std::vector<std::string> choices;  // the words a choice takes
  std::string range;                 // the checked range, if any
};

class Document;

// A view of one TOML table inside a Document.
class Table {
 public:
  Table(Document* doc, const toml::table* table, std::string path);

  const std::string& path() const { return path_; }
  bool has(std::string_view key) const;
  // The number of entries of an array key; nullopt when absent or no array.
  // Reads nothing (the key's getter still must): what a reader decides from
  // before it reads the key, as a scene's dimension from its grid's size.
  std::optional<std::size_t> array_length(std::string_view key) const;

  // Dimensional value written with its unit; returned in SI.
  double quantity(const Key& key, const units::Dimension& dimension) const;
  // Like quantity(), but either of two dimensions; returns which was given.
  std::pair<double, units::Dimension> quantity_of(const Key& key,
                                                  const units::Dimension& a,
                                                  const units::Dimension& b) const;
  std::vector<double> quantity_vector(const Key& key, const units::Dimension& dimension,
                                      std::size_t count) const;
  // An array of points, each `components` quantities: [["0 m", "1 m"], ...].
  std::vector<std::vector<double>> quantity_points(const Key& key, const units::Dimension& dimension,
                                                   std::size_t components) const;
  double number(const Key& key) const;
  // An integer checked against the key's range and the range of T (the type
  // the program stores it in), so no value wraps when it is stored.
  template <std::integral T>
  T integer(const Key& key) const;
  template <std::integral T>
  std::vector<T> integer_vector(const Key& key, std::size_t count) const;
  std::vector<double> number_vector(const Key& key, std::size_t count) const;
  bool boolean(const Key& key) const;
  std::string string(const Key& key) const;
  // One of a fixed set of words; the error lists them.
  std::string choice(const Key& key, const std::vector<std::string_view>& choices) const;
  // One of a fixed set of words, each naming a value: the names and what they
  // mean are declared once, at the call, and no word falls through to a default.
  template <class T>
  T choice(const Key& key, std::initializer_list<std::pair<std::string_view, T>> options) const {
    std::vector<std::string_view> names;
    for (const auto& o : options) names.push_back(o.first);
    const std::string word = choice(key, names);
    for (const auto& o : options)
      if (o.first == word) return o.second;
    throw std::logic_error("scene: a checked choice matched no option");
  }
  // One of a registry's models (each with a name and a description, see
  // common/registry.hpp); the key's help is `doc` followed by the models.
  template <class Model>
  const Model& model(std::string_view key, std::string_view doc, std::string_view fallback,
                     const std::vector<Model>& models) const {
    std::vector<std::string_view> names;
    std::string help(doc);
    for (const auto& m : models) {
      names.push_back(m.name);
      help += std::string(names.size() == 1 ? ": " : ", ") + "\"" + std::string(m.name) + "\" (" +
              std::string(m.description) + ")";
    }
    const std::string word = choice({key, help, fallback}, names);
    for (const auto& m : models)
      if (m.name == word) return m;
    throw std::logic_error("scene: a checked choice matched no model");
  }
  std::vector<std::string> choice_list(const Key& key,
                                       const std::vector<std::string_view>& choices) const;
  // A file path, resolved relative to the scene file's folder.
  std::filesystem::path file(const Key& key) const;
  // Either a constant quantity ("0.1 MPa") or a table of [time, value] pairs,
  // interpolated linearly and held constant outside the table.
  TimeFunction time_function(const Key& key, const units::Dimension& dimension) const;

  // A sub-table; `required` false returns nullopt when absent.
  std::optional<Table> table(std::string_view key, std::string_view doc, bool required) const;
  // An array of tables ([[regions]]); empty when absent.
  std::vector<Table> table_array(std::string_view key, std::string_view doc) const;

  // An error located at this key (or at the table when the key is absent).
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;
  // As fail(), for a value that is valid but cannot work here (scene::Refusal).
  [[noreturn]] void refuse(std::string_view key, const std::string& message) const;

 private:
  const toml::node* node(std::string_view key) const;
  const toml::node* required_node(const Key& key) const;
  // `expects` and `choices` for --explain; `range` when the key's range is
  // not shown in SI (angles).
  void record(const Key& key, const std::string& value, bool defaulted, std::string expects,
              std::vector<std::string> choices = {}, std::string range = {}) const;
  std::string key_path(std::string_view key) const;

  Document* doc_;
  const toml::table* table_;
  std::string path_;
};

class Document {
 public:
  // Parse a scene file; each override is "dotted.key=<TOML value>" and replaces or
  // adds that key (for studies and quick experiments from the command line).
  static std::unique_ptr<Document> load(const std::filesystem::path& file,
                                        const std::vector<std::string>& overrides = {});
  // Parse scene text directly (tests); `name` stands in for the file name.
  static std::unique_ptr<Document> parse(std::string_view text, const std::string& name,
                                         const std::vector<std::string>& overrides = {});
  ~Document();

  Table root();
  const std::filesystem::path& file() const { return file_; }
  const std::string& text() const { return text_; }
  const std::vector<std::string>& overrides() const { return overrides_; }

  // Throws Error for the first key that no getter read, listing its siblings.
  void reject_unused() const;
  const std::vector<ReadRecord>& records() const { return records_; }
  // Every key the run read: as aligned text lines, or as one JSON object
  // {"scene": file, "keys": [{"key", "value", "default", "fallback", "doc",
  // "expects", "choices", "range"}, ...]} for scripts that need the names a
  // choice takes (tests, studies).
  std::string explain() const;
  std::string explain_json() const;

  // Error message with location: "file:line:col: key 'a.b': message".
  std::string located(const toml::node* node, const std::string& key_path,
                      const std::string& message) const;
  // For a missing key: keys nothing has read whose names are one or two
  // letters off a part of `key_path` (a misspelt "[couplings]" leaves
  // "coupling.window" missing). Empty when there is none.
  std::string misspelling_hint(const std::string& key_path) const;

 private:
  friend class Table;
  Document() = default;
  void mark_used(const toml::node* node);
  void check_unused(const toml::table& table, const std::string& path) const;

  std::filesystem::path file_;
  std::string text_;
  std::vector<std::string> overrides_;
  std::set<std::string> overridden_paths_;
  std::unique_ptr<toml::table> root_;
  std::set<const toml::node*> used_;
  std::vector<ReadRecord> records_;
};

}  // namespace outburst::scene
