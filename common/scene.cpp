#include "common/scene.hpp"

#include <algorithm>
#include <charconv>
#include <functional>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

namespace outburst::scene {

namespace {

std::string read_text(const std::filesystem::path& file) {
  // A device (/dev/zero) or a pipe would be read without end.
  if (const auto what = not_a_regular_file(file))
    throw Error(fmt::format("{}: the scene is {}; expected a TOML file", file.string(), *what));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open the scene file", file.string()));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string node_text(const toml::node& n) {
  if (const auto* s = n.as_string()) return s->get();
  if (const auto* f = n.as_floating_point()) return fmt::format("{}", f->get());  // shortest, and exact
  std::ostringstream out;
  n.visit([&](const auto& v) { out << v; });
  return out.str();
}

std::vector<std::string_view> split_commas(std::string_view text) {
  std::vector<std::string_view> parts;
  while (true) {
    const auto comma = text.find(',');
    std::string_view part = text.substr(0, comma);
    while (!part.empty() && part.front() == ' ') part.remove_prefix(1);
    while (!part.empty() && part.back() == ' ') part.remove_suffix(1);
    parts.push_back(part);
    if (comma == std::string_view::npos) return parts;
    text.remove_prefix(comma + 1);
  }
}

double parse_number_text(std::string_view text) {
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size())
    throw std::logic_error(fmt::format("default '{}' is not a number", text));
  return v;
}

// "a pressure", "an angle".
std::string with_article(const std::string& noun) {
  const bool vowel = !noun.empty() && std::string_view("aeiou").find(noun.front()) != std::string_view::npos;
  return (vowel ? "an " : "a ") + noun;
}

// ", such as \"3 s\"" (or an array of `count` of them), in the dimension's
// unit; empty for a dimension no single unit has.
std::string example(double value, const units::Dimension& dimension, std::size_t count = 0) {
  const std::string unit = units::symbol(dimension);
  if (unit.empty()) return {};
  if (count == 0) return fmt::format(", such as \"{:g} {}\"", value, unit);
  std::string items;
  for (std::size_t k = 0; k < count; ++k) items += fmt::format("{}\"{:g} {}\"", k ? ", " : "", value + k, unit);
  return ", such as [" + items + "]";
}

// Angle keys are written in degrees, so their ranges are shown in degrees;
// the others in SI.
std::string range_text(const Range& range, const units::Dimension& dimension) {
  if (dimension == units::angle) return range.describe(std::numbers::pi / 180, "deg");
  return range.describe() + " (in SI)";
}

// The key's range narrowed to the values T holds.
template <std::integral T>
Range within_type(Range range) {
  const double lowest = static_cast<double>(std::numeric_limits<T>::min());
  const double highest = static_cast<double>(std::numeric_limits<T>::max());
  if (!range.min || *range.min < lowest) range.min = lowest, range.min_inclusive = true;
  if (!range.max || *range.max > highest) range.max = highest, range.max_inclusive = true;
  return range;
}

// Edits (insertions, deletions, substitutions, swaps of neighbours) that turn a into b.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// "bodies" -> "body", "regions" -> "region".
std::string singular(std::string_view word) {
  if (word.ends_with("ies")) return std::string(word.substr(0, word.size() - 3)) + "y";
  if (word.ends_with("s")) return std::string(word.substr(0, word.size() - 1));
  return std::string(word);
}

// One slip of the keyboard (two in a long name), a plural for a singular or
// the other way round, or a few letters too many ("scenery"); short names
// differ too little to tell a slip from another key.
bool looks_misspelt(std::string_view written, std::string_view meant) {
  if (written == meant || meant.size() < 4) return false;
  return edit_distance(written, meant) <= (std::min(written.size(), meant.size()) >= 10 ? 2 : 1) ||
         singular(written) == singular(meant) || (written.starts_with(meant) && written.size() <= meant.size() + 3);
}

std::string join(const std::vector<std::string_view>& words) {
  std::string s;
  for (const auto& w : words) s += fmt::format("{}\"{}\"", s.empty() ? "" : ", ", w);
  return s;
}

// How deep a scene's keys and values may nest: tables of tables (counting
// each part of a dotted key or header), arrays and inline tables. Scenes need
// a handful of levels; toml++ parses nesting by recursion, as do the readers
// here, and a 70 kB scene of one 35,000-part dotted key overflowed the stack.
constexpr int max_depth = 32;

// Refuses text nested deeper than max_depth, before toml++ sees it. A scan of
// TOML's lexical structure (strings, comments, keys, headers, arrays, inline
// tables), not a parser: what it does not follow it skips, so it always reaches
// the end, and leaves syntax errors to toml++. A --set value comes as "v =
// <value>", and is named by its `override_key` instead.
void check_depth(std::string_view text, const std::string& name, std::string_view override_key = {}) {
  std::size_t i = 0, line = 1, line_start = 0;
  const std::size_t n = text.size();
  const auto at = [&](std::size_t k) { return k < n ? text[k] : '\0'; };
  // `depth`: how deep the key goes, or (`at_least`) where the scan stopped.
  const auto refuse = [&](std::size_t start, std::size_t key_start, std::size_t key_stop, int depth,
                          bool at_least = false) {
    std::string key(override_key.empty() ? text.substr(key_start, std::min<std::size_t>(key_stop - key_start, 60))
                                         : override_key);
    if (override_key.empty() && key_stop - key_start > 60) key += "...";
    const std::string where =
        override_key.empty() ? fmt::format("{}:{}:{}", name, line, start - line_start + 1) : name;
    throw Error(fmt::format("{}: key '{}': nested {}{} levels deep (each table, part of a dotted key, array and "
                            "inline table is a level); a scene may nest at most {}",
                            where, key, depth, at_least ? " or more" : "", max_depth));
  };
  const auto newline = [&] {
    ++line;
    line_start = i + 1;
  };
  const auto skip_blanks = [&] {
    while (i < n && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r')) ++i;
  };
  // Blanks, newlines and comments: between the values of an array.
  const auto skip_space = [&] {
    for (;;) {
      skip_blanks();
      if (at(i) == '#')
        while (i < n && text[i] != '\n') ++i;
      if (at(i) != '\n') return;
      newline();
      ++i;
    }
  };
  const auto skip_string = [&] {
    const char quote = text[i];
    const bool multi = at(i + 1) == quote && at(i + 2) == quote;
    i += multi ? 3 : 1;
    while (i < n) {
      const char c = text[i];
      if (c == '\\' && quote == '"') {
        i += at(i + 1) == '\n' ? 1 : 2;  // a line-ending backslash: the newline is counted next
        continue;
      }
      if (c == '\n') {
        newline();
        if (!multi) return;  // unterminated: toml++ says so
      }
      if (c == quote && (!multi || (at(i + 1) == quote && at(i + 2) == quote))) {
        i += multi ? 3 : 1;
        while (multi && at(i) == quote) ++i;  // up to two quotes of the content before the closing three
        return;
      }
      ++i;
    }
  };
  const auto bare = [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  };
  // A dotted key's parts (0: none there); key_end is where its last one ends.
  std::size_t key_end = 0;
  const auto key_parts = [&] {
    int parts = 0;
    for (;;) {
      skip_blanks();
      if (at(i) == '"' || at(i) == '\'') {
        skip_string();
      } else if (bare(at(i))) {
        while (bare(at(i))) ++i;
      } else {
        return parts;
      }
      ++parts;
      key_end = i;
      skip_blanks();
      if (at(i) != '.') return parts;
      ++i;
    }
  };
  const auto skip_scalar = [&] {
    const std::size_t start = i;
    while (i < n && std::string_view(",]}#\n \t\r").find(text[i]) == std::string_view::npos) ++i;
    if (i == start) ++i;
  };

  struct Open {
    char close;  // ']' an array, '}' an inline table
    int depth;   // of its values (an inline table's: before its keys' parts)
  };
  std::vector<Open> open;
  if (text.starts_with("\xEF\xBB\xBF")) i = 3;
  int table_depth = 0;  // of the last [header]
  while (i < n) {
    // A statement: a [header], [[header]], or key = value.
    skip_space();
    if (i >= n) break;
    const std::size_t start = i;
    if (text[i] == '[') {
      i += at(i + 1) == '[' ? 2 : 1;
      const std::size_t key_start = i;
      table_depth = key_parts();
      if (table_depth > max_depth) refuse(start, key_start, key_end, table_depth);
      while (i < n && text[i] != '\n' && text[i] != '#') ++i;
      continue;
    }
    const int parts = key_parts();
    const std::size_t statement_key_end = key_end;
    if (parts == 0 || at(i) != '=') {
      while (i < n && text[i] != '\n') ++i;  // not a statement: toml++ says what it is
      continue;
    }
    if (table_depth + parts > max_depth) refuse(start, start, statement_key_end, table_depth + parts);
    ++i;
    // The value, and the values and keys inside it.
    enum class Next { value, comma_or_close, key };
    Next next = Next::value;
    int depth = table_depth + parts;
    open.clear();
    for (;;) {
      if (open.empty())
        skip_blanks();  // a value ends with its line
      else
        skip_space();
      if (i >= n) break;
      const char c = text[i];
      if (next == Next::value) {
        next = Next::comma_or_close;
        if (c == '[' || c == '{') {
          if (c == '[') ++depth;
          if (depth > max_depth) refuse(i, start, statement_key_end, depth, true);
          open.push_back({c == '[' ? ']' : '}', depth});
          ++i;
          next = c == '[' ? Next::value : Next::key;
        } else if (c == '"' || c == '\'') {
          skip_string();
        } else if (c != ']' && c != '}') {  // those close an empty array, or one after a trailing comma
          skip_scalar();
        }
      } else if (next == Next::comma_or_close) {
        if (open.empty()) break;  // the statement's end
        if (c == ',') {
          ++i;
          depth = open.back().depth;
          next = open.back().close == ']' ? Next::value : Next::key;
        } else if (c == ']' || c == '}') {
          ++i;
          open.pop_back();
        } else {
          skip_scalar();  // the time of a date-time, or what toml++ will refuse
        }
      } else if (c == '}') {  // an empty inline table
        ++i;
        open.pop_back();
        next = Next::comma_or_close;
      } else {
        const std::size_t key_start = i;
        const int inner = key_parts();
        skip_blanks();
        if (at(i) == '=')
          ++i;
        else if (i == key_start)
          skip_scalar();  // not a key: past it, whatever it is
        depth = open.back().depth + std::max(inner, 1);
        if (depth > max_depth) refuse(key_start, start, statement_key_end, depth, true);
        next = Next::value;
      }
    }
  }
}

// Insert `value` (TOML syntax) at a dotted path, creating tables on the way.
void apply_override(toml::table& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(fmt::format("--set '{}': expected key=value, for example "
                            "--set seepage.time_step='\"1 h\"'",
                            assignment));
  const std::string path = assignment.substr(0, eq);
  if (const auto parts = std::count(path.begin(), path.end(), '.') + 1; parts > max_depth)
    throw Error(fmt::format("--set: key '{}...': nested {} levels deep (each part of a dotted key is a level); a "
                            "scene may nest at most {}",
                            path.substr(0, 60), parts, max_depth));
  toml::table parsed;
  const std::string value = "v = " + assignment.substr(eq + 1);
  check_depth(value, "--set", path);
  try {
    parsed = toml::parse(value, std::string_view("--set"));
  } catch (const toml::parse_error& e) {
    throw Error(fmt::format("--set '{}': the value is not TOML ({}); strings need quotes, "
                            "for example --set seepage.time_step='\"1 h\"'",
                            assignment, e.description()));
  }
  // Walk the dotted path; "regions[1]" steps into an array of tables.
  toml::table* target = &root;
  std::string_view rest = path;
  for (;;) {
    const auto dot = rest.find('.');
    std::string key(rest.substr(0, dot));
    std::optional<std::size_t> index;
    if (const auto open = key.find('['); open != std::string::npos && key.back() == ']') {
      const std::string digits = key.substr(open + 1, key.size() - open - 2);
      if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos)
        throw Error(fmt::format("--set '{}': '{}' is not an index; write {}[0]", assignment, digits,
                                key.substr(0, open)));
      std::size_t value = 0;
      if (std::from_chars(digits.data(), digits.data() + digits.size(), value).ec != std::errc())
        throw Error(fmt::format("--set '{}': the scene has no table {}", assignment, key));
      index = value;
      key.resize(open);
    }
    if (dot == std::string_view::npos && !index) {
      parsed.get("v")->visit([&](auto& v) { target->insert_or_assign(key, v); });
      return;
    }
    toml::node* next = target->get(key);
    if (index) {
      auto* arr = next ? next->as_array() : nullptr;
      if (!arr || !arr->is_array_of_tables() || *index >= arr->size())
        throw Error(fmt::format("--set '{}': the scene has no table {}[{}]", assignment, key, *index));
      next = arr->get(*index);
      if (dot == std::string_view::npos)
        throw Error(fmt::format("--set '{}': name a key inside {}[{}]", assignment, key, *index));
    } else if (!next) {
      next = target->insert_or_assign(key, toml::table{}).first->second.as_table();
    }
    if (!next->is_table())
      throw Error(fmt::format("--set '{}': '{}' is not a table", assignment, key));
    target = next->as_table();
    rest.remove_prefix(dot + 1);
  }
}

}  // namespace

