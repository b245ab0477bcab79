#include "common/field_output.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "common/atomic_file.hpp"
#include "common/checkpoint.hpp"
#include "common/hdf5_file.hpp"

namespace outburst::output {

namespace {

// The length of the UTF-8 sequence at s[i] of a character XML 1.0 may hold
// (U+0020 and up but DEL, no surrogates, not U+FFFE or U+FFFF), or 0.
std::size_t xml_character(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
  const auto continues = [&](std::size_t k, unsigned lo = 0x80, unsigned hi = 0xBF) {
    return byte(k) >= lo && byte(k) <= hi;
  };
  const unsigned b = byte(i);
  if (b >= 0x20 && b < 0x7F) return 1;
  if (b >= 0xC2 && b <= 0xDF) return continues(i + 1) ? 2 : 0;
  if (b >= 0xE0 && b <= 0xEF) {
    const bool ok = continues(i + 1, b == 0xE0 ? 0xA0 : 0x80, b == 0xED ? 0x9F : 0xBF) && continues(i + 2);
    const bool not_a_character = b == 0xEF && byte(i + 1) == 0xBF && byte(i + 2) >= 0xBE;
    return ok && !not_a_character ? 3 : 0;
  }
  if (b >= 0xF0 && b <= 0xF4)
    return continues(i + 1, b == 0xF0 ? 0x90 : 0x80, b == 0xF4 ? 0x8F : 0xBF) && continues(i + 2) &&
                   continues(i + 3)
               ? 4
               : 0;
  return 0;
}

// Text for an XML attribute value: markup escaped, and each byte XML cannot
// hold (control characters, bytes that are not UTF-8, as a path may have) and
// '%' percent-encoded ("%FF"), so the text reads back, byte for byte, by
// decoding what ParaView shows.
std::string xml_escape(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t length = s[i] == '%' ? 0 : xml_character(s, i);
    if (length == 0) {
      out += fmt::format("%{:02X}", static_cast<unsigned char>(s[i++]));
      continue;
    }
    switch (s[i]) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out.append(s, i, length);
    }
    i += length;
  }
  return out;
}

void stamp_provenance(hdf5::H5Writer& w, const RunInfo& info) {
  w.attribute("/", "program", info.program);
  w.attribute("/", "version", info.version);
  w.attribute("/", "scene_file", info.scene_file);
  w.attribute("/", "scene_text", info.scene_text);
  std::string overrides;
  for (const auto& o : info.overrides) overrides += o + "\n";
  w.attribute("/", "scene_overrides", overrides);
  w.attribute("/", "units", info.units);
}

std::string data_item(const std::string& file, const std::string& path, std::size_t rows,
                      int columns, bool integer) {
  const std::string dims =
      columns == 1 ? fmt::format("{}", rows) : fmt::format("{} {}", rows, columns);
  return fmt::format(
      R"(<DataItem Dimensions="{}" NumberType="{}" Precision="8" Format="HDF">{}:{}</DataItem>)",
      dims, integer ? "Int" : "Float", file, path);
}

}  // namespace

void Snapshot::add(const std::string& grid, Field field) {
  fields_[grid].push_back(std::move(field));
}

void Snapshot::set_points(const std::string& grid, std::vector<double> xyz) {
  points_[grid] = std::move(xyz);
}

FieldSeries::FieldSeries(std::filesystem::path directory, std::string name, RunInfo info)
    : directory_(std::move(directory)), name_(std::move(name)), info_(std::move(info)) {
  std::filesystem::create_directories(directory_);
}

int corners_of(CellShape shape) { return shape == CellShape::quadrilateral ? 4 : 8; }

void FieldSeries::add_mesh(const std::string& grid, const std::vector<double>& xyz,
                           const std::vector<std::int64_t>& cells, CellShape shape) {
  const std::size_t corners = static_cast<std::size_t>(corners_of(shape));
  hdf5::H5Writer w(directory_ / (name_ + "_" + grid + ".h5"));
  w.write("/nodes", xyz.data(), {xyz.size() / 3, 3}, "m");
  w.write("/cells", cells.data(), {cells.size() / corners, corners});
  stamp_provenance(w, info_);
  w.commit();
  meshes_[grid] = {xyz.size() / 3, cells.size() / corners, shape};
}

