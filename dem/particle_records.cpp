// Per-particle records and the ParaView particle files (particle_records.h; docs/dem.md, fix fdm/output).
#include "particle_records.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/types.h>
#include <unistd.h>

namespace fdm {
namespace records {

namespace {

const char magic[8] = {'F', 'D', 'M', 'P', 'R', 'E', 'C', '\n'};

bool littleEndian()
{
  const uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

std::string systemReason() { return std::strerror(errno); }

std::string numberText(double v)
{
  char s[40];
  std::snprintf(s, sizeof s, "%.17g", v);
  return s;
}

// the integer value of "key": in a flat JSON text (the writer's own header)
long long jsonInteger(const std::string &json, const std::string &key)
{
  const std::string quoted = "\"" + key + "\":";
  const size_t at = json.find(quoted);
  if (at == std::string::npos) throw Error("records header has no " + key);
  return std::atoll(json.c_str() + at + quoted.size());
}

}  // namespace

Layout::Layout(const std::vector<Field> &fields, long particles) : fields_(fields), particles_(particles), recordBytes_(0)
{
  if (particles <= 0) throw Error("records: the number of particles must be positive");
  for (const Field &f : fields) {
    if (f.kind != 'i' && f.kind != 'l' && f.kind != 'f') throw Error("records: field " + f.name + " has an unknown kind");
    if (f.count < 1) throw Error("records: field " + f.name + " has no component");
    recordBytes_ += size_t(f.bytes());
  }
}

size_t Layout::offset(const std::string &name) const
{
  size_t at = 0;
  for (const Field &f : fields_) {
    if (f.name == name) return at;
    at += size_t(f.bytes());
  }
  throw Error("records: no field " + name);
}

bool Layout::has(const std::string &name) const
{
  for (const Field &f : fields_)
    if (f.name == name) return true;
  return false;
}

std::string Layout::numpyFields() const
{
  const char order = littleEndian() ? '<' : '>';
  std::string s = "[";
  for (size_t k = 0; k < fields_.size(); ++k) {
    const Field &f = fields_[k];
    s += std::string(k ? ", " : "") + "[\"" + f.name + "\", \"" + order + (f.kind == 'f' ? "f8" : f.kind == 'l' ? "i8" : "i4") + "\"";
    if (f.count > 1) s += ", [" + std::to_string(f.count) + "]";
    s += "]";
  }
  return s + "]";
}

std::string header(const Layout &layout, const std::string &metadata)
{
  // the header's size depends on its own text (header_bytes): written with a fixed-width number
  std::string json = "{\"format\": \"fdm particle records\", \"version\": 1, \"byte_order\": \"" +
                     std::string(littleEndian() ? "little" : "big") + "\", \"particles\": " +
                     std::to_string(layout.particles()) + ", \"record_bytes\": " + std::to_string(layout.recordBytes()) +
                     ", \"block_bytes\": " + std::to_string(layout.blockBytes()) +
                     ", \"header_bytes\": HEADERBYTES, \"block\": \"int64 step, float64 time, particles x record, int64 end = -1 - step\""
                     ", \"particle_fields\": " + layout.numpyFields() + (metadata.empty() ? "" : ", " + metadata) + "}";
  const size_t slot = json.find("HEADERBYTES");
  json.replace(slot, 11, std::string(11, ' '));
  size_t total = 12 + json.size() + 1;
  total = (total + 63) / 64 * 64;
  char number[12];
  std::snprintf(number, sizeof number, "%-11zu", total);
  json.replace(slot, 11, number);
  json += std::string(total - 12 - json.size() - 1, ' ') + "\n";
  const uint32_t length = uint32_t(json.size());
  std::string out(magic, 8);
  for (int b = 0; b < 4; ++b) out += char((length >> (8 * b)) & 0xff);
  return out + json;
}

Writer::Writer(const std::string &path, const Layout &layout, const std::string &metadata, bool append,
               int64_t keepUpToStep) :
  path_(path), layout_(layout), file_(nullptr), headerBytes_(0), kept_(0), written_(0)
{
  const std::string head = header(layout, metadata);
  headerBytes_ = head.size();
  block_.resize(layout.blockBytes());
  if (append) {
    FILE *exists = std::fopen(path.c_str(), "rb");
    if (exists) {
      std::fclose(exists);
      const Contents old = read(path);
      if (old.layout.numpyFields() != layout.numpyFields() || old.layout.particles() != layout.particles())
        throw Error("records file " + path + " holds " + std::to_string(old.layout.particles()) +
                    " particles with the fields " + old.layout.numpyFields() + ", this run writes " +
                    std::to_string(layout.particles()) + " with " + layout.numpyFields() +
                    ": cannot append (write to a new file)");
      size_t keep = 0;
      while (keep < old.steps.size() && old.steps[keep] <= keepUpToStep) ++keep;
      kept_ = long(keep);
      const off_t size = off_t(old.headerBytes + keep * layout.blockBytes());
      if (::truncate(path.c_str(), size) != 0)
        throw Error("cannot truncate the records file " + path + " to its " + std::to_string(keep) +
                    " blocks up to step " + std::to_string((long long) keepUpToStep) + ": " + systemReason());
      file_ = std::fopen(path.c_str(), "ab");
      if (!file_) throw Error("cannot open the records file " + path + " to append: " + systemReason());
      return;
    }
  }
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw Error("cannot create the records file " + path + ": " + systemReason());
  if (std::fwrite(head.data(), 1, head.size(), file_) != head.size() || std::fflush(file_) != 0) {
    const std::string reason = systemReason();
    std::fclose(file_);
    file_ = nullptr;
    throw Error("cannot write the header of the records file " + path + ": " + reason);
  }
}

Writer::~Writer()
{
  if (file_) std::fclose(file_);
}

void Writer::write(int64_t step, double time, const char *records)
{
  char *b = block_.data();
  std::memcpy(b, &step, 8);
  std::memcpy(b + 8, &time, 8);
  const size_t n = size_t(layout_.particles()) * layout_.recordBytes();
  std::memcpy(b + 16, records, n);
  const int64_t end = ~step;   // -1 - step: a block of zeros is not complete
  std::memcpy(b + 16 + n, &end, 8);
  if (std::fwrite(b, 1, block_.size(), file_) != block_.size() || std::fflush(file_) != 0)
    throw Error("cannot write the records of step " + std::to_string((long long) step) + " to " + path_ + ": " +
                systemReason());
  ++written_;
}

Contents read(const std::string &path)
{
  std::ifstream in(path.c_str(), std::ios::binary);
  if (!in) throw Error("cannot open the records file " + path);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (all.size() < 12 || std::memcmp(all.data(), magic, 8) != 0)
    throw Error(path + " is not a particle records file (no FDMPREC header)");
  uint32_t length = 0;
  for (int b = 0; b < 4; ++b) length |= uint32_t((unsigned char) all[8 + b]) << (8 * b);
  if (all.size() < 12 + size_t(length)) throw Error(path + ": the records header is cut short");
  Contents c;
  c.json = all.substr(12, length);
  c.headerBytes = 12 + length;
  if (size_t(jsonInteger(c.json, "header_bytes")) != c.headerBytes) throw Error(path + ": inconsistent header length");
  if (c.json.find(std::string("\"byte_order\": \"") + (littleEndian() ? "little" : "big")) == std::string::npos)
    throw Error(path + " was written with the other byte order");
  // the fields, from the numpy description [["name", "<f8", [3]], ...]
  std::vector<Field> fields;
  const size_t start = c.json.find("\"particle_fields\": [");
  if (start == std::string::npos) throw Error(path + ": the records header has no particle_fields");
  // the list itself, by matching brackets (the metadata after it may hold lists too)
  size_t stop = start + 19;
  for (int depth = 0; stop < c.json.size(); ++stop) {
    if (c.json[stop] == '[') ++depth;
    if (c.json[stop] == ']' && --depth == 0) break;
  }
  const std::string list = c.json.substr(start + 20, stop - start - 20);
  size_t at = 0;
  while (true) {
    const size_t open = list.find("[\"", at);
    if (open == std::string::npos) break;
    const size_t nameEnd = list.find('"', open + 2);
    Field f;
    f.name = list.substr(open + 2, nameEnd - open - 2);
    const size_t type = list.find('"', nameEnd + 1);
    const std::string t = list.substr(type + 1, 3);
    f.kind = t == "<f8" || t == ">f8" ? 'f' : t == "<i8" || t == ">i8" ? 'l' : 'i';
    f.count = 1;
    const size_t close = list.find(']', type);
    const size_t count = list.find('[', type);
    if (count != std::string::npos && count < close) {
      f.count = std::atoi(list.c_str() + count + 1);
      at = list.find(']', close + 1) + 1;
    } else {
      at = close + 1;
    }
    fields.push_back(f);
  }
  c.layout = Layout(fields, long(jsonInteger(c.json, "particles")));
  if (c.layout.recordBytes() != size_t(jsonInteger(c.json, "record_bytes")))
    throw Error(path + ": the fields do not add up to record_bytes");
  const size_t block = c.layout.blockBytes(), data = c.layout.particles() * c.layout.recordBytes();
  size_t offset = c.headerBytes;
  while (offset + block <= all.size()) {
    int64_t step, end;
    double time;
    std::memcpy(&step, all.data() + offset, 8);
    std::memcpy(&time, all.data() + offset + 8, 8);
    std::memcpy(&end, all.data() + offset + 16 + data, 8);
    if (end != ~step) break;   // not completely written (e.g. a crash with the file extended)
    c.steps.push_back(step);
    c.times.push_back(time);
    c.records.insert(c.records.end(), all.begin() + long(offset + 16), all.begin() + long(offset + 16 + data));
    offset += block;
  }
  c.droppedBytes = all.size() - offset;
  return c;
}

double Contents::value(size_t block, long particle, const std::string &field, int component) const
{
  double v;
  std::memcpy(&v, records.data() + (block * layout.particles() + particle) * layout.recordBytes() +
                      layout.offset(field) + 8 * component, 8);
  return v;
}

int64_t Contents::integer(size_t block, long particle, const std::string &field, int component) const
{
  const char *at = records.data() + (block * layout.particles() + particle) * layout.recordBytes() + layout.offset(field);
  for (const Field &f : layout.fields())
    if (f.name == field) {
      if (f.kind == 'l') {
        int64_t v;
        std::memcpy(&v, at + 8 * component, 8);
        return v;
      }
      int32_t v;
      std::memcpy(&v, at + 4 * component, 4);
      return v;
    }
  throw Error("records: no field " + field);
}

}  // namespace records

namespace vtk {

namespace {

void renameInto(const std::string &tmp, const std::string &path)
{
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw records::Error("cannot move " + tmp + " to " + path + ": " + std::strerror(errno));
}

}  // namespace

void writeParticles(const std::string &path, const std::vector<double> &points, const std::vector<Array> &arrays)
{
  const size_t n = points.size() / 3;
  const bool little = records::littleEndian();
  // raw appended data: each array is a uint64 byte count then its values
  std::ostringstream xml;
  std::string data;
  auto append = [&](const void *values, uint64_t bytes) {
    const size_t offset = data.size();
    data.append(reinterpret_cast<const char *>(&bytes), 8);
    data.append(reinterpret_cast<const char *>(values), size_t(bytes));
    return offset;
  };
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\""
      << (little ? "LittleEndian" : "BigEndian") << "\" header_type=\"UInt64\">\n<PolyData>\n<Piece NumberOfPoints=\""
      << n << "\" NumberOfVerts=\"" << n << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
  xml << "<PointData Scalars=\"radius\">\n";
  for (const Array &a : arrays) {
    if (a.values.size() != n * size_t(a.components))
      throw records::Error("vtk: array " + a.name + " has " + std::to_string(a.values.size()) + " values for " +
                           std::to_string(n) + " points of " + std::to_string(a.components) + " components");
    const size_t offset = append(a.values.data(), 8 * a.values.size());
    xml << "<DataArray type=\"Float64\" Name=\"" << a.name << "\" NumberOfComponents=\"" << a.components
        << "\" format=\"appended\" offset=\"" << offset << "\"/>\n";
  }
  xml << "</PointData>\n<Points>\n";
  xml << "<DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\""
      << append(points.data(), 8 * points.size()) << "\"/>\n</Points>\n<Verts>\n";
  std::vector<int64_t> connectivity(n), offsets(n);
  for (size_t k = 0; k < n; ++k) {
    connectivity[k] = int64_t(k);
    offsets[k] = int64_t(k + 1);
  }
  xml << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\""
      << append(connectivity.data(), 8 * n) << "\"/>\n";
  xml << "<DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"" << append(offsets.data(), 8 * n)
      << "\"/>\n</Verts>\n</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";
  const std::string tmp = path + ".tmp";
  FILE *f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw records::Error("cannot create " + tmp + ": " + std::strerror(errno));
  const std::string head = xml.str(), tail = "\n</AppendedData>\n</VTKFile>\n";
  const bool ok = std::fwrite(head.data(), 1, head.size(), f) == head.size() &&
                  std::fwrite(data.data(), 1, data.size(), f) == data.size() &&
                  std::fwrite(tail.data(), 1, tail.size(), f) == tail.size();
  const std::string reason = std::strerror(errno);
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    throw records::Error("cannot write " + path + ": " + reason);
  }
  renameInto(tmp, path);
}

void Series::load(double keepUpToTime)
{
  entries_.clear();
  std::ifstream in(path_.c_str());
  std::string line;
  while (std::getline(in, line)) {
    const size_t t = line.find("timestep=\""), f = line.find("file=\"");
    if (t == std::string::npos || f == std::string::npos) continue;
    const double time = std::atof(line.c_str() + t + 10);
    const std::string file = line.substr(f + 6, line.find('"', f + 6) - f - 6);
    if (time <= keepUpToTime) entries_.emplace_back(time, file);
  }
}

void Series::add(double time, const std::string &file)
{
  while (!entries_.empty() && entries_.back().first >= time) entries_.pop_back();  // a step written again
  entries_.emplace_back(time, file);
  write();
}

void Series::write() const
{
  const std::string tmp = path_ + ".tmp";
  FILE *f = std::fopen(tmp.c_str(), "w");
  if (!f) throw records::Error("cannot create " + tmp + ": " + std::strerror(errno));
  std::fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n", f);
  for (const auto &e : entries_)
    std::fprintf(f, "<DataSet timestep=\"%.15g\" part=\"0\" file=\"%s\"/>\n", e.first, e.second.c_str());
  std::fputs("</Collection>\n</VTKFile>\n", f);
  const bool bad = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || bad) {
    std::remove(tmp.c_str());
    throw records::Error("cannot write " + path_ + ": " + std::strerror(errno));
  }
  renameInto(tmp, path_);
}

}  // namespace vtk
}  // namespace fdm