// ---------------------------------------------------------------- Range

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (min && (min_inclusive ? v < *min : v <= *min)) return false;
  if (max && (max_inclusive ? v > *max : v >= *max)) return false;
  return true;
}

std::string Range::describe(double scale, std::string_view unit) const {
  const auto limit = [&](bool inclusive, bool lower, double v) {
    const double shown = v / scale;
    // Integer limits in full (2147483647, not 2.14748e+09).
    const std::string number =
        shown == std::round(shown) && std::abs(shown) < 1e15 ? fmt::format("{:.0f}", shown) : fmt::format("{:g}", shown);
    return fmt::format("{} {}{}{}", lower ? (inclusive ? ">=" : ">") : (inclusive ? "<=" : "<"), number,
                       unit.empty() ? "" : " ", unit);
  };
  if (min && max) return limit(min_inclusive, true, *min) + " and " + limit(max_inclusive, false, *max);
  if (min) return limit(min_inclusive, true, *min);
  if (max) return limit(max_inclusive, false, *max);
  return "finite";
}

std::optional<std::string> not_a_regular_file(const std::filesystem::path& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  switch (status.type()) {
    case std::filesystem::file_type::regular: return std::nullopt;
    case std::filesystem::file_type::directory: return "a directory";
    case std::filesystem::file_type::character:
    case std::filesystem::file_type::block: return "a device";
    case std::filesystem::file_type::fifo: return "a pipe";
    case std::filesystem::file_type::socket: return "a socket";
    case std::filesystem::file_type::not_found: return "missing";
    default: return "not a regular file";
  }
}

