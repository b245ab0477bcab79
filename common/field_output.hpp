#pragma once
// Time series of fields for ParaView: HDF5 data indexed by an XDMF file.
//
// Layout of an output folder:
//   <name>_mesh.h5         static mesh geometry and topology, written once
//   <name>_000042.h5       one file per snapshot (fields, moving point clouds)
//   <name>.xdmf            the index ParaView opens; rewritten after each snapshot
// Every file is written under a temporary name and renamed into place, so a run
// that dies leaves complete snapshots and an index that lists only those. Each
// HDF5 file carries the run's provenance (program, version, scene text, units).

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace outburst::checkpoint {
class Out;
class In;
}  // namespace outburst::checkpoint

namespace outburst::output {

struct RunInfo {
  std::string program;
  std::string version;
  std::string scene_file;
  std::string scene_text;
  std::vector<std::string> overrides;
  // Units of everything written, e.g. "SI: m, s, kg, Pa; P = p^2 in Pa^2".
  std::string units;
};

enum class Center { node, cell };

// The cells of a fixed mesh, with their corners in XDMF's (VTK's) order:
// quadrilaterals counter-clockwise, hexahedra one face counter-clockwise seen
// from the inside, then the opposite face in the same order (Gmsh's order too).
enum class CellShape { quadrilateral, hexahedron };
int corners_of(CellShape shape);

struct Field {
  std::string name;
  Center center;
  // 1 scalar, 3 vector (2D vectors are padded with z = 0), 6 symmetric tensor
  // in XDMF's Tensor6 order xx, xy, xz, yy, yz, zz
  int components;
  std::string unit;
  std::vector<double> values;  // entity-major: values[i * components + c]
};

// What one output time holds: fields per grid, and the positions of point grids.
class Snapshot {
 public:
  explicit Snapshot(double time) : time_(time) {}
  void add(const std::string& grid, Field field);
  // Point clouds (particles) move: their positions are part of every snapshot.
  void set_points(const std::string& grid, std::vector<double> xyz);

  double time() const { return time_; }

 private:
  friend class FieldSeries;
  double time_;
  std::map<std::string, std::vector<Field>> fields_;
  std::map<std::string, std::vector<double>> points_;
};

class FieldSeries {
 public:
  FieldSeries(std::filesystem::path directory, std::string name, RunInfo info);

  // A fixed mesh of one cell shape: xyz holds 3 coordinates per node, cells
  // corners_of(shape) node indices per cell.
  void add_mesh(const std::string& grid, const std::vector<double>& xyz, const std::vector<std::int64_t>& cells,
                CellShape shape);
  // A point cloud whose positions come with each snapshot.
  void add_point_grid(const std::string& grid);

  // Writes the snapshot's file and lists it in the index (or, once
  // list_with_others() was called, holds it until publish() lists it).
  void write(const Snapshot& snapshot);

  std::filesystem::path index_path() const { return directory_ / (name_ + ".xdmf"); }
  std::size_t snapshots_written() const { return written_.size(); }

  // The snapshots listed so far, to and from a checkpoint. load() lists
  // exactly those in the index again and removes later snapshot files (a
  // killed run's, written after its checkpoint), so that the series goes on
  // from the checkpoint's time.
  void save(checkpoint::Out out) const;
  void load(const checkpoint::In& in);

  // Series written at the same output times (a coupled run's seepage and
  // particles): from now on a time is listed in their indexes only by
  // publish(), once every one of them has its snapshot file, so a write that
  // fails midway (a full disk) leaves all indexes listing the same times.
  void list_with_others() { deferred_ = true; }
  friend void publish(const std::vector<FieldSeries*>& series);

 private:
  struct MeshGrid {
    std::size_t nodes = 0, cells = 0;
    CellShape shape = CellShape::quadrilateral;
  };
  struct WrittenField {
    std::string name;
    Center center;
    int components;
  };
  struct WrittenGrid {
    std::size_t points = 0;  // point grids only
    std::vector<WrittenField> fields;
  };
  struct Written {
    double time;
    std::string file;
    std::map<std::string, WrittenGrid> grids;
  };

  std::string index_text() const;

  std::filesystem::path directory_;
  std::string name_;
  RunInfo info_;
  std::map<std::string, MeshGrid> meshes_;
  std::vector<std::string> point_grids_;
  std::vector<Written> written_;
  bool deferred_ = false;
  std::vector<Written> pending_;  // written, not yet listed
};

// Lists the snapshots the series hold in their indexes: every index is
// written under a temporary name before any replaces its predecessor.
void publish(const std::vector<FieldSeries*>& series);

}  // namespace outburst::output
