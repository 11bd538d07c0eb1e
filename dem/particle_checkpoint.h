/* The particle side's checkpoint file (fix fdm/couple checkpoint N, fdmDEM -resume FILE; docs/coupling.md,
   "Checkpoint and resume"). Plain C++ (no LIGGGHTS): fix fdm/couple fills and reads the arrays.

   A checkpoint is everything the next time step reads, in binary (IEEE doubles, bit-exact), so that
   a resumed run repeats the steps of the uninterrupted one: per particle its position, velocity and
   image flags, the contact history (tangential springs) of pairs and walls, and the position
   update's history (U_n, U_{n-1}, x_n and the planned displacement rates of Adams-Bashforth 2,
   position_update.h), with the last step's outputs (per-atom arrays of the fix).

   File layout (little-endian, as the machine writes doubles):
     FDM-DEM-CHECKPOINT 1\n
     step=S lastStep=L natoms=N dt=... boxlo=x,y,z boxhi=x,y,z\n
     array NAME COUNT\n          (one line per array, in name order)
     data BYTES crc32=C\n        (BYTES = 8 x the sum of the counts; C the CRC-32 of those bytes)
     <the doubles of every array, in the order of the lines>
     end FDM-DEM-CHECKPOINT\n
   It is written to FILE.tmp, flushed to disk and renamed to FILE: a kill during the write leaves
   FILE.tmp and the previous checkpoints untouched. scripts/fdmsubgrid/checkpoint.py reads the same layout. */

#ifndef FDM_PARTICLE_CHECKPOINT_H
#define FDM_PARTICLE_CHECKPOINT_H

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdm {
namespace checkpoint {

struct ParticleCheckpoint {
  long long step = 0;        // the LIGGGHTS time step it was written at the end of
  long long lastStep = 0;    // the last step of the run it belongs to (run N upto)
  long long natoms = 0;
  double dt = 0;
  double boxlo[3] = {0, 0, 0}, boxhi[3] = {0, 0, 0};
  std::map<std::string, std::vector<double> > arrays;

  // the array, or a CheckpointError naming the file if it is absent or not `count` long (count < 0: any)
  const std::vector<double> &array(const std::string &name, long long count, const std::string &file) const;
};

struct CheckpointError : std::runtime_error {
  explicit CheckpointError(const std::string &what) : std::runtime_error(what) {}
};

// The file's bytes.
std::vector<char> encode(const ParticleCheckpoint &c);
// Decodes and checks the bytes of `file` (its name is for the messages): a file cut short, another
// format, a damaged payload are CheckpointErrors saying so.
ParticleCheckpoint decode(const std::vector<char> &bytes, const std::string &file);
// FILE.tmp, fsync, rename to FILE; throws CheckpointError naming the file (disk full ...).
void writeAtomically(const std::string &file, const std::vector<char> &bytes);
std::vector<char> readFile(const std::string &file);
// Deletes the checkpoints PREFIX<step> in `directory` but the `keep` newest up to `newest`
// (a newer one, left by an earlier attempt of the run, goes too), and every PREFIX*.tmp.
void prune(const std::string &directory, const std::string &prefix, long long newest, int keep);

uint32_t crc32(const char *data, size_t size);

}  // namespace checkpoint
}  // namespace fdm

#endif