// ---------------------------------------------------------------- Document

std::unique_ptr<Document> Document::load(const std::filesystem::path& file,
                                         const std::vector<std::string>& overrides) {
  auto doc = parse(read_text(file), file.string(), overrides);
  doc->file_ = file;
  return doc;
}

std::unique_ptr<Document> Document::parse(std::string_view text, const std::string& name,
                                          const std::vector<std::string>& overrides) {
  std::unique_ptr<Document> doc(new Document());
  doc->file_ = name;
  doc->text_ = std::string(text);
  doc->overrides_ = overrides;
  check_depth(doc->text_, name);
  try {
    doc->root_ = std::make_unique<toml::table>(toml::parse(doc->text_, name));
  } catch (const toml::parse_error& e) {
    throw Error(fmt::format("{}:{}:{}: not valid TOML: {}", name, e.source().begin.line,
                            e.source().begin.column, e.description()));
  }
  for (const auto& o : overrides) {
    apply_override(*doc->root_, o);
    doc->overridden_paths_.insert(o.substr(0, o.find('=')));
  }
  return doc;
}

Document::~Document() = default;

Table Document::root() { return Table(this, root_.get(), ""); }

void Document::mark_used(const toml::node* n) {
  used_.insert(n);
  if (const auto* arr = n->as_array())
    for (const auto& child : *arr) mark_used(&child);
}

