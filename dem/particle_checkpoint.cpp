// The particle side's checkpoint file (see particle_checkpoint.h).
#include "particle_checkpoint.h"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace fdm {
namespace checkpoint {

namespace {

const char magic[] = "FDM-DEM-CHECKPOINT 1";
const char trailer[] = "end FDM-DEM-CHECKPOINT\n";

std::string digits(double x)
{
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

}  // namespace

uint32_t crc32(const char *data, size_t size)
{
  // CRC-32 (IEEE 802.3, as zlib.crc32), bitwise: a checkpoint is written every N steps
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < size; i++) {
    c ^= uint8_t(data[i]);
    for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

const std::vector<double> &ParticleCheckpoint::array(const std::string &name, long long count,
                                                     const std::string &file) const
{
  auto it = arrays.find(name);
  if (it == arrays.end()) throw CheckpointError(file + " has no array '" + name + "': not a checkpoint of this fdmDEM");
  if (count >= 0 && (long long) it->second.size() != count)
    throw CheckpointError(file + ": array '" + name + "' has " + std::to_string(it->second.size()) +
                          " values where " + std::to_string(count) + " were expected");
  return it->second;
}

std::vector<char> encode(const ParticleCheckpoint &c)
{
  std::ostringstream head;
  head << magic << "\n"
       << "step=" << c.step << " lastStep=" << c.lastStep << " natoms=" << c.natoms << " dt=" << digits(c.dt)
       << " boxlo=" << digits(c.boxlo[0]) << "," << digits(c.boxlo[1]) << "," << digits(c.boxlo[2])
       << " boxhi=" << digits(c.boxhi[0]) << "," << digits(c.boxhi[1]) << "," << digits(c.boxhi[2]) << "\n";
  size_t values = 0;
  for (const auto &a : c.arrays) {
    head << "array " << a.first << " " << a.second.size() << "\n";
    values += a.second.size();
  }
  std::vector<char> payload(values * sizeof(double));
  char *p = payload.data();
  for (const auto &a : c.arrays) {
    if (!a.second.empty()) std::memcpy(p, a.second.data(), a.second.size() * sizeof(double));
    p += a.second.size() * sizeof(double);
  }
  head << "data " << payload.size() << " crc32=" << crc32(payload.data(), payload.size()) << "\n";
  const std::string h = head.str();
  std::vector<char> bytes(h.begin(), h.end());
  bytes.insert(bytes.end(), payload.begin(), payload.end());
  bytes.insert(bytes.end(), trailer, trailer + std::strlen(trailer));
  return bytes;
}

ParticleCheckpoint decode(const std::vector<char> &bytes, const std::string &file)
{
  size_t pos = 0;
  auto line = [&]() -> std::string {
    const auto end = std::find(bytes.begin() + long(pos), bytes.end(), '\n');
    if (end == bytes.end())
      throw CheckpointError(file + " is truncated: it ends inside its header (" + std::to_string(bytes.size()) +
                            " bytes; was the run killed while it was written, or the file copied in part?)");
    std::string s(bytes.begin() + long(pos), end);
    pos = size_t(end - bytes.begin()) + 1;
    return s;
  };
  if (line() != magic) throw CheckpointError(file + " is not a particle checkpoint of fdmDEM (no '" + std::string(magic) + "' line)");
  ParticleCheckpoint c;
  {
    std::istringstream is(line());
    std::string token;
    while (is >> token) {
      const size_t eq = token.find('=');
      const std::string key = token.substr(0, eq), value = eq == std::string::npos ? "" : token.substr(eq + 1);
      if (key == "step") c.step = std::stoll(value);
      else if (key == "lastStep") c.lastStep = std::stoll(value);
      else if (key == "natoms") c.natoms = std::stoll(value);
      else if (key == "dt") c.dt = std::stod(value);
      else if (key == "boxlo" || key == "boxhi")
        std::sscanf(value.c_str(), "%lf,%lf,%lf", key == "boxlo" ? &c.boxlo[0] : &c.boxhi[0],
                    key == "boxlo" ? &c.boxlo[1] : &c.boxhi[1], key == "boxlo" ? &c.boxlo[2] : &c.boxhi[2]);
    }
  }
  std::vector<std::pair<std::string, size_t> > names;
  size_t payloadBytes = 0;
  unsigned long crc = 0;
  while (true) {
    std::istringstream is(line());
    std::string word;
    is >> word;
    if (word == "array") {
      std::string name;
      size_t count = 0;
      is >> name >> count;
      names.push_back(std::make_pair(name, count));
    } else if (word == "data") {
      std::string crcText;
      is >> payloadBytes >> crcText;
      crc = std::stoul(crcText.substr(crcText.find('=') + 1));
      break;
    } else {
      throw CheckpointError(file + ": unexpected header line '" + word + " ...': not a checkpoint of this fdmDEM");
    }
  }
  size_t values = 0;
  for (const auto &n : names) values += n.second;
  if (values * sizeof(double) != payloadBytes)
    throw CheckpointError(file + " is damaged: its arrays hold " + std::to_string(values) + " values but its data " +
                          std::to_string(payloadBytes) + " bytes");
  const size_t expected = pos + payloadBytes + std::strlen(trailer);
  if (bytes.size() < expected)
    throw CheckpointError(file + " is truncated: " + std::to_string(bytes.size()) + " bytes where its header says " +
                          std::to_string(expected) + " (was the run killed while it was written, or the file copied "
                          "in part?)");
  if (bytes.size() != expected || std::memcmp(&bytes[pos + payloadBytes], trailer, std::strlen(trailer)) != 0)
    throw CheckpointError(file + " is damaged: it does not end with '" + std::string(trailer, std::strlen(trailer) - 1) +
                          "' after its " + std::to_string(payloadBytes) + " bytes of data");
  if (crc32(&bytes[pos], payloadBytes) != crc)
    throw CheckpointError(file + " is damaged: the CRC-32 of its data differs from the one written with it");
  const char *p = &bytes[pos];
  for (const auto &n : names) {
    std::vector<double> &a = c.arrays[n.first];
    a.resize(n.second);
    if (n.second) std::memcpy(a.data(), p, n.second * sizeof(double));
    p += n.second * sizeof(double);
  }
  return c;
}

void writeAtomically(const std::string &file, const std::vector<char> &bytes)
{
  const std::string tmp = file + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw CheckpointError("could not create " + tmp + ": " + std::strerror(errno));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      ::unlink(tmp.c_str());
      throw CheckpointError("could not write " + tmp + " (" + why + ": disk full?); the previous checkpoint is kept");
    }
    done += size_t(n);
  }
  // on disk before the rename makes it the checkpoint (a crash of the machine, not only of the run)
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw CheckpointError("could not write " + tmp + " (" + why + "); the previous checkpoint is kept");
  }
  if (std::rename(tmp.c_str(), file.c_str()) != 0)
    throw CheckpointError("could not rename " + tmp + " to " + file + ": " + std::strerror(errno));
}

