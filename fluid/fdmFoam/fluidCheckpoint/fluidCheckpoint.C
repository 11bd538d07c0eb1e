#include "fluidCheckpoint.H"

#include <fcntl.h>
#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

std::string Foam::fluidCheckpoint::write(const std::string& file) const
{
    std::ostringstream os;
    char t[40];
    std::snprintf(t, sizeof t, "%.17g", time);
    os  << "# fdmFoam checkpoint: U p lambda phi of this step in " << timeName
        << "/ (binary; processor*/" << timeName << "/ in parallel)\n"
        << "step " << step << "\ntime " << t << "\ntimeIndex " << timeIndex
        << "\ntimeName " << timeName << "\nstepsDone " << stepsDone
        << "\ncells " << cells << "\nprocessors " << processors
        << "\nparticles " << particles << "\nregularOutput "
        << (regularOutput ? 1 : 0) << "\nfromRest " << (fromRest ? 1 : 0)
        << "\nend\n";
    const std::string text = os.str();
    const std::string tmp = file + ".tmp";
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0)
    {
        return "could not create " + tmp + ": " + std::strerror(errno);
    }
    const bool ok =
        ::write(fd, text.data(), text.size()) == ssize_t(text.size())
     && ::fsync(fd) == 0;
    const std::string why = std::strerror(errno);
    if (::close(fd) != 0 || !ok)
    {
        ::unlink(tmp.c_str());
        return "could not write " + tmp + " (" + why + ": disk full?)";
    }
    if (std::rename(tmp.c_str(), file.c_str()) != 0)
    {
        return "could not rename " + tmp + " to " + file + ": "
            + std::strerror(errno);
    }
    return "";
}


std::string Foam::fluidCheckpoint::read(const std::string& file)
{
    std::ifstream is(file);
    if (!is)
    {
        return "there is no checkpoint marker " + file
            + " (no complete fluid checkpoint of that step)";
    }
    std::string key;
    bool complete = false;
    int found = 0;
    while (is >> key)
    {
        if (key[0] == '#') { std::getline(is, key); continue; }
        if (key == "end") { complete = true; break; }
        if (key == "step") { is >> step; ++found; }
        else if (key == "time") { is >> time; ++found; }
        else if (key == "timeIndex") { is >> timeIndex; ++found; }
        else if (key == "timeName") { is >> timeName; ++found; }
        else if (key == "stepsDone") { is >> stepsDone; ++found; }
        else if (key == "cells") { is >> cells; ++found; }
        else if (key == "processors") { is >> processors; ++found; }
        else if (key == "particles") { is >> particles; ++found; }
        else if (key == "regularOutput") { int r = 0; is >> r; regularOutput = r; }
        else if (key == "fromRest") { int r = 0; is >> r; fromRest = r; }
        else { std::getline(is, key); }
    }
    if (!complete || found != 8 || is.bad())
    {
        return file + " is not a complete fdmFoam checkpoint marker (truncated"
            " or damaged: " + std::to_string(found) + " of its 8 entries and "
            + (complete ? "" : "no ") + "end line)";
    }
    return "";
}