std::string Document::located(const toml::node* n, const std::string& key_path,
                              const std::string& message) const {
  std::string where = file_.string();
  if (overridden_paths_.count(key_path))
    where = "--set";
  else if (n && n->source().begin.line > 0)
    where = fmt::format("{}:{}:{}", file_.string(), n->source().begin.line, n->source().begin.column);
  if (key_path.empty()) return fmt::format("{}: {}", where, message);
  return fmt::format("{}: key '{}': {}", where, key_path, message);
}

std::string Document::misspelling_hint(const std::string& key_path) const {
  // Along the path, each table's unread keys against the name wanted there:
  // a misspelt key is a sibling of the missing one or of a table above it.
  std::vector<std::string> suspects;
  const toml::table* table = root_.get();
  std::string at;
  for (std::string_view rest = key_path; table && !rest.empty();) {
    const auto dot = rest.find('.');
    const std::string_view part = rest.substr(0, dot);
    const std::string name(part.substr(0, part.find('[')));
    for (const auto& [k, v] : *table)
      if (!used_.count(&v) && looks_misspelt(k.str(), name))
        suspects.push_back(fmt::format("'{}{}' ({}:{}:{})", at, k.str(), file_.string(), v.source().begin.line,
                                       v.source().begin.column));
    const toml::node* next = table->get(name);
    if (next && part.find('[') != std::string_view::npos) {
      std::size_t index = 0;
      std::from_chars(part.data() + part.find('[') + 1, part.data() + part.size(), index);
      next = next->is_array() ? next->as_array()->get(index) : nullptr;
    }
    table = next ? next->as_table() : nullptr;
    at += std::string(part) + ".";
    rest = dot == std::string_view::npos ? std::string_view() : rest.substr(dot + 1);
  }
  if (suspects.empty()) return {};
  std::string list;
  for (const auto& s : suspects) list += (list.empty() ? "" : ", ") + s;
  return fmt::format("; the scene has {}, which nothing reads: misspelt?", list);
}

