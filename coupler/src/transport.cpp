// Transports of the fdm coupler: a TCP socket between the two master ranks, or a directory of
// message files (debugging, replay). Every failure is a CouplerError meant for the user.
#include "fdm/coupler.h"

#include <arpa/inet.h>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>

namespace fdm {
namespace coupler {

namespace {

double now()
{
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

std::string seconds(double s)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g s", s);
    return buf;
}

void writeFileAtomically(const std::string& path, const void* data, size_t size)
{
    const std::string tmp = path + ".tmp";
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw CouplerError("coupling: cannot write " + tmp + ": " + std::strerror(errno));
    const bool ok = std::fwrite(data, 1, size, f) == size;
    if (std::fclose(f) != 0 || !ok || std::rename(tmp.c_str(), path.c_str()) != 0)
        throw CouplerError("coupling: cannot write " + path + ": " + std::strerror(errno));
}

bool readFile(const std::string& path, std::vector<unsigned char>& bytes)
{
    std::ifstream in(path.c_str(), std::ios::binary);
    if (!in) return false;
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

// Common part: recording, Error messages from the peer.
class Base : public Transport {
public:
    explicit Base(const Options& o) : options_(o) {}
    void send(const Message& m) override
    {
        const std::vector<unsigned char> bytes = encode(m);
        sendBytes(bytes);
        record(bytes);
    }
    Message receive() override
    {
        std::vector<unsigned char> bytes = receiveBytes(first_ ? options_.connectTimeout : options_.receiveTimeout);
        first_ = false;
        record(bytes);
        Message m = decode(bytes.data(), bytes.size());
        if (m.type == MessageType::Error) throw CouplerError("the " + options_.name + " stopped: " + m.text);
        return m;
    }

protected:
    virtual void sendBytes(const std::vector<unsigned char>& bytes) = 0;
    virtual std::vector<unsigned char> receiveBytes(double timeout) = 0;
    void record(const std::vector<unsigned char>& bytes)
    {
        if (options_.recordFile.empty()) return;
        FILE* f = std::fopen(options_.recordFile.c_str(), "ab");
        if (!f) throw CouplerError("coupling: cannot append to record file " + options_.recordFile);
        std::fwrite(bytes.data(), 1, bytes.size(), f);
        std::fclose(f);
    }
    Options options_;
    bool first_ = true;
};

// ---- socket ---------------------------------------------------------------------------------------
class Socket : public Base {
public:
    Socket(const Options& o, int fd, const std::string& where) : Base(o), fd_(fd), where_(where)
    {
        int one = 1;
        setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
    ~Socket() override { close(); }
    void close() noexcept override
    {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }
    std::string describe() const override { return "socket " + where_; }

protected:
    void sendBytes(const std::vector<unsigned char>& bytes) override
    {
        size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) throw lost(std::strerror(errno));
            done += size_t(n);
        }
    }
    std::vector<unsigned char> receiveBytes(double timeout) override
    {
        std::vector<unsigned char> bytes(headerSize);
        readExactly(bytes.data(), headerSize, timeout);
        const size_t total = encodedSize(bytes.data());
        bytes.resize(total);
        readExactly(bytes.data() + headerSize, total - headerSize, timeout);
        return bytes;
    }

private:
    CouplerError lost(const std::string& why) const
    {
        return CouplerError("coupling: the " + options_.name + " closed the connection (" + why +
                            "): did it crash? See its log.");
    }
    void readExactly(unsigned char* to, size_t size, double timeout)
    {
        const double deadline = now() + timeout;
        size_t done = 0;
        while (done < size) {
            const double left = deadline - now();
            if (left <= 0)
                throw CouplerError("coupling: the " + options_.name + " sent nothing for " + seconds(timeout) +
                                   " (receiveTimeout): is it hung?");
            pollfd p = {fd_, POLLIN, 0};
            const int r = ::poll(&p, 1, int(std::min(left, 1.0) * 1000) + 1);
            if (r < 0 && errno == EINTR) continue;
            if (r < 0) throw lost(std::strerror(errno));
            if (r == 0) continue;
            const ssize_t n = ::recv(fd_, to + done, size - done, 0);
            if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
            if (n == 0) throw lost("end of stream");
            if (n < 0) throw lost(std::strerror(errno));
            done += size_t(n);
        }
    }
    int fd_;
    std::string where_;
};

sockaddr_in address(const std::string& host, int port)
{
    sockaddr_in a;
    std::memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons(uint16_t(port));
    if (inet_pton(AF_INET, host.c_str(), &a.sin_addr) != 1) {
        addrinfo hints, *res = nullptr;
        std::memset(&hints, 0, sizeof hints);
        hints.ai_family = AF_INET;
        if (getaddrinfo(host.c_str(), nullptr, &hints, &res) != 0 || !res)
            throw CouplerError("coupling: unknown host '" + host + "'");
        a.sin_addr = reinterpret_cast<sockaddr_in*>(res->ai_addr)->sin_addr;
        freeaddrinfo(res);
    }
    return a;
}

std::unique_ptr<Transport> listenSocket(const Options& o)
{
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) throw CouplerError(std::string("coupling: socket(): ") + std::strerror(errno));
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a = address(o.host, o.port);
    if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(fd, 1) != 0) {
        const std::string why = std::strerror(errno);
        ::close(fd);
        throw CouplerError("coupling: cannot listen on " + o.host + ":" + std::to_string(o.port) + ": " + why);
    }
    socklen_t len = sizeof a;
    getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    const int port = ntohs(a.sin_port);
    if (!o.portFile.empty()) {
        const std::string text = std::to_string(port) + "\n";
        writeFileAtomically(o.portFile, text.data(), text.size());
    }
    pollfd p = {fd, POLLIN, 0};
    const double deadline = now() + o.connectTimeout;
    int r = 0;
    while ((r = ::poll(&p, 1, int(std::max(0.0, deadline - now()) * 1000))) < 0 && errno == EINTR) {}
    if (r <= 0) {
        ::close(fd);
        if (!o.portFile.empty()) std::remove(o.portFile.c_str());
        throw CouplerError("coupling: no peer connected to " + o.host + ":" + std::to_string(port) + " within " +
                           seconds(o.connectTimeout) + " (connectTimeout): is the " + o.name + " running?");
    }
    const int conn = ::accept(fd, nullptr, nullptr);
    ::close(fd);
    if (!o.portFile.empty()) std::remove(o.portFile.c_str());
    if (conn < 0) throw CouplerError(std::string("coupling: accept(): ") + std::strerror(errno));
    return std::unique_ptr<Transport>(new Socket(o, conn, o.host + ":" + std::to_string(port)));
}

std::unique_ptr<Transport> connectSocket(const Options& o)
{
    const double deadline = now() + o.connectTimeout;
    std::string lastProblem = "nothing tried";
    while (true) {
        int port = o.port;
        bool havePort = true;
        if (!o.portFile.empty()) {
            std::vector<unsigned char> bytes;
            havePort = readFile(o.portFile, bytes) && !bytes.empty();
            if (havePort) port = std::atoi(std::string(bytes.begin(), bytes.end()).c_str());
            else lastProblem = "port file " + o.portFile + " not there";
        }
        if (havePort && port > 0) {
            const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
            sockaddr_in a = address(o.host, port);
            if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0)
                return std::unique_ptr<Transport>(new Socket(o, fd, o.host + ":" + std::to_string(port)));
            lastProblem = o.host + ":" + std::to_string(port) + ": " + std::strerror(errno);
            ::close(fd);
        }
        if (now() > deadline)
            throw CouplerError("coupling: could not connect to the " + o.name + " within " + seconds(o.connectTimeout) +
                               " (connect_timeout; last: " + lastProblem + "): is it running?");
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
}

// ---- file -----------------------------------------------------------------------------------------
class Directory : public Base {
public:
    Directory(const Options& o, const std::string& me, const std::string& peer) : Base(o), me_(me), peer_(peer) {}
    void close() noexcept override {}
    std::string describe() const override { return "file " + options_.directory; }

protected:
    std::string path(uint64_t seq, const std::string& who) const
    {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%08llu", (unsigned long long)seq);
        return options_.directory + "/" + buf + "." + who + ".msg";
    }
    void sendBytes(const std::vector<unsigned char>& bytes) override
    {
        writeFileAtomically(path(++sent_, me_), bytes.data(), bytes.size());
    }
    std::vector<unsigned char> receiveBytes(double timeout) override
    {
        const std::string file = path(received_ + 1, peer_);
        const double deadline = now() + timeout;
        std::vector<unsigned char> bytes;
        while (!readFile(file, bytes)) {
            if (now() > deadline)
                throw CouplerError("coupling: " + file + " did not appear within " + seconds(timeout) + ": is the " +
                                   options_.name + " running?");
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        ++received_;
        return bytes;
    }

private:
    std::string me_, peer_;
    uint64_t sent_ = 0, received_ = 0;
};

void prepareDirectory(const Options& o, bool clean)
{
    if (o.directory.empty()) throw CouplerError("coupling: the file transport needs a directory");
    ::mkdir(o.directory.c_str(), 0755);
    struct stat st;
    if (::stat(o.directory.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
        throw CouplerError("coupling: cannot create directory " + o.directory);
    if (clean) {
        // Messages of an earlier run would be taken for this one's.
        for (uint64_t seq = 1;; ++seq) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%08llu", (unsigned long long)seq);
            const std::string base = o.directory + "/" + buf;
            const bool a = std::remove((base + ".fluid.msg").c_str()) == 0;
            const bool b = std::remove((base + ".dem.msg").c_str()) == 0;
            if (!a && !b) break;
        }
    }
}

}  // namespace

std::unique_ptr<Transport> listen(const Options& o)
{
    if (o.transport == "socket") return listenSocket(o);
    if (o.transport == "file") {
        prepareDirectory(o, true);
        return std::unique_ptr<Transport>(new Directory(o, "fluid", "dem"));
    }
    throw CouplerError("coupling: unknown transport '" + o.transport + "' (socket or file)");
}

std::unique_ptr<Transport> connect(const Options& o)
{
    if (o.transport == "socket") return connectSocket(o);
    if (o.transport == "file") {
        prepareDirectory(o, false);
        return std::unique_ptr<Transport>(new Directory(o, "dem", "fluid"));
    }
    throw CouplerError("coupling: unknown transport '" + o.transport + "' (socket or file)");
}

}  // namespace coupler
}  // namespace fdm
