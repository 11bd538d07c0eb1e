/* Per-particle records of long suspension runs, and the ParaView files of the particles: plain C++,
   no LIGGGHTS, no MPI (fix fdm/output gathers the particles and calls these on rank 0; docs/dem.md,
   "fix fdm/output"; the Python reader is scripts/fdmsubgrid/output.py, read_particle_records).

   The records file (binary, native byte order, declared in the header):

     bytes 0..7     magic "FDMPREC\n"
     bytes 8..11    uint32 little-endian: L, the length of the JSON text that follows
     bytes 12..     the JSON text (format, version, particles N, record_bytes, block_bytes,
                    header_bytes, particle_fields: the numpy dtype of one particle record as
                    [[name, type, [count]], ...], and the writer's metadata), padded with spaces and
                    one final new line so that the header is a multiple of 64 bytes
     then blocks, one per record step, each block_bytes long:
                    int64 step, float64 time, N particle records (ordered by tag), int64 end marker
                    = -1 - step (a block is complete when its marker matches its step: a block cut
                    short, or of zeros after a machine crash, is not)

   Every block is written with one fwrite and flushed: a run killed at any moment leaves every
   block written before, and at most one partial block at the end, which readers drop. */
#ifndef FDM_PARTICLE_RECORDS_H
#define FDM_PARTICLE_RECORDS_H

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdm {
namespace records {

// One field of a particle record: name, 'i' (int32), 'l' (int64) or 'f' (float64), components.
struct Field {
  std::string name;
  char kind;
  int count;
  int bytes() const { return (kind == 'i' ? 4 : 8) * count; }
};

struct Error : std::runtime_error {
  explicit Error(const std::string &what) : std::runtime_error(what) {}
};

// The layout of a particle record and of a block of N records.
class Layout {
 public:
  Layout() : particles_(0), recordBytes_(0) {}
  Layout(const std::vector<Field> &fields, long particles);
  const std::vector<Field> &fields() const { return fields_; }
  long particles() const { return particles_; }
  size_t recordBytes() const { return recordBytes_; }
  size_t blockBytes() const { return 16 + size_t(particles_) * recordBytes_ + 8; }
  // byte offset of a field in a particle record; Error if there is no such field
  size_t offset(const std::string &name) const;
  bool has(const std::string &name) const;
  // the numpy description of a record: [["tag", "<i8"], ["x", "<f8", [3]], ...]
  std::string numpyFields() const;

 private:
  std::vector<Field> fields_;
  long particles_;
  size_t recordBytes_;
};

// The whole header (magic, length, JSON padded) for a layout and the writer's metadata, a JSON
// object's members without braces (e.g. "\"dt\": 0.01, \"every\": 10"), may be empty.
std::string header(const Layout &layout, const std::string &metadata);

// Appends blocks to a records file.
class Writer {
 public:
  // Creates (truncates) path and writes the header; with append, an existing file with the same
  // layout keeps its complete blocks of steps <= keepUpToStep and is continued (a resumed run;
  // Error if the layout differs); a file that does not exist is created.
  Writer(const std::string &path, const Layout &layout, const std::string &metadata, bool append = false,
         int64_t keepUpToStep = 0);
  ~Writer();
  Writer(const Writer &) = delete;
  Writer &operator=(const Writer &) = delete;
  // One block: records holds N records of layout.recordBytes() each, ordered by tag. Written
  // with one fwrite and flushed; Error (naming the file and the system's reason) if that fails.
  void write(int64_t step, double time, const char *records);
  const std::string &path() const { return path_; }
  long blocksKept() const { return kept_; }     // blocks of a previous run kept by append
  long blocksWritten() const { return written_; }
  size_t headerBytes() const { return headerBytes_; }

 private:
  std::string path_;
  Layout layout_;
  FILE *file_;
  size_t headerBytes_;
  long kept_, written_;
  std::vector<char> block_;
};

// What a records file holds (tests, append): the header JSON, the layout, and the complete blocks.
struct Contents {
  std::string json;
  Layout layout;
  size_t headerBytes = 0;
  std::vector<int64_t> steps;
  std::vector<double> times;
  std::vector<char> records;    // blocks x N x recordBytes, the particle records of the complete blocks
  size_t droppedBytes = 0;      // bytes after the last complete block (a partial block)
  double value(size_t block, long particle, const std::string &field, int component = 0) const;
  int64_t integer(size_t block, long particle, const std::string &field, int component = 0) const;
};
// Reads the header and every complete block; a trailing partial block (or one whose end marker
// does not match) ends the data and is counted in droppedBytes. Error if the file is no records file.
Contents read(const std::string &path);

}  // namespace records

// ParaView output of the particles: VTK XML PolyData (.vtp) with one vertex per particle and point
// arrays, binary appended raw (little or big endian as the machine), and the .pvd series file.
namespace vtk {

struct Array {
  std::string name;
  int components;              // 1, 3 (vectors) or 6 (symmetric tensors, VTK order xx yy zz xy yz xz)
  std::vector<double> values;  // n x components
};

// Writes path (via a temporary file renamed into place: a reader never sees half a file).
void writeParticles(const std::string &path, const std::vector<double> &points, const std::vector<Array> &arrays);

// The .pvd collection of the particle files: every add rewrites it (temporary file + rename).
class Series {
 public:
  explicit Series(const std::string &path) : path_(path) {}
  // Continues an existing series: keeps its entries with time <= keepUpToTime (a resumed run).
  void load(double keepUpToTime);
  void add(double time, const std::string &file);   // file relative to the .pvd's folder
  size_t size() const { return entries_.size(); }

 private:
  void write() const;
  std::string path_;
  std::vector<std::pair<double, std::string>> entries_;
};

}  // namespace vtk
}  // namespace fdm

#endif