void Document::check_unused(const toml::table& table, const std::string& path) const {
  for (const auto& [k, v] : table) {
    const std::string key_path = path.empty() ? std::string(k.str()) : path + "." + std::string(k.str());
    if (!used_.count(&v)) {
      std::string read;
      for (const auto& [k2, v2] : table)
        if (used_.count(&v2)) read += fmt::format("{}{}", read.empty() ? "" : ", ", k2.str());
      const std::string section = path.empty() ? "the top level" : "[" + path + "]";
      const std::string hint = read.empty()
                                   ? fmt::format("nothing in {} is read by this scene's solvers",
                                                 section)
                                   : fmt::format("keys this scene reads in {}: {}", section, read);
      throw Error(located(&v, key_path,
                          fmt::format("unknown key, or a key this scene does not use ({})", hint)));
    }
    if (const auto* sub = v.as_table()) check_unused(*sub, key_path);
    if (const auto* arr = v.as_array(); arr && arr->is_array_of_tables())
      for (std::size_t i = 0; i < arr->size(); ++i)
        check_unused(*arr->get(i)->as_table(), fmt::format("{}[{}]", key_path, i));
  }
}

void Document::reject_unused() const { check_unused(*root_, ""); }

std::string Document::explain() const {
  std::size_t width = 0;
  for (const auto& r : records_) width = std::max(width, r.path.size() + r.value.size() + 3);
  std::string out;
  for (const auto& r : records_) {
    const std::string kv = fmt::format("{} = {}", r.path, r.value);
    out += fmt::format("{:<{}} {} {}\n", kv, width, r.defaulted ? "(default)" : "         ",
                       r.doc);
  }
  return out;
}

std::string Document::explain_json() const {
  toml::array keys;
  for (const auto& r : records_) {
    toml::array choices;
    for (const auto& c : r.choices) choices.push_back(c);
    keys.push_back(toml::table{{"key", r.path},
                               {"value", r.value},
                               {"default", r.defaulted},
                               {"fallback", r.fallback},
                               {"doc", r.doc},
                               {"expects", r.expects},
                               {"choices", std::move(choices)},
                               {"range", r.range}});
  }
  const toml::table root{{"scene", file_.string()}, {"keys", std::move(keys)}};
  std::ostringstream out;
  out << toml::json_formatter{root} << "\n";
  return out.str();
}

// ---------------------------------------------------------------- Table

Table::Table(Document* doc, const toml::table* table, std::string path)
    : doc_(doc), table_(table), path_(std::move(path)) {}

std::string Table::key_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

bool Table::has(std::string_view key) const { return table_->get(key) != nullptr; }

std::optional<std::size_t> Table::array_length(std::string_view key) const {
  const toml::node* n = table_->get(key);
  if (const auto* arr = n ? n->as_array() : nullptr) return arr->size();
  return std::nullopt;
}

const toml::node* Table::node(std::string_view key) const {
  const toml::node* n = table_->get(key);
  if (n) doc_->mark_used(n);
  return n;
}

void Table::fail(std::string_view key, const std::string& message) const {
  const toml::node* n = table_->get(key);
  if (n) throw Error(doc_->located(n, key_path(key), message));
  throw Error(doc_->located(table_, key_path(key), message + doc_->misspelling_hint(key_path(key))));
}

void Table::refuse(std::string_view key, const std::string& message) const {
  const toml::node* n = table_->get(key);
  throw Refusal(doc_->located(n ? n : table_, key_path(key), message));
}

const toml::node* Table::required_node(const Key& key) const {
  const toml::node* n = node(key.name);
  if (!n && key.fallback.empty()) fail(key.name, fmt::format("required key is missing ({})", key.doc));
  return n;
}

void Table::record(const Key& key, const std::string& value, bool defaulted, std::string expects,
                   std::vector<std::string> choices, std::string range) const {
  // A key without limits shows none (not its type's, not "finite").
  if (!key.range.min && !key.range.max)
    range.clear();
  else if (range.empty())
    range = key.range.describe();
  doc_->records_.push_back({key_path(key.name), value, defaulted, std::string(key.doc), std::string(key.fallback),
                            std::move(expects), std::move(choices), std::move(range)});
}

namespace {

units::Quantity quantity_from_text(std::string_view text, const units::Dimension& dimension,
                                   const std::function<void(const std::string&)>& fail) {
  units::Quantity q{};
  try {
    q = units::parse_quantity(text);
  } catch (const units::UnitError& e) {
    fail(fmt::format("expected {} with its unit: {}", with_article(units::describe(dimension)), e.what()));
  }
  if (!(q.dimension == dimension)) {
    const std::string given = q.dimension == units::dimensionless
                                  ? std::string("a bare number")
                                  : with_article(units::describe(q.dimension));
    fail(fmt::format("expected {} with its unit, got \"{}\", which is {}",
                     with_article(units::describe(dimension)), text, given));
  }
  return q;
}

}  // namespace

