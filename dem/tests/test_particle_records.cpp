// The particle records file and the ParaView particle files on their own (particle_records.h):
// round trip, a run killed in the middle of a block, appending after a resume, the VTK files.
#include "particle_records.h"
#include "scratch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace rec = fdm::records;

namespace {

std::string scratch(const std::string &name)
{
  const std::string dir = fdm::testing::scratchPath("fdmRecordsTest", name);
  ::mkdir(dir.c_str(), 0755);
  return dir;
}

const std::vector<rec::Field> fields = {{"tag", 'l', 1}, {"type", 'i', 1}, {"image", 'i', 3}, {"x", 'f', 3},
                                        {"radius", 'f', 1}, {"S_contact", 'f', 6}};

// a particle record of the layout above for particle p at step s, every value distinct
std::vector<char> records(const rec::Layout &layout, long step)
{
  std::vector<char> out(layout.recordBytes() * layout.particles());
  for (long p = 0; p < layout.particles(); ++p) {
    char *r = &out[p * layout.recordBytes()];
    const int64_t tag = p + 1;
    const int32_t type = 1 + p % 2, image[3] = {int32_t(step % 3 - 1), 0, -int32_t(p)};
    double x[3] = {0.1 * p + step, 1.0 / (p + 1), -std::sqrt(double(step + p))}, radius = 1 + 0.4 * (p % 2), s[6];
    for (int k = 0; k < 6; ++k) s[k] = 1e-3 * (k + 1) * (p + 1) * (step + 1);
    std::memcpy(r + layout.offset("tag"), &tag, 8);
    std::memcpy(r + layout.offset("type"), &type, 4);
    std::memcpy(r + layout.offset("image"), image, 12);
    std::memcpy(r + layout.offset("x"), x, 24);
    std::memcpy(r + layout.offset("radius"), &radius, 8);
    std::memcpy(r + layout.offset("S_contact"), s, 48);
  }
  return out;
}

long fileSize(const std::string &path)
{
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 ? long(st.st_size) : -1;
}

}  // namespace

TEST(ParticleRecords, LayoutAndHeader)
{
  const rec::Layout layout(fields, 5);
  EXPECT_EQ(layout.recordBytes(), 8u + 4 + 12 + 24 + 8 + 48);
  EXPECT_EQ(layout.blockBytes(), 16 + 5 * layout.recordBytes() + 8);
  EXPECT_EQ(layout.offset("x"), 24u);
  EXPECT_THROW(layout.offset("y"), rec::Error);
  const std::string h = rec::header(layout, "\"dt\": 0.5");
  EXPECT_EQ(h.size() % 64, 0u);
  EXPECT_EQ(h.substr(0, 8), "FDMPREC\n");
  EXPECT_EQ(h.back(), '\n');
  EXPECT_NE(h.find("\"header_bytes\": " + std::to_string(h.size()) + " "), std::string::npos) << h;
  EXPECT_NE(h.find("[\"image\", \"<i4\", [3]]"), std::string::npos) << h;
  EXPECT_THROW(rec::Layout(fields, 0), rec::Error);
  EXPECT_THROW(rec::Layout({{"x", 'q', 1}}, 1), rec::Error);
}

TEST(ParticleRecords, RoundTrip)
{
  const std::string path = scratch("roundtrip") + "/p.records";
  const rec::Layout layout(fields, 7);
  {
    rec::Writer w(path, layout, "\"every\": 10, \"box_lo\": [0, 0, 0]");
    for (long step = 10; step <= 50; step += 10) w.write(step, 0.02 * step, records(layout, step).data());
    EXPECT_EQ(w.blocksWritten(), 5);
    // flushed after every block: the file is complete while the writer is still open
    EXPECT_EQ(fileSize(path), long(w.headerBytes() + 5 * layout.blockBytes()));
  }
  const rec::Contents c = rec::read(path);
  ASSERT_EQ(c.steps.size(), 5u);
  EXPECT_EQ(c.droppedBytes, 0u);
  EXPECT_EQ(c.layout.numpyFields(), layout.numpyFields());
  EXPECT_NE(c.json.find("\"box_lo\": [0, 0, 0]"), std::string::npos);
  for (size_t b = 0; b < 5; ++b) {
    const long step = 10 * long(b + 1);
    EXPECT_EQ(c.steps[b], step);
    EXPECT_EQ(c.times[b], 0.02 * step);
    const std::vector<char> expected = records(layout, step);
    EXPECT_EQ(0, std::memcmp(expected.data(), &c.records[b * expected.size()], expected.size())) << "block " << b;
  }
  EXPECT_EQ(c.integer(3, 4, "tag"), 5);
  EXPECT_EQ(c.integer(3, 4, "image", 2), -4);
  EXPECT_EQ(c.value(3, 4, "x", 2), -std::sqrt(44.0));
}