void FieldSeries::add_point_grid(const std::string& grid) { point_grids_.push_back(grid); }

void FieldSeries::write(const Snapshot& snapshot) {
  const std::string file = fmt::format("{}_{:06d}.h5", name_, written_.size() + pending_.size());
  hdf5::H5Writer w(directory_ / file);
  stamp_provenance(w, info_);
  w.attribute("/", "time", snapshot.time());
  Written record{snapshot.time(), file, {}};
  for (const auto& [grid, xyz] : snapshot.points_) {
    const std::size_t n = xyz.size() / 3;
    std::vector<std::int64_t> connectivity(n);
    for (std::size_t i = 0; i < n; ++i) connectivity[i] = static_cast<std::int64_t>(i);
    w.write("/" + grid + "/points", xyz.data(), {n, 3}, "m");
    // Xdmf3 readers show nothing for a Polyvertex without explicit connectivity.
    w.write("/" + grid + "/connectivity", connectivity.data(), {n});
    record.grids[grid].points = n;
  }
  for (const auto& [grid, fields] : snapshot.fields_) {
    for (const auto& f : fields) {
      const std::size_t rows = f.values.size() / static_cast<std::size_t>(f.components);
      if (f.components == 1)
        w.write("/" + grid + "/" + f.name, f.values.data(), {rows}, f.unit);
      else
        w.write("/" + grid + "/" + f.name, f.values.data(),
                {rows, static_cast<std::size_t>(f.components)}, f.unit);
      record.grids[grid].fields.push_back({f.name, f.center, f.components});
    }
  }
  w.commit();
  if (deferred_) {
    pending_.push_back(std::move(record));
    return;
  }
  written_.push_back(std::move(record));
  write_file_atomically(index_path(), index_text());
}

void publish(const std::vector<FieldSeries*>& series) {
  for (auto* s : series) {
    s->written_.insert(s->written_.end(), s->pending_.begin(), s->pending_.end());
    s->pending_.clear();
  }
  std::vector<std::filesystem::path> temps;
  try {
    for (const auto* s : series) temps.push_back(write_beside(s->index_path(), s->index_text()));
  } catch (...) {
    std::error_code ignored;
    for (const auto& t : temps) std::filesystem::remove(t, ignored);
    throw;
  }
  for (std::size_t k = 0; k < series.size(); ++k) move_into_place(temps[k], series[k]->index_path());
}

// One line per snapshot, grid and field, tab-separated:
//   S <time> <file>, G <grid> <points>, F <field> <node|cell> <components>
void FieldSeries::save(checkpoint::Out out) const {
  if (!pending_.empty()) throw std::logic_error("a checkpoint with snapshots written but not listed");
  std::string text;
  for (const auto& w : written_) {
    text += fmt::format("S\t{:.17g}\t{}\n", w.time, w.file);
    for (const auto& [grid, data] : w.grids) {
      text += fmt::format("G\t{}\t{}\n", grid, data.points);
      for (const auto& f : data.fields)
        text += fmt::format("F\t{}\t{}\t{}\n", f.name, f.center == Center::node ? "node" : "cell", f.components);
    }
  }
  out.text("snapshots", text);
}

