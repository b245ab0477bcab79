#include "seepage_fe/mesh.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "seepage_fe/q1.hpp"

namespace outburst::seepage {

template <int Dim>
int MeshOf<Dim>::region_index(const std::string& name) const {
  for (std::size_t i = 0; i < region_names.size(); ++i)
    if (region_names[i] == name) return static_cast<int>(i);
  return -1;
}

template <int Dim>
const typename MeshOf<Dim>::Boundary* MeshOf<Dim>::boundary(const std::string& name) const {
  for (const auto& b : boundaries)
    if (b.name == name) return &b;
  return nullptr;
}

template <int Dim>
std::vector<std::string> MeshOf<Dim>::boundary_names() const {
  std::vector<std::string> names;
  for (const auto& b : boundaries) names.push_back(b.name);
  return names;
}

template struct MeshOf<2>;
template struct MeshOf<3>;

namespace {

// Node coordinates along one direction with geometric grading: successive cell
// sizes grow by r = grading^(1/(n-1)), so the last cell is `grading` times the first.
std::vector<double> graded_coordinates(double start, double length, int n, double grading) {
  std::vector<double> x(static_cast<std::size_t>(n) + 1);
  const double r = n > 1 ? std::pow(grading, 1.0 / (n - 1)) : 1.0;
  std::vector<double> widths(static_cast<std::size_t>(n));
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += widths[i] = std::pow(r, i);
  x[0] = start;
  for (int i = 0; i < n; ++i) x[i + 1] = x[i] + length * widths[i] / sum;
  x[n] = start + length;
  return x;
}

// The last region whose box holds the cell centre.
template <int Dim>
int region_holding(const std::vector<RegionBoxOf<Dim>>& regions, const Eigen::Matrix<double, Dim, 1>& centre) {
  int region = -1;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const auto& reg = regions[r];
    if (reg.whole_domain ||
        ((centre.array() >= reg.box_min.array()).all() && (centre.array() <= reg.box_max.array()).all()))
      region = static_cast<int>(r);
  }
  if (region < 0)
    throw std::invalid_argument(fmt::format("the cell centred at ({:g} m) lies in no region's box; give one region "
                                            "without a box to cover the whole mesh, or widen the boxes",
                                            fmt::join(centre.data(), centre.data() + Dim, " m, ")));
  return region;
}

}  // namespace

Mesh make_structured_mesh(const StructuredMeshSpec& spec) {
  const int nx = spec.cells[0], ny = spec.cells[1];
  const auto xs = graded_coordinates(spec.origin.x(), spec.size.x(), nx, spec.grading[0]);
  const auto ys = graded_coordinates(spec.origin.y(), spec.size.y(), ny, spec.grading[1]);
  Mesh mesh;
  const auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) mesh.nodes.emplace_back(xs[i], ys[j]);
  for (const auto& r : spec.regions) mesh.region_names.push_back(r.name);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      mesh.cells.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      const Eigen::Vector2d centre(0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1]));
      const int region = region_holding(spec.regions, centre);
      mesh.cell_region.push_back(region);
    }
  }
  Mesh::Boundary left{"left", {}}, right{"right", {}}, bottom{"bottom", {}}, top{"top", {}};
  for (int j = 0; j < ny; ++j) {
    left.faces.push_back({id(0, j + 1), id(0, j)});
    right.faces.push_back({id(nx, j), id(nx, j + 1)});
  }
  for (int i = 0; i < nx; ++i) {
    bottom.faces.push_back({id(i, 0), id(i + 1, 0)});
    top.faces.push_back({id(i + 1, ny), id(i, ny)});
  }
  mesh.boundaries = {left, right, bottom, top};
  return mesh;
}

namespace {

// Whitespace-separated tokens with the line each came from, for error messages.
class MshReader {
 public:
  MshReader(const std::filesystem::path& file) : file_(file), in_(file) {
    if (!in_) throw std::runtime_error(fmt::format("{}: cannot open the mesh file", file.string()));
    std::error_code error;
    size_ = std::filesystem::file_size(file, error);
    if (error) throw std::runtime_error(fmt::format("{}: cannot read the mesh file's size", file.string()));
  }

  [[noreturn]] void fail(const std::string& what) const { fail_at(line_, what); }
  [[noreturn]] void fail_at(int line, const std::string& what) const {
    throw std::runtime_error(fmt::format("{}:{}: {}", file_.string(), line, what));
  }