TEST(ParticleRecords, AKilledRunKeepsEveryCompleteBlock)
{
  const std::string path = scratch("truncated") + "/p.records";
  const rec::Layout layout(fields, 3);
  size_t header;
  {
    rec::Writer w(path, layout, "");
    for (long step = 1; step <= 4; ++step) w.write(step, step, records(layout, step).data());
    header = w.headerBytes();
  }
  // cut in the middle of the last block, then just before its end marker, then a whole block
  // followed by a block of zeros (a crash after the file grew, before the data reached the disk)
  for (long cut : {long(layout.blockBytes() / 2), 1L, 4L}) {
    ASSERT_EQ(0, ::truncate(path.c_str(), long(header + 4 * layout.blockBytes()) - cut));
    const rec::Contents c = rec::read(path);
    ASSERT_EQ(c.steps.size(), 3u) << "cut " << cut;
    EXPECT_EQ(c.steps.back(), 3);
    EXPECT_EQ(c.droppedBytes, layout.blockBytes() - cut);
    const std::vector<char> expected = records(layout, 3);
    EXPECT_EQ(0, std::memcmp(expected.data(), &c.records[2 * expected.size()], expected.size()));
  }
  ASSERT_EQ(0, ::truncate(path.c_str(), long(header + 3 * layout.blockBytes())));
  ASSERT_EQ(0, ::truncate(path.c_str(), long(header + 4 * layout.blockBytes())));  // zeros
  EXPECT_EQ(rec::read(path).steps.size(), 3u);
  // a cut header is no records file
  ASSERT_EQ(0, ::truncate(path.c_str(), 30));
  EXPECT_THROW(rec::read(path), rec::Error);
  std::ofstream(path) << "ITEM: TIMESTEP\n0\n";
  try {
    rec::read(path);
    FAIL() << "a text dump read as records";
  } catch (const rec::Error &e) {
    EXPECT_NE(std::string(e.what()).find("not a particle records file"), std::string::npos) << e.what();
  }
}

TEST(ParticleRecords, AppendContinuesAfterTheResumeStep)
{
  const std::string path = scratch("append") + "/p.records";
  const rec::Layout layout(fields, 4);
  {
    rec::Writer w(path, layout, "");
    for (long step = 10; step <= 60; step += 10) w.write(step, step, records(layout, step).data());
  }
  ASSERT_EQ(0, ::truncate(path.c_str(), fileSize(path) - 5));   // and killed in the last block
  {
    // resumed from the checkpoint of step 30: blocks 40, 50 (and the partial 60) are dropped
    rec::Writer w(path, layout, "", true, 30);
    EXPECT_EQ(w.blocksKept(), 3);
    for (long step = 40; step <= 50; step += 10) w.write(step, step + 0.5, records(layout, step).data());
  }
  const rec::Contents c = rec::read(path);
  EXPECT_EQ(c.steps, (std::vector<int64_t>{10, 20, 30, 40, 50}));
  EXPECT_EQ(c.times[3], 40.5);
  EXPECT_EQ(c.droppedBytes, 0u);
  // another layout cannot be appended
  try {
    rec::Writer w(path, rec::Layout(fields, 5), "", true, 50);
    FAIL() << "appended 5 particles to a file of 4";
  } catch (const rec::Error &e) {
    EXPECT_NE(std::string(e.what()).find("holds 4 particles"), std::string::npos) << e.what();
  }
  // append to a file that is not there: a new file
  const std::string fresh = scratch("append") + "/new.records";
  {
    rec::Writer w(fresh, layout, "", true, 0);
    w.write(1, 1, records(layout, 1).data());
  }
  EXPECT_EQ(rec::read(fresh).steps.size(), 1u);
  // an unwritable place is an error naming the file
  try {
    rec::Writer w("/nonexistent-folder/p.records", layout, "");
    FAIL();
  } catch (const rec::Error &e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/p.records"), std::string::npos) << e.what();
  }
}

TEST(ParticleVtk, FileAndSeries)
{
  const std::string dir = scratch("vtk");
  const std::vector<double> points = {0, 0, 0, 1, 2, 3};
  fdm::vtk::writeParticles(dir + "/a.vtp", points, {{"radius", 1, {1.0, 1.4}}, {"U", 3, {1, 2, 3, 4, 5, 6}}});
  std::ifstream in(dir + "/a.vtp", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("NumberOfPoints=\"2\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"U\" NumberOfComponents=\"3\" format=\"appended\" offset=\"24\""), std::string::npos);
  // the raw data: radius (8 + 16 bytes) first, after the '_'
  const size_t data = text.find('_', text.find("<AppendedData")) + 1;
  uint64_t bytes;
  double r[2];
  std::memcpy(&bytes, text.data() + data, 8);
  std::memcpy(r, text.data() + data + 8, 16);
  EXPECT_EQ(bytes, 16u);
  EXPECT_EQ(r[1], 1.4);
  EXPECT_NE(text.find("</VTKFile>"), std::string::npos);
  EXPECT_EQ(fileSize(dir + "/a.vtp.tmp"), -1);
  EXPECT_THROW(fdm::vtk::writeParticles(dir + "/b.vtp", points, {{"radius", 1, {1.0}}}), rec::Error);

  fdm::vtk::Series s(dir + "/p.pvd");
  s.add(0, "p_0.vtp");
  s.add(0.5, "p_5.vtp");
  s.add(1, "p_10.vtp");
  fdm::vtk::Series resumed(dir + "/p.pvd");
  resumed.load(0.5);
  EXPECT_EQ(resumed.size(), 2u);
  resumed.add(0.75, "p_75.vtp");
  std::ifstream pvd(dir + "/p.pvd");
  std::stringstream all;
  all << pvd.rdbuf();
  EXPECT_NE(all.str().find("timestep=\"0.75\" part=\"0\" file=\"p_75.vtp\""), std::string::npos) << all.str();
  EXPECT_EQ(all.str().find("p_10.vtp"), std::string::npos);
}

FDM_SCRATCH_CLEANUP("fdmRecordsTest");