void FieldSeries::load(const checkpoint::In& in) {
  written_.clear();
  pending_.clear();
  const std::string text = in.text("snapshots");
  WrittenGrid* grid = nullptr;
  for (std::size_t start = 0, end; (end = text.find('\n', start)) != std::string::npos; start = end + 1) {
    std::vector<std::string> parts;
    for (std::size_t a = start, b; a <= end; a = b + 1) {
      b = std::min(text.find('\t', a), end);
      parts.push_back(text.substr(a, b - a));
    }
    const std::string& kind = parts[0];
    bool read = true;
    try {
      if (kind == "S" && parts.size() == 3) {
        written_.push_back({std::stod(parts[1]), parts[2], {}});
        grid = nullptr;
      } else if (kind == "G" && parts.size() == 3 && !written_.empty()) {
        grid = &written_.back().grids[parts[1]];
        grid->points = std::stoul(parts[2]);
      } else if (kind == "F" && parts.size() == 4 && grid) {
        grid->fields.push_back({parts[1], parts[2] == "node" ? Center::node : Center::cell, std::stoi(parts[3])});
      } else {
        read = false;
      }
    } catch (const std::logic_error&) {  // std::stod and kin: not a number, or out of range
      read = false;
    }
    if (!read) in.fail("snapshots", fmt::format("cannot read the line '{}'", text.substr(start, end - start)));
  }
  for (std::size_t k = written_.size();; ++k) {
    const auto later = directory_ / fmt::format("{}_{:06d}.h5", name_, k);
    std::error_code error;
    if (!std::filesystem::remove(later, error)) break;
  }
  write_file_atomically(index_path(), index_text());
}

std::string FieldSeries::index_text() const {
  std::string x;
  x += "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n";
  x += fmt::format("<Information Name=\"program\" Value=\"{} {}\"/>\n", xml_escape(info_.program),
                   xml_escape(info_.version));
  x += fmt::format("<Information Name=\"scene\" Value=\"{}\"/>\n", xml_escape(info_.scene_file));
  x += fmt::format("<Information Name=\"units\" Value=\"{}\"/>\n", xml_escape(info_.units));
  x += fmt::format("<Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
                   xml_escape(name_));
  for (const auto& snap : written_) {
    const bool several = snap.grids.size() > 1;
    if (several)
      x += fmt::format(
          "<Grid Name=\"t{:g}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
          "<Time Value=\"{:.17g}\"/>\n",
          snap.time, snap.time);
    for (const auto& [grid, data] : snap.grids) {
      x += fmt::format("<Grid Name=\"{}\" GridType=\"Uniform\">\n", xml_escape(grid));
      if (!several) x += fmt::format("<Time Value=\"{:.17g}\"/>\n", snap.time);
      std::size_t nodes = 0, cells = 0;
      if (const auto mesh = meshes_.find(grid); mesh != meshes_.end()) {
        const std::string mesh_file = name_ + "_" + grid + ".h5";
        nodes = mesh->second.nodes;
        cells = mesh->second.cells;
        const CellShape shape = mesh->second.shape;
        x += fmt::format("<Topology TopologyType=\"{}\" NumberOfElements=\"{}\">\n{}\n"
                         "</Topology>\n",
                         shape == CellShape::quadrilateral ? "Quadrilateral" : "Hexahedron", cells,
                         data_item(mesh_file, "/cells", cells, corners_of(shape), true));
        x += fmt::format("<Geometry GeometryType=\"XYZ\">\n{}\n</Geometry>\n",
                         data_item(mesh_file, "/nodes", nodes, 3, false));
      } else {
        nodes = cells = data.points;
        x += fmt::format(
            "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" "
            "NodesPerElement=\"1\">\n{}\n</Topology>\n",
            cells, data_item(snap.file, "/" + grid + "/connectivity", cells, 1, true));
        x += fmt::format("<Geometry GeometryType=\"XYZ\">\n{}\n</Geometry>\n",
                         data_item(snap.file, "/" + grid + "/points", nodes, 3, false));
      }
      for (const auto& f : data.fields) {
        const std::size_t rows = f.center == Center::node ? nodes : cells;
        x += fmt::format(
            "<Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{}\">\n{}\n</Attribute>\n",
            xml_escape(f.name), f.components == 1 ? "Scalar" : f.components == 6 ? "Tensor6" : "Vector",
            f.center == Center::node ? "Node" : "Cell",
            data_item(snap.file, "/" + grid + "/" + f.name, rows, f.components, false));
      }
      x += "</Grid>\n";
    }
    if (several) x += "</Grid>\n";
  }
  x += "</Grid>\n</Domain>\n</Xdmf>\n";
  return x;
}

}  // namespace outburst::output
