// fdmCouplerDump -- prints the messages of a coupled run, for debugging and replay:
//   fdmCouplerDump [--all] <record file | coupling directory>
// A record file (fix fdm/couple record FILE, fdmFoam coupling record) holds messages back to back
// in wire format; a directory is the file transport's (<seq>.<sender>.msg files).
#include "fdm/coupler.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/stat.h>
#include <vector>

using namespace fdm::coupler;

namespace {

bool showAll = false;

// Who sent it: the protocol fixes it for every type but Hello (its text says) and Error.
std::string sender(const Message& m)
{
    switch (m.type) {
        case MessageType::Step: case MessageType::Velocities: case MessageType::Finish: return "dem";
        case MessageType::Volumes: case MessageType::Integrals: case MessageType::StepDone: return "fluid";
        case MessageType::Hello: return m.text.find("role=fluid") != std::string::npos ? "fluid" : "dem";
        default: return "?";
    }
}

void print(size_t index, const Message& m, const std::string& from)
{
    const std::string to = from == "dem" ? "fluid" : from == "fluid" ? "dem" : "?";
    std::printf("#%-5zu %5s -> %-5s %-10s step %llu iteration %u  %u x %u", index, from.c_str(), to.c_str(),
                messageTypeName(m.type), (unsigned long long)m.step, m.iteration, m.count, m.width);
    if (!m.text.empty()) std::printf("  \"%s\"", m.text.c_str());
    std::printf("\n");
    const uint32_t shown = showAll ? m.count : std::min<uint32_t>(m.count, 4);
    for (uint32_t r = 0; r < shown; ++r) {
        std::printf("        [%u]", r);
        for (uint32_t f = 0; f < m.width; ++f) std::printf(" %.17g", m.at(r, f));
        std::printf("\n");
    }
    if (shown < m.count) std::printf("        ... %u more records (--all shows them)\n", m.count - shown);
}

bool readFile(const std::string& path, std::vector<unsigned char>& bytes)
{
    std::ifstream in(path.c_str(), std::ios::binary);
    if (!in) return false;
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

int dumpRecord(const std::string& path)
{
    std::vector<unsigned char> bytes;
    if (!readFile(path, bytes)) {
        std::fprintf(stderr, "fdmCouplerDump: cannot read %s\n", path.c_str());
        return 1;
    }
    size_t at = 0, index = 0;
    while (at < bytes.size()) {
        try {
            if (bytes.size() - at < headerSize) throw CouplerError("truncated header");
            const size_t size = encodedSize(&bytes[at]);
            if (bytes.size() - at < size) throw CouplerError("truncated message");
            const Message m = decode(&bytes[at], size);
            print(++index, m, sender(m));
            at += size;
        } catch (const CouplerError& e) {
            std::fprintf(stderr, "fdmCouplerDump: %s: byte %zu (message %zu): %s\n", path.c_str(), at, index + 1,
                         e.what());
            return 1;
        }
    }
    std::printf("%zu messages\n", index);
    return 0;
}

int dumpDirectory(const std::string& dir)
{
    struct Entry { long long mtime; std::string name; };
    std::vector<Entry> files;
    if (DIR* d = opendir(dir.c_str())) {
        while (dirent* e = readdir(d)) {
            const std::string name = e->d_name;
            if (name.size() < 4 || name.compare(name.size() - 4, 4, ".msg") != 0) continue;
            struct stat st;
            if (stat((dir + "/" + name).c_str(), &st) != 0) continue;
            files.push_back(Entry{st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec, name});
        }
        closedir(d);
    }
    // the order in which they were written (both sides number their own messages from 1)
    std::sort(files.begin(), files.end(), [](const Entry& a, const Entry& b) {
        return a.mtime != b.mtime ? a.mtime < b.mtime : a.name < b.name;
    });
    int status = 0;
    size_t index = 0;
    for (const Entry& f : files) {
        std::vector<unsigned char> bytes;
        const std::string from = f.name.substr(f.name.find('.') + 1, f.name.rfind('.') - f.name.find('.') - 1);
        try {
            if (!readFile(dir + "/" + f.name, bytes)) throw CouplerError("cannot read it");
            print(++index, decode(bytes.data(), bytes.size()), from);
        } catch (const CouplerError& e) {
            std::fprintf(stderr, "fdmCouplerDump: %s/%s: %s\n", dir.c_str(), f.name.c_str(), e.what());
            status = 1;
        }
    }
    std::printf("%zu messages\n", index);
    return status;
}

}  // namespace

int main(int argc, char** argv)
{
    std::string path;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--all") || !std::strcmp(argv[i], "-a")) showAll = true;
        else if (path.empty() && argv[i][0] != '-') path = argv[i];
        else path.clear(), i = argc;
    }
    if (path.empty()) {
        std::fprintf(stderr, "usage: fdmCouplerDump [--all] <record file | coupling directory>\n");
        return 2;
    }
    struct stat st;
    if (stat(path.c_str(), &st) != 0) {
        std::fprintf(stderr, "fdmCouplerDump: %s does not exist\n", path.c_str());
        return 1;
    }
    return S_ISDIR(st.st_mode) ? dumpDirectory(path) : dumpRecord(path);
}