  bool next_line(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }

  // The next non-empty line, split into tokens.
  std::vector<std::string> tokens(const char* expected) {
    std::string line;
    do {
      if (!next_line(line)) fail(fmt::format("the file ends early; expected {}", expected));
    } while (line.find_first_not_of(" \t") == std::string::npos);
    std::istringstream s(line);
    std::vector<std::string> t;
    for (std::string w; s >> w;) t.push_back(w);
    return t;
  }

  template <class T = long>
  T integer(const std::string& token, const char* what) const {
    T v = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
    if (ec == std::errc::result_out_of_range)
      fail(fmt::format("{} {} is out of range (at most {})", what, token, std::numeric_limits<T>::max()));
    if (ec != std::errc() || end != token.data() + token.size())
      fail(fmt::format("expected {} (an integer), got '{}'", what, token));
    return v;
  }

  // A count of records that follow, each taking a byte of the file at least:
  // a count the rest of the file cannot hold is refused before anything is
  // allocated for it.
  long count(const std::string& token, const char* what) {
    const long n = integer(token, what);
    if (n < 0) fail(fmt::format("{} is {}; expected a count >= 0", what, n));
    const auto at = in_.tellg();
    const double left = at < 0 ? 0.0 : static_cast<double>(size_) - static_cast<double>(at);
    if (static_cast<double>(n) > left)
      fail(fmt::format("{} is {}, more than the rest of the file ({:.0f} bytes) holds", what, n, left));
    return n;
  }

  double number(const std::string& token, const char* what) const {
    try {
      std::size_t used = 0;
      const double v = std::stod(token, &used);
      if (used == token.size() && std::isfinite(v)) return v;
    } catch (const std::exception&) {
    }
    fail(fmt::format("expected {} (a finite number), got '{}'", what, token));
  }

  void expect_count(const std::vector<std::string>& t, std::size_t n, const char* what) const {
    if (t.size() < n) fail(fmt::format("expected {} ({} values), got {}", what, n, t.size()));
  }

  void expect_end(const char* section) {
    const auto t = tokens(section);
    if (t.empty() || t[0] != section) fail(fmt::format("expected {}", section));
  }

  int line() const { return line_; }