double Table::quantity(const Key& key, const units::Dimension& dimension) const {
  return quantity_of(key, dimension, dimension).first;
}

std::pair<double, units::Dimension> Table::quantity_of(const Key& key,
                                                       const units::Dimension& a,
                                                       const units::Dimension& b) const {
  const toml::node* n = required_node(key);
  const std::string expected = a == b ? with_article(units::describe(a))
                                      : with_article(units::describe(a)) + " or " + with_article(units::describe(b));
  std::string text;
  if (n) {
    if (!n->is_string()) {
      if (n->is_number())
        fail(key.name, fmt::format("expected {} with its unit as a string{}; a bare number has no unit", expected,
                                   example(n->value<double>().value_or(1), a)));
      fail(key.name, fmt::format("expected {} with its unit as a string", expected));
    }
    text = n->as_string()->get();
  } else {
    text = key.fallback;
  }
  units::Quantity q{};
  try {
    q = units::parse_quantity(text);
  } catch (const units::UnitError& e) {
    fail(key.name, fmt::format("expected {} with its unit: {}", expected, e.what()));
  }
  if (!(q.dimension == a) && !(q.dimension == b)) {
    const std::string given = q.dimension == units::dimensionless
                                  ? std::string("a bare number")
                                  : with_article(units::describe(q.dimension));
    fail(key.name, fmt::format("expected {} with its unit, got \"{}\", which is {}", expected,
                               text, given));
  }
  if (!key.range.contains(q.si))
    fail(key.name, fmt::format("must be {}, got \"{}\"", range_text(key.range, q.dimension), text));
  record(key, text, n == nullptr, expected, {}, range_text(key.range, q.dimension));
  return {q.si, q.dimension};
}

std::vector<double> Table::quantity_vector(const Key& key, const units::Dimension& dimension,
                                           std::size_t count) const {
  const toml::node* n = required_node(key);
  std::vector<std::string> texts;
  if (n) {
    const auto* arr = n->as_array();
    if (!arr || arr->size() != count)
      fail(key.name, fmt::format("expected an array of {} {} values with units{}", count, units::describe(dimension),
                                 example(0, dimension, count)));
    for (const auto& item : *arr) {
      if (!item.is_string())
        fail(key.name, fmt::format("expected each entry as {} with its unit, as a string",
                                   with_article(units::describe(dimension))));
      texts.push_back(item.as_string()->get());
    }
  } else {
    for (auto part : split_commas(key.fallback)) texts.emplace_back(part);
  }
  std::vector<double> values;
  std::string shown;
  for (const auto& t : texts) {
    const auto q = quantity_from_text(t, dimension, [&](const std::string& m) { fail(key.name, m); });
    if (!key.range.contains(q.si))
      fail(key.name, fmt::format("each entry must be {}, got \"{}\"", range_text(key.range, dimension), t));
    values.push_back(q.si);
    shown += fmt::format("{}\"{}\"", shown.empty() ? "" : ", ", t);
  }
  record(key, "[" + shown + "]", n == nullptr, fmt::format("{} values: {}", count, units::describe(dimension)), {},
         range_text(key.range, dimension));
  return values;
}

std::vector<std::vector<double>> Table::quantity_points(const Key& key, const units::Dimension& dimension,
                                                       std::size_t components) const {
  const toml::node* n = required_node(key);
  const std::string form = fmt::format("expected an array of points [{}, ...], each coordinate {} with its unit",
                                       components == 2 ? "[\"x\", \"y\"]" : "[\"x\", \"y\", \"z\"]",
                                       with_article(units::describe(dimension)));
  const auto* arr = n ? n->as_array() : nullptr;
  if (!arr) fail(key.name, form);
  std::vector<std::vector<double>> points;
  for (const auto& item : *arr) {
    const auto* point = item.as_array();
    if (!point || point->size() != components) fail(key.name, form);
    auto& values = points.emplace_back();
    for (const auto& coordinate : *point) {
      if (!coordinate.is_string()) fail(key.name, form);
      values.push_back(
          quantity_from_text(coordinate.as_string()->get(), dimension, [&](const std::string& m) { fail(key.name, m); })
              .si);
    }
  }
  record(key, node_text(*n), false, fmt::format("points of {} coordinates: {}", components, units::describe(dimension)));
  return points;
}

double Table::number(const Key& key) const {
  const toml::node* n = required_node(key);
  double v = 0;
  if (n) {
    if (n->is_string())
      fail(key.name, fmt::format("expected a plain number (dimensionless), got the string \"{}\"",
                                 n->as_string()->get()));
    const auto value = n->value<double>();
    if (!value) fail(key.name, "expected a number");
    v = *value;
  } else {
    v = parse_number_text(key.fallback);
  }
  if (!key.range.contains(v))
    fail(key.name, fmt::format("must be {}, got {:g}", key.range.describe(), v));
  record(key, n ? node_text(*n) : std::string(key.fallback), n == nullptr, "a number");
  return v;
}