std::vector<char> readFile(const std::string &file)
{
  FILE *f = std::fopen(file.c_str(), "rb");
  if (!f) throw CheckpointError("cannot open the checkpoint " + file + ": " + std::strerror(errno));
  std::vector<char> bytes;
  char buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) bytes.insert(bytes.end(), buf, buf + n);
  std::fclose(f);
  return bytes;
}

void prune(const std::string &directory, const std::string &prefix, long long newest, int keep)
{
  DIR *dir = ::opendir(directory.c_str());
  if (!dir) return;
  std::vector<long long> steps;
  std::vector<std::string> temporaries;
  while (dirent *e = ::readdir(dir)) {
    const std::string name = e->d_name;
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    if (rest.size() > 4 && rest.compare(rest.size() - 4, 4, ".tmp") == 0) {
      temporaries.push_back(name);
    } else if (!rest.empty() && rest.find_first_not_of("0123456789") == std::string::npos) {
      steps.push_back(std::stoll(rest));
    }
  }
  ::closedir(dir);
  std::sort(steps.rbegin(), steps.rend());
  int kept = 0;
  for (long long s : steps) {
    if (s <= newest && kept < keep) {
      kept++;
      continue;
    }
    std::remove((directory + "/" + prefix + std::to_string(s)).c_str());
  }
  for (const std::string &t : temporaries) std::remove((directory + "/" + t).c_str());
}

}  // namespace checkpoint
}  // namespace fdm