 private:
  std::filesystem::path file_;
  std::ifstream in_;
  std::uintmax_t size_ = 0;
  int line_ = 0;
};

// Plural, as in "surface 3 holds 3-node triangles".
std::string element_names(long type) {
  switch (type) {
    case 1: return "2-node lines";
    case 2: return "3-node triangles";
    case 3: return "4-node quadrangles";
    case 4: return "4-node tetrahedra";
    case 5: return "8-node hexahedra";
    case 6: return "6-node prisms";
    case 7: return "5-node pyramids";
    case 8: return "3-node lines";
    case 9: return "6-node triangles";
    case 10: return "9-node quadrangles";
    case 11: return "10-node tetrahedra";
    case 12: return "27-node hexahedra";
    case 15: return "points";
    case 16: return "8-node quadrangles";
    case 17: return "20-node hexahedra";
    default: return fmt::format("elements of type {}", type);
  }
}

// Gmsh's Q1 element of entity dimension d = 1, 2, 3 (at d - 1: the line,
// the quadrangle, the hexahedron), its node count and how a record of it reads.
constexpr long q1_type[3] = {1, 3, 5};
constexpr int q1_nodes[3] = {2, 4, 8};
constexpr const char* q1_record[3] = {"a line 'tag n1 n2'", "a quadrangle 'tag n1 n2 n3 n4'",
                                      "a hexahedron 'tag n1 ... n8'"};

// One block of $Elements. Whether the file holds hexahedra decides what its
// blocks are (cells or boundaries), so they are judged once all are read.
struct ElementBlock {
  int dim, entity;
  long type;
  long count;
  int line;      // of the block's header
  int physical;  // the entity's physical tag; -1: none
  // The node tags of its elements (q1_nodes[dim - 1] each) and the line of each:
  // kept for Q1 elements of physical entities only, the others are never used.
  std::vector<long> tags;
  std::vector<int> lines;
};

struct GmshNode {
  Eigen::Vector3d x;  // [m]
  int line;           // of its coordinates
};

struct GmshFile {
  std::map<std::pair<int, int>, std::string> physical_names;  // (dim, tag) -> name
  std::unordered_map<long, GmshNode> nodes;                   // by tag
  std::vector<ElementBlock> blocks;
  bool has_hexahedra() const {
    return std::any_of(blocks.begin(), blocks.end(), [](const ElementBlock& b) { return b.dim == 3 && b.count > 0; });
  }
  std::string physical_name(int dim, int tag) const {
    const auto name = physical_names.find({dim, tag});
    return name != physical_names.end() ? name->second : fmt::format("{}", tag);
  }
};

GmshFile parse_gmsh(MshReader& r, double length_scale) {
  GmshFile g;
  std::map<std::pair<int, int>, int> entity_physical;  // (dim, entity) -> physical tag
  bool seen_format = false, seen_nodes = false, seen_elements = false;
  std::string line;
  while (r.next_line(line)) {
    if (line.empty()) continue;
    if (line == "$MeshFormat") {
      const auto t = r.tokens("the MSH version line");
      r.expect_count(t, 3, "the version line 'version file-type data-size'");
      if (t[0] != "4.1")
        r.fail(fmt::format("MSH format {} is not supported; save the mesh as MSH 4.1 "
                           "(gmsh -format msh41, or Mesh.MshFileVersion = 4.1)",
                           t[0]));
      if (t[1] != "0") r.fail("binary MSH is not supported; save as ASCII (Mesh.Binary = 0)");
      r.expect_end("$EndMeshFormat");
      seen_format = true;
    } else if (line == "$PhysicalNames") {
      const long n = r.count(r.tokens("the number of physical names")[0], "the number of names");
      for (long i = 0; i < n; ++i) {
        auto t = r.tokens("a physical name 'dimension tag \"name\"'");
        r.expect_count(t, 3, "a physical name 'dimension tag \"name\"'");
        std::string name = t[2];
        for (std::size_t k = 3; k < t.size(); ++k) name += " " + t[k];
        if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
        g.physical_names[{r.integer<int>(t[0], "a dimension"), r.integer<int>(t[1], "a physical tag")}] = name;
      }
      r.expect_end("$EndPhysicalNames");
    } else if (line == "$Entities") {
      const auto counts = r.tokens("the entity counts");
      r.expect_count(counts, 4, "the entity counts 'points curves surfaces volumes'");
      for (int dim = 0; dim < 4; ++dim) {
        const long n = r.count(counts[dim], "an entity count");
        for (long i = 0; i < n; ++i) {
          const auto t = r.tokens("an entity");
          // Points carry x y z before their physical tags; the others a bounding box.
          const std::size_t at = dim == 0 ? 4 : 7;
          r.expect_count(t, at + 1, "an entity record");
          const int tag = r.integer<int>(t[0], "an entity tag");
          const long physicals = r.integer(t[at], "the number of physical tags");
          if (physicals > 0) {
            r.expect_count(t, at + 2, "the entity's physical tags");
            const int physical = r.integer<int>(t[at + 1], "a physical tag");
            if (physical == std::numeric_limits<int>::min()) r.fail("a physical tag is out of range");
            entity_physical[{dim, tag}] = std::abs(physical);
          }
        }
      }
      r.expect_end("$EndEntities");
    } else if (line == "$Nodes") {
      const auto head = r.tokens("the node block header");
      r.expect_count(head, 4, "'numEntityBlocks numNodes minNodeTag maxNodeTag'");
      const long blocks = r.count(head[0], "the number of node blocks");
      for (long b = 0; b < blocks; ++b) {
        const auto bh = r.tokens("a node block header");
        r.expect_count(bh, 4, "'entityDim entityTag parametric numNodesInBlock'");
        const long n = r.count(bh[3], "the number of nodes in the block");
        if (bh[2] != "0") r.fail("parametric node coordinates are not supported");
        std::vector<long> tags(static_cast<std::size_t>(n));
        for (long i = 0; i < n; ++i) tags[i] = r.integer(r.tokens("a node tag")[0], "a node tag");
        for (long i = 0; i < n; ++i) {
          const auto c = r.tokens("node coordinates 'x y z'");
          r.expect_count(c, 3, "node coordinates 'x y z'");
          const Eigen::Vector3d x =
              Eigen::Vector3d(r.number(c[0], "x"), r.number(c[1], "y"), r.number(c[2], "z")) * length_scale;
          // A tag given twice at one place names one node; at two, the cells
          // would take whichever definition came last.
          const auto [it, added] = g.nodes.try_emplace(tags[i], GmshNode{x, r.line()});
          if (!added && it->second.x != x)
            r.fail(fmt::format("node {} is defined a second time, elsewhere than at line {}: a node tag names one "
                               "point (given twice, it must have the same coordinates)",
                               tags[i], it->second.line));
        }
      }
      r.expect_end("$EndNodes");
      seen_nodes = true;
    } else if (line == "$Elements") {
      const auto head = r.tokens("the element block header");
      r.expect_count(head, 4, "'numEntityBlocks numElements minElementTag maxElementTag'");
      const long blocks = r.count(head[0], "the number of element blocks");
      for (long b = 0; b < blocks; ++b) {
        const auto bh = r.tokens("an element block header");
        r.expect_count(bh, 4, "'entityDim entityTag elementType numElementsInBlock'");
        ElementBlock block{r.integer<int>(bh[0], "an entity dimension"), r.integer<int>(bh[1], "an entity tag"),
                           r.integer(bh[2], "an element type"), r.count(bh[3], "the number of elements in the block"),
                           r.line(), -1, {}, {}};
        if (const auto p = entity_physical.find({block.dim, block.entity}); p != entity_physical.end())
          block.physical = p->second;
        const bool kept =
            block.dim >= 1 && block.dim <= 3 && block.type == q1_type[block.dim - 1] && block.physical >= 0;
        for (long i = 0; i < block.count; ++i) {
          const auto t = r.tokens("an element record");
          if (!kept) continue;
          const int nodes = q1_nodes[block.dim - 1];
          r.expect_count(t, static_cast<std::size_t>(nodes) + 1, q1_record[block.dim - 1]);
          for (int k = 1; k <= nodes; ++k) block.tags.push_back(r.integer(t[k], "a node tag"));
          block.lines.push_back(r.line());
        }
        g.blocks.push_back(std::move(block));
      }
      r.expect_end("$EndElements");
      seen_elements = true;
    }
  }
  if (!seen_format) r.fail("no $MeshFormat section: this is not a Gmsh MSH file");
  if (!seen_nodes || !seen_elements) r.fail("the file has no $Nodes or no $Elements section");
  return g;
}

// Cells are the Q1 elements of dimension Dim, boundaries those of Dim - 1.
template <int Dim>
void check_blocks(const GmshFile& g, const MshReader& r) {
  for (const auto& b : g.blocks) {
    if (b.dim == Dim) {
      if (b.type != q1_type[Dim - 1])
        r.fail_at(b.line, Dim == 2 ? fmt::format("surface {} holds {}; the seepage solver needs 4-node "
                                                 "quadrangles (add 'Recombine Surface{{...}};' to the .geo file)",
                                                 b.entity, element_names(b.type))
                                   : fmt::format("volume {} holds {}; the seepage solver needs 8-node hexahedra "
                                                 "(make the volume and its surfaces transfinite and recombine them, "
                                                 "or extrude a recombined surface with Layers{{...}}; Recombine;)",
                                                 b.entity, element_names(b.type)));
      if (b.physical < 0)
        r.fail_at(b.line, fmt::format("{} {} belongs to no physical group, so its cells would have no region; add "
                                      "it to a 'Physical {}'",
                                      Dim == 2 ? "surface" : "volume", b.entity, Dim == 2 ? "Surface" : "Volume"));
    } else if (b.dim == Dim - 1 && b.physical >= 0 && b.count > 0 && b.type != q1_type[Dim - 2]) {
      r.fail_at(b.line, Dim == 2 ? fmt::format("curve {} holds {}; only 2-node lines are supported", b.entity,
                                               element_names(b.type))
                                 : fmt::format("surface {} of physical surface \"{}\" holds {}; the boundaries of a "
                                               "hexahedral mesh need 4-node quadrangles (recombine the surface)",
                                               b.entity, g.physical_name(2, b.physical), element_names(b.type)));
    }
  }
}

// A counter-clockwise quadrilateral's edges, each by its corners in the order
// that faces out of the cell, as q1::hex_face does a hexahedron's faces.
constexpr int quad_edge[4][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};

template <int Dim>
constexpr const auto& cell_faces() {
  if constexpr (Dim == 2)
    return quad_edge;
  else
    return q1::hex_face;
}

// A mesh's boundary elements (lines of a plane mesh, quadrangles of a volume
// one), each replaced by the face of the cell it lies on as that cell sees it,
// facing out (a face inside the mesh: out of the first cell listed that holds
// it). An element on no cell's face is refused: its condition would apply
// between nodes no face joins, inside the mesh.
template <int Dim>
void add_boundaries(MeshOf<Dim>& mesh, const GmshFile& g, const std::unordered_map<long, int>& index,
                    const std::filesystem::path& file) {
  using Face = typename MeshOf<Dim>::Face;
  constexpr int corners = MeshOf<Dim>::face_corners;
  // The cells around each node.
  std::vector<int> start(mesh.num_nodes() + 1, 0), around;
  for (const auto& cell : mesh.cells)
    for (int node : cell) ++start[node + 1];
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) start[i + 1] += start[i];
  around.resize(static_cast<std::size_t>(start.back()));
  std::vector<int> filled(start.begin(), start.end() - 1);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    for (int node : mesh.cells[c]) around[filled[node]++] = static_cast<int>(c);

