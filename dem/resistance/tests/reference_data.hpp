// Readers for the tests' reference numbers, kept in the repository under dem/resistance/tests/data (sources
// and users of each file in its README.md).  A missing folder or file throws, so the test that needs it
// FAILS with the path in the message (it never skips).
#ifndef FDM_RESISTANCE_TESTS_REFERENCE_DATA_HPP
#define FDM_RESISTANCE_TESTS_REFERENCE_DATA_HPP

#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <vector>

namespace reference {

inline std::string folder() { return FDM_TEST_DATA_DIR; }

inline bool folderExists()
{
    struct stat s;
    return stat(folder().c_str(), &s) == 0 && S_ISDIR(s.st_mode);
}

inline std::string path(const std::string& relative)
{
    if (!folderExists())
        throw std::runtime_error("reference data folder missing: " + folder() +
                                 " (dem/resistance/tests/data in the repository)");
    const std::string p = folder() + "/" + relative;
    std::ifstream in(p.c_str());
    if (!in) throw std::runtime_error("reference file missing or unreadable: " + p);
    return p;
}

// Whitespace-separated numeric rows, skipping `skipLines` header lines.
inline std::vector<std::vector<double> > readTable(const std::string& relative, int skipLines)
{
    std::ifstream in(path(relative).c_str());
    std::string line;
    for (int i = 0; i < skipLines; ++i) std::getline(in, line);
    std::vector<std::vector<double> > rows;
    while (std::getline(in, line)) {
        std::istringstream s(line);
        std::vector<double> row;
        double v;
        while (s >> v) row.push_back(v);
        if (!row.empty()) rows.push_back(row);
    }
    if (rows.empty()) throw std::runtime_error("reference file has no data: " + relative);
    return rows;
}

// CSV with an optional header line; returns the header names (empty if none) and the numeric rows.
struct Csv {
    std::vector<std::string> header;
    std::vector<std::vector<double> > rows;
    int column(const std::string& name) const
    {
        for (std::size_t i = 0; i < header.size(); ++i)
            if (header[i] == name) return int(i);
        throw std::runtime_error("reference column not found: " + name);
    }
};

inline Csv readCsv(const std::string& relative, bool hasHeader)
{
    std::ifstream in(path(relative).c_str());
    Csv csv;
    std::string line;
    if (hasHeader && std::getline(in, line)) {
        std::istringstream s(line);
        std::string cell;
        while (std::getline(s, cell, ',')) csv.header.push_back(cell);
    }
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        std::istringstream s(line);
        std::string cell;
        std::vector<double> row;
        while (std::getline(s, cell, ',')) row.push_back(std::stod(cell));
        csv.rows.push_back(row);
    }
    if (csv.rows.empty()) throw std::runtime_error("reference file has no data: " + relative);
    return csv;
}

}  // namespace reference

#endif
