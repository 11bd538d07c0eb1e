// Scratch directories of the C++ unit tests: /tmp/<prefix>.<pid>.<name>. A run where every test
// passed removes its own at the end; a failing run keeps them (inputs, dumps, message records) for
// inspection, and so does any run with FDM_KEEP_TEST_DIRS=1.
#ifndef FDM_TEST_SUPPORT_SCRATCH_H
#define FDM_TEST_SUPPORT_SCRATCH_H

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <ftw.h>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace fdm {
namespace testing {

inline std::string scratchPath(const std::string& prefix, const std::string& name)
{
    return "/tmp/" + prefix + "." + std::to_string(getpid()) + "." + name;
}

// Registered once per test program (see FDM_SCRATCH_CLEANUP).
class ScratchCleanup : public ::testing::Environment
{
public:
    explicit ScratchCleanup(const std::string& prefix) : prefix_(prefix + "." + std::to_string(getpid()) + ".") {}

    void TearDown() override
    {
        if (!::testing::UnitTest::GetInstance()->Passed() || std::getenv("FDM_KEEP_TEST_DIRS"))
            return;
        std::vector<std::string> paths;
        if (DIR* tmp = ::opendir("/tmp")) {
            while (const dirent* entry = ::readdir(tmp))
                if (std::strncmp(entry->d_name, prefix_.c_str(), prefix_.size()) == 0)
                    paths.push_back(std::string("/tmp/") + entry->d_name);
            ::closedir(tmp);
        }
        for (const std::string& path : paths)
            ::nftw(path.c_str(), [](const char* p, const struct stat*, int, struct FTW*) { return ::remove(p); }, 16,
                   FTW_DEPTH | FTW_PHYS);
    }

private:
    std::string prefix_;
};

}  // namespace testing
}  // namespace fdm

// In one source file of a test program: FDM_SCRATCH_CLEANUP("fdmDEMTest");
#define FDM_SCRATCH_CLEANUP(prefix)                                                                            \
    static ::testing::Environment* const fdmScratchCleanup =                                                   \
        ::testing::AddGlobalTestEnvironment(new ::fdm::testing::ScratchCleanup(prefix))

#endif