  const auto outward_face = [&](Face nodes) -> std::optional<Face> {
    std::sort(nodes.begin(), nodes.end());
    for (int k = start[nodes[0]]; k < start[nodes[0] + 1]; ++k) {
      const auto& cell = mesh.cells[around[k]];
      for (const auto& local : cell_faces<Dim>()) {
        Face face;
        for (int a = 0; a < corners; ++a) face[a] = cell[local[a]];
        auto sorted = face;
        std::sort(sorted.begin(), sorted.end());
        if (sorted == nodes) return face;
      }
    }
    return std::nullopt;
  };
  const char* element = Dim == 2 ? "line" : "quadrangle";
  const char* cell_word = Dim == 2 ? "quadrangle" : "hexahedron";
  std::map<int, std::size_t> boundary_of_physical;
  for (const auto& b : g.blocks) {
    if (b.dim != Dim - 1 || b.tags.empty()) continue;
    const std::string physical = g.physical_name(Dim - 1, b.physical);
    for (std::size_t e = 0; e < b.lines.size(); ++e) {
      Face nodes{};
      for (int a = 0; a < corners; ++a) {
        const long tag = b.tags[corners * e + a];
        const auto found = index.find(tag);
        if (found == index.end())
          throw std::runtime_error(fmt::format("{}:{}: this boundary {} uses node {}, which no {} uses", file.string(),
                                               b.lines[e], element, tag, cell_word));
        nodes[a] = found->second;
      }
      const auto face = outward_face(nodes);
      if (!face)
        throw std::runtime_error(fmt::format(
            "{}:{}: this {} of physical {} \"{}\" is not {} of any {}: a boundary must lie on the cells' {}",
            file.string(), b.lines[e], element, Dim == 2 ? "curve" : "surface", physical,
            Dim == 2 ? "an edge" : "a face", cell_word, Dim == 2 ? "edges" : "faces"));
      const auto [it, added] = boundary_of_physical.try_emplace(b.physical, mesh.boundaries.size());
      if (added) mesh.boundaries.push_back({physical, {}});
      mesh.boundaries[it->second].faces.push_back(*face);
    }
  }
}