template <std::integral T>
T Table::integer(const Key& key) const {
  const toml::node* n = required_node(key);
  std::int64_t v = 0;
  if (n) {
    if (!n->is_integer()) fail(key.name, fmt::format("expected an integer, got {}", node_text(*n)));
    v = n->as_integer()->get();
  } else {
    v = static_cast<std::int64_t>(parse_number_text(key.fallback));
  }
  const Range range = within_type<T>(key.range);
  if (!range.contains(static_cast<double>(v))) fail(key.name, fmt::format("must be {}, got {}", range.describe(), v));
  record(key, std::to_string(v), n == nullptr, "an integer", {}, within_type<T>(key.range).describe());
  return static_cast<T>(v);
}

template <std::integral T>
std::vector<T> Table::integer_vector(const Key& key, std::size_t count) const {
  const toml::node* n = required_node(key);
  std::vector<std::int64_t> values;
  if (n) {
    const auto* arr = n->as_array();
    if (!arr || arr->size() != count)
      fail(key.name, fmt::format("expected an array of {} integers", count));
    for (const auto& item : *arr) {
      if (!item.is_integer()) fail(key.name, fmt::format("expected an array of {} integers", count));
      values.push_back(item.as_integer()->get());
    }
  } else {
    for (auto part : split_commas(key.fallback))
      values.push_back(static_cast<std::int64_t>(parse_number_text(part)));
  }
  const Range range = within_type<T>(key.range);
  std::string shown;
  for (const std::int64_t v : values) {
    if (!range.contains(static_cast<double>(v)))
      fail(key.name, fmt::format("each entry must be {}, got {}", range.describe(), v));
    shown += fmt::format("{}{}", shown.empty() ? "" : ", ", v);
  }
  record(key, "[" + shown + "]", n == nullptr, fmt::format("{} integers", count), {}, range.describe());
  return {values.begin(), values.end()};
}

// The programs store their integer keys as int; seeds as 64-bit integers.
template int Table::integer<int>(const Key&) const;
template std::int64_t Table::integer<std::int64_t>(const Key&) const;
template std::vector<int> Table::integer_vector<int>(const Key&, std::size_t) const;

std::vector<double> Table::number_vector(const Key& key, std::size_t count) const {
  const toml::node* n = required_node(key);
  std::vector<double> values;
  if (n) {
    const auto* arr = n->as_array();
    if (!arr || arr->size() != count)
      fail(key.name, fmt::format("expected an array of {} numbers", count));
    for (const auto& item : *arr) {
      const auto v = item.value<double>();
      if (!v || item.is_string()) fail(key.name, fmt::format("expected an array of {} numbers", count));
      values.push_back(*v);
    }
  } else {
    for (auto part : split_commas(key.fallback)) values.push_back(parse_number_text(part));
  }
  std::string shown;
  for (double v : values) {
    if (!key.range.contains(v))
      fail(key.name, fmt::format("each entry must be {}, got {:g}", key.range.describe(), v));
    shown += fmt::format("{}{:g}", shown.empty() ? "" : ", ", v);
  }
  record(key, "[" + shown + "]", n == nullptr, fmt::format("{} numbers", count));
  return values;
}

bool Table::boolean(const Key& key) const {
  const toml::node* n = required_node(key);
  bool v = key.fallback == "true";
  if (n) {
    if (!n->is_boolean()) fail(key.name, fmt::format("expected true or false, got {}", node_text(*n)));
    v = n->as_boolean()->get();
  }
  record(key, v ? "true" : "false", n == nullptr, "true or false");
  return v;
}

std::string Table::string(const Key& key) const {
  const toml::node* n = required_node(key);
  std::string v(key.fallback);
  if (n) {
    if (!n->is_string()) fail(key.name, fmt::format("expected a string, got {}", node_text(*n)));
    v = n->as_string()->get();
  }
  record(key, "\"" + v + "\"", n == nullptr, "a string");
  return v;
}

std::string Table::choice(const Key& key, const std::vector<std::string_view>& choices) const {
  const toml::node* n = required_node(key);
  std::string v(key.fallback);
  if (n) {
    if (!n->is_string())
      fail(key.name, fmt::format("expected one of {}, got {}", join(choices), node_text(*n)));
    v = n->as_string()->get();
  }
  if (std::find(choices.begin(), choices.end(), v) == choices.end())
    fail(key.name, fmt::format("expected one of {}, got \"{}\"", join(choices), v));
  record(key, "\"" + v + "\"", n == nullptr, "one of", {choices.begin(), choices.end()});
  return v;
}