// The cells, regions and boundaries of a plane (Dim = 2) or volume mesh.
template <int Dim>
MeshOf<Dim> build_mesh(const GmshFile& g, const MshReader& r, const std::filesystem::path& file) {
  check_blocks<Dim>(g, r);
  constexpr int N = MeshOf<Dim>::cell_corners;
  const char* cell_word = Dim == 2 ? "quadrangle" : "hexahedron";
  const bool has_cells =
      std::any_of(g.blocks.begin(), g.blocks.end(), [](const ElementBlock& b) { return b.dim == Dim && b.count > 0; });
  if (!has_cells) r.fail("the mesh has no quadrangles in any physical surface");

  // Keep only nodes that cells use (Gmsh also stores geometry points), numbered
  // in order of first use.
  MeshOf<Dim> mesh;
  std::unordered_map<long, int> index;
  std::map<int, int> region_of_physical;
  const auto node_index = [&](long tag, int line) {
    const auto found = index.find(tag);
    if (found != index.end()) return found->second;
    const auto xyz = g.nodes.find(tag);
    if (xyz == g.nodes.end())
      throw std::runtime_error(
          fmt::format("{}:{}: the element uses node {}, which $Nodes does not define", file.string(), line, tag));
    const int i = static_cast<int>(mesh.nodes.size());
    mesh.nodes.push_back(xyz->second.x.template head<Dim>());
    index[tag] = i;
    return i;
  };
  // A cell given twice would count its volume, storage and conductivity twice.
  std::map<std::array<long, N>, int> line_of_cell;
  for (const auto& b : g.blocks) {
    if (b.dim != Dim) continue;
    for (std::size_t e = 0; e < b.lines.size(); ++e) {
      std::array<long, N> nodes;
      std::copy_n(b.tags.begin() + static_cast<std::ptrdiff_t>(N * e), N, nodes.begin());
      std::sort(nodes.begin(), nodes.end());
      if (const auto [it, added] = line_of_cell.try_emplace(nodes, b.lines[e]); !added)
        throw std::runtime_error(fmt::format("{}:{}: this {} has the nodes of the one at line {}: a cell given twice",
                                             file.string(), b.lines[e], cell_word, it->second));
    }
  }
  for (const auto& b : g.blocks) {
    if (b.dim != Dim) continue;
    for (std::size_t e = 0; e < b.lines.size(); ++e) {
      typename MeshOf<Dim>::Cell cell{};
      for (int k = 0; k < N; ++k) cell[k] = node_index(b.tags[N * e + k], b.lines[e]);
      const auto [it, added] =
          region_of_physical.try_emplace(b.physical, static_cast<int>(mesh.region_names.size()));
      if (added) mesh.region_names.push_back(g.physical_name(Dim, b.physical));
      const auto& p = mesh.nodes;
      if constexpr (Dim == 2) {
        // Gmsh orients quads by the surface normal; we need counter-clockwise in x-y.
        const double twice_area = (p[cell[2]] - p[cell[0]]).x() * (p[cell[3]] - p[cell[1]]).y() -
                                  (p[cell[2]] - p[cell[0]]).y() * (p[cell[3]] - p[cell[1]]).x();
        if (twice_area < 0) std::swap(cell[1], cell[3]);
      } else {
        // Gmsh's hexahedra have q1::hex_corner's order, but a mirrored one (its
        // volume's orientation) maps the reference cube inside out: exchanging
        // xi and eta turns it right-handed. A twisted or collapsed one stays
        // so, for check_mesh to refuse.
        q1::Corners3 x;
        for (int a = 0; a < 8; ++a) x[a] = p[cell[a]];
        if (q1::evaluate(x, Eigen::Vector3d::Zero()).det_j < 0) {
          std::swap(cell[1], cell[3]);
          std::swap(cell[5], cell[7]);
        }
      }
      mesh.cells.push_back(cell);
      mesh.cell_region.push_back(it->second);
    }
  }
  // Before the boundaries: their faces are looked up on the cells.
  check_mesh(mesh, file.string());
  add_boundaries(mesh, g, index, file);
  return mesh;
}

}  // namespace

std::variant<Mesh, Mesh3> read_gmsh_mesh(const std::filesystem::path& file, double length_scale) {
  MshReader r(file);
  const GmshFile g = parse_gmsh(r, length_scale);
  if (g.has_hexahedra()) return build_mesh<3>(g, r, file);
  return build_mesh<2>(g, r, file);
}

Mesh read_gmsh(const std::filesystem::path& file, double length_scale) {
  auto mesh = read_gmsh_mesh(file, length_scale);
  if (!std::holds_alternative<Mesh>(mesh))
    throw std::runtime_error(
        fmt::format("{}: holds hexahedra, a volume mesh; a plane mesh (quadrangles) is needed here", file.string()));
  return std::get<Mesh>(std::move(mesh));
}

Mesh3 read_gmsh3(const std::filesystem::path& file, double length_scale) {
  auto mesh = read_gmsh_mesh(file, length_scale);
  if (!std::holds_alternative<Mesh3>(mesh))
    throw std::runtime_error(
        fmt::format("{}: holds no hexahedra, a plane mesh; a volume mesh is needed here", file.string()));
  return std::get<Mesh3>(std::move(mesh));
}

void check_mesh(const Mesh& mesh, const std::string& source) {
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const auto& cell = mesh.cells[c];
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d a = mesh.nodes[cell[(k + 1) % 4]] - mesh.nodes[cell[k]];
      const Eigen::Vector2d b = mesh.nodes[cell[(k + 3) % 4]] - mesh.nodes[cell[k]];
      const double cross = a.x() * b.y() - a.y() * b.x();
      if (!(cross > 0))
        throw std::runtime_error(fmt::format(
            "{}: cell {} (nodes at ({:g}, {:g}), ({:g}, {:g}), ({:g}, {:g}), ({:g}, {:g})) is "
            "degenerate or not convex at its corner {}",
            source, c, mesh.nodes[cell[0]].x(), mesh.nodes[cell[0]].y(), mesh.nodes[cell[1]].x(),
            mesh.nodes[cell[1]].y(), mesh.nodes[cell[2]].x(), mesh.nodes[cell[2]].y(),
            mesh.nodes[cell[3]].x(), mesh.nodes[cell[3]].y(), k));
    }
  }
}