std::vector<std::string> Table::choice_list(const Key& key,
                                            const std::vector<std::string_view>& choices) const {
  const toml::node* n = required_node(key);
  std::vector<std::string> values;
  if (n) {
    const auto* arr = n->as_array();
    if (!arr) fail(key.name, fmt::format("expected an array of words from {}", join(choices)));
    for (const auto& item : *arr) {
      if (!item.is_string())
        fail(key.name, fmt::format("expected an array of words from {}", join(choices)));
      values.push_back(item.as_string()->get());
    }
  } else {
    for (auto part : split_commas(key.fallback))
      if (!part.empty()) values.emplace_back(part);
  }
  std::string shown;
  for (const auto& v : values) {
    if (std::find(choices.begin(), choices.end(), v) == choices.end())
      fail(key.name, fmt::format("\"{}\" is not one of {}", v, join(choices)));
    if (std::count(values.begin(), values.end(), v) > 1)
      fail(key.name, fmt::format("\"{}\" is listed twice", v));
    shown += fmt::format("{}\"{}\"", shown.empty() ? "" : ", ", v);
  }
  record(key, "[" + shown + "]", n == nullptr, "a list of", {choices.begin(), choices.end()});
  return values;
}

std::filesystem::path Table::file(const Key& key) const {
  const std::string text = string(key);
  std::filesystem::path p(text);
  if (p.is_relative()) p = doc_->file().parent_path() / p;
  if (const auto what = not_a_regular_file(p))
    fail(key.name, *what == "missing"
                       ? fmt::format("the file \"{}\" does not exist (looked for {})", text, p.string())
                       : fmt::format("\"{}\" is {} (looked at {}); expected a file", text, *what, p.string()));
  return p;
}

TimeFunction Table::time_function(const Key& key, const units::Dimension& dimension) const {
  const toml::node* n = table_->get(key.name);
  if (!n || n->is_string()) return TimeFunction(quantity(key, dimension));
  node(key.name);
  const auto* arr = n->as_array();
  const std::string form = fmt::format(
      "expected {} with its unit (\"0.1 MPa\") or a table of [time, value] pairs "
      "([[\"0 s\", \"3 MPa\"], [\"10 s\", \"0.1 MPa\"]])",
      with_article(units::describe(dimension)));
  if (!arr || arr->empty()) fail(key.name, form);
  std::vector<std::pair<double, double>> points;
  for (const auto& item : *arr) {
    const auto* pair = item.as_array();
    if (!pair || pair->size() != 2 || !pair->get(0)->is_string() || !pair->get(1)->is_string())
      fail(key.name, form);
    const auto fail_here = [&](const std::string& m) { fail(key.name, m); };
    const double t = quantity_from_text(pair->get(0)->as_string()->get(), units::time, fail_here).si;
    const double v =
        quantity_from_text(pair->get(1)->as_string()->get(), dimension, fail_here).si;
    if (!points.empty() && t <= points.back().first)
      fail(key.name, "the times of the [time, value] pairs must increase strictly");
    if (!key.range.contains(v))
      fail(key.name, fmt::format("every value must be {}, got \"{}\"", range_text(key.range, dimension),
                                 pair->get(1)->as_string()->get()));
    points.emplace_back(t, v);
  }
  record(key, node_text(*n), false, "a constant or [time, value] pairs: " + units::describe(dimension), {},
         range_text(key.range, dimension));
  return TimeFunction(std::move(points));
}

std::optional<Table> Table::table(std::string_view key, std::string_view doc, bool required) const {
  const toml::node* n = node(key);
  if (!n) {
    if (required) fail(key, fmt::format("required section [{}] is missing ({})", key_path(key), doc));
    return std::nullopt;
  }
  if (!n->is_table()) fail(key, fmt::format("expected a section (a TOML table): {}", doc));
  return Table(doc_, n->as_table(), key_path(key));
}

std::vector<Table> Table::table_array(std::string_view key, std::string_view doc) const {
  const toml::node* n = node(key);
  std::vector<Table> tables;
  if (!n) return tables;
  const auto* arr = n->as_array();
  if (!arr || !arr->is_array_of_tables())
    fail(key, fmt::format("expected an array of tables, written [[{}]]: {}", key_path(key), doc));
  for (std::size_t i = 0; i < arr->size(); ++i)
    tables.emplace_back(doc_, arr->get(i)->as_table(), fmt::format("{}[{}]", key_path(key), i));
  return tables;
}

}  // namespace outburst::scene