Mesh3 make_box_mesh(const BoxMeshSpec& spec) {
  for (int d = 0; d < 3; ++d)
    if (spec.cells[d] < 1 || !(spec.size[d] > 0))
      throw std::invalid_argument(fmt::format("a box mesh needs a positive size and at least one cell along each "
                                              "axis; axis {} has {} cells over {:g} m",
                                              d, spec.cells[d], spec.size[d]));
  const int nx = spec.cells[0], ny = spec.cells[1], nz = spec.cells[2];
  std::array<std::vector<double>, 3> at;
  for (int d = 0; d < 3; ++d) at[d] = graded_coordinates(spec.origin[d], spec.size[d], spec.cells[d], spec.grading[d]);
  Mesh3 mesh;
  const auto id = [nx, ny](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) mesh.nodes.emplace_back(at[0][i], at[1][j], at[2][k]);
  for (const auto& r : spec.regions) mesh.region_names.push_back(r.name);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        mesh.cells.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                              id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
        const Eigen::Vector3d centre(0.5 * (at[0][i] + at[0][i + 1]), 0.5 * (at[1][j] + at[1][j + 1]),
                                     0.5 * (at[2][k] + at[2][k + 1]));
        mesh.cell_region.push_back(region_holding(spec.regions, centre));
      }
  Mesh3::Boundary left{"left", {}}, right{"right", {}}, bottom{"bottom", {}}, top{"top", {}}, back{"back", {}},
      front{"front", {}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      left.faces.push_back({id(0, j, k), id(0, j, k + 1), id(0, j + 1, k + 1), id(0, j + 1, k)});
      right.faces.push_back({id(nx, j, k), id(nx, j + 1, k), id(nx, j + 1, k + 1), id(nx, j, k + 1)});
    }
  for (int k = 0; k < nz; ++k)
    for (int i = 0; i < nx; ++i) {
      bottom.faces.push_back({id(i, 0, k), id(i + 1, 0, k), id(i + 1, 0, k + 1), id(i, 0, k + 1)});
      top.faces.push_back({id(i, ny, k), id(i, ny, k + 1), id(i + 1, ny, k + 1), id(i + 1, ny, k)});
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      back.faces.push_back({id(i, j, 0), id(i, j + 1, 0), id(i + 1, j + 1, 0), id(i + 1, j, 0)});
      front.faces.push_back({id(i, j, nz), id(i + 1, j, nz), id(i + 1, j + 1, nz), id(i, j + 1, nz)});
    }
  mesh.boundaries = {left, right, bottom, top, back, front};
  check_mesh(mesh, "the generated box");
  return mesh;
}

void check_mesh(const Mesh3& mesh, const std::string& source) {
  // A positive Jacobian at the corners and at the Gauss points the integrals
  // use: not a proof that a trilinear map is invertible (a badly twisted
  // hexahedron can pass), but it refuses inverted and collapsed cells, and
  // every point the solver evaluates has a positive volume.
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const auto x = mesh.corners(c);
    const auto refuse = [&](const std::string& where) {
      throw std::runtime_error(fmt::format(
          "{}: hexahedron {} (first corner at ({:g}, {:g}, {:g})) is degenerate or inverted at {}", source, c,
          x[0].x(), x[0].y(), x[0].z(), where));
    };
    for (int a = 0; a < 8; ++a) {
      const Eigen::Vector3d r(q1::hex_corner[a][0], q1::hex_corner[a][1], q1::hex_corner[a][2]);
      if (!(q1::evaluate(x, r).det_j > 0)) refuse(fmt::format("its corner {}", a));
    }
    for (const auto& g : q1::gauss2_points3())
      if (!(q1::evaluate(x, g).det_j > 0)) refuse("a Gauss point");
  }
}

}  // namespace outburst::seepage
