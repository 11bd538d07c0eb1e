// Transports of the fdm coupler: a TCP socket between the two master ranks, or a directory of
// message files (debugging, replay). Every failure is a CouplerError meant for the user.
#include "fdm/coupler.h"

#include <algorithm>
#include <arpa/inet.h>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <fstream>
#include <iterator>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sstream>
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

int pollMilliseconds(double deadline)
{
    // poll() in slices of at most 1 s so that EINTR or a clock jump never stretches a timeout
    const double left = deadline - now();
    return left <= 0 ? 0 : int(std::min(left, 1.0) * 1000) + 1;
}

std::string hostName()
{
    char buf[256] = {0};
    if (gethostname(buf, sizeof buf - 1) != 0) return "unknown";
    return buf;
}

void writeFileAtomically(const std::string& path, const void* data, size_t size)
{
    // The reader must never see a half-written file: write a private temporary, then rename.
    const std::string tmp = path + ".tmp" + std::to_string(getpid());
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw CouplerError("coupling: cannot write " + tmp + ": " + std::strerror(errno));
    const bool ok = std::fwrite(data, 1, size, f) == size;
    if (std::fclose(f) != 0 || !ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string why = std::strerror(errno);
        std::remove(tmp.c_str());
        throw CouplerError("coupling: cannot write " + path + ": " + why);
    }
}

bool readFile(const std::string& path, std::vector<unsigned char>& bytes)
{
    std::ifstream in(path.c_str(), std::ios::binary);
    if (!in) return false;
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

// Common part of both transports: timeouts, recording, Error messages from the peer.
class Base : public Transport {
public:
    explicit Base(const Options& o) : options_(o), record_(nullptr), handshakeDone_(false)
    {
        if (!o.recordFile.empty()) {
            record_ = std::fopen(o.recordFile.c_str(), "ab");
            if (!record_)
                throw CouplerError("coupling: cannot open the record file " + o.recordFile + ": " +
                                   std::strerror(errno));
        }
    }
    ~Base() override
    {
        if (record_) std::fclose(record_);
    }
    void send(const Message& m) override
    {
        const std::vector<unsigned char> bytes = encode(m);
        sendBytes(bytes);
        record(bytes);
    }
    Message receive() override
    {
        // Until the peer's first message (its Hello) the peer may still be starting up: the
        // handshake is bounded by connectTimeout, later messages by receiveTimeout.
        std::vector<unsigned char> bytes = receiveBytes();
        handshakeDone_ = true;
        record(bytes);
        Message m = decode(bytes.data(), bytes.size());
        if (m.type == MessageType::Error) throw CouplerError("the " + options_.name + " stopped: " + m.text);
        return m;
    }
    const std::string& peerName() const { return options_.name; }

protected:
    virtual void sendBytes(const std::vector<unsigned char>& bytes) = 0;
    virtual std::vector<unsigned char> receiveBytes() = 0;

    double receiveTimeout() const { return handshakeDone_ ? options_.receiveTimeout : options_.connectTimeout; }
    CouplerError peerClosed() const
    {
        return CouplerError("coupling: the " + options_.name +
                            " closed the connection (did it crash? see its log)");
    }
    CouplerError peerSilent() const
    {
        if (!handshakeDone_)
            return CouplerError("coupling: the " + options_.name + " did not complete the handshake within " +
                                seconds(options_.connectTimeout) + " (connect timeout)");
        return CouplerError("coupling: the " + options_.name + " sent nothing for " +
                            seconds(options_.receiveTimeout) + " (receive timeout): is it hung?");
    }
    void record(const std::vector<unsigned char>& bytes)
    {
        if (!record_) return;
        // flushed at once: after a crash the record holds every message up to it
        if (std::fwrite(bytes.data(), 1, bytes.size(), record_) != bytes.size() || std::fflush(record_) != 0)
            throw CouplerError("coupling: cannot append to the record file " + options_.recordFile + ": " +
                               std::strerror(errno));
    }

    Options options_;
    FILE* record_;
    bool handshakeDone_;
};

// ---- socket ---------------------------------------------------------------------------------------
class Socket : public Base {
public:
    Socket(const Options& o, int fd, const std::string& where) : Base(o), fd_(fd), where_(where)
    {
        int one = 1;
        setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // small messages, ping-pong
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
        if (fd_ < 0) throw CouplerError("coupling: send on a closed connection to the " + options_.name);
        const double deadline = now() + options_.receiveTimeout;
        size_t done = 0;
        while (done < bytes.size()) {
            pollfd p = {fd_, POLLOUT, 0};
            const int r = ::poll(&p, 1, pollMilliseconds(deadline));
            if (r < 0 && errno != EINTR) throw CouplerError(std::string("coupling: poll(): ") + std::strerror(errno));
            if (r <= 0) {
                if (now() >= deadline)
                    throw CouplerError("coupling: the " + options_.name + " has not read for " +
                                       seconds(options_.receiveTimeout) + " (receive timeout): is it hung?");
                continue;
            }
            // MSG_NOSIGNAL: a dead peer must give an error here, not a SIGPIPE that kills us silently
            const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL | MSG_DONTWAIT);
            if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
            if (n < 0 && (errno == EPIPE || errno == ECONNRESET)) throw peerClosed();
            if (n <= 0) throw CouplerError(std::string("coupling: send(): ") + std::strerror(errno));
            done += size_t(n);
        }
    }
    std::vector<unsigned char> receiveBytes() override
    {
        if (fd_ < 0) throw CouplerError("coupling: receive on a closed connection to the " + options_.name);
        const double deadline = now() + receiveTimeout();
        std::vector<unsigned char> bytes(headerSize);
        readExactly(bytes.data(), headerSize, deadline);
        const size_t total = encodedSize(bytes.data());
        // Grow as the bytes arrive: a lying header cannot make us allocate what was never sent.
        const size_t chunk = size_t(16) << 20;
        while (bytes.size() < total) {
            const size_t have = bytes.size(), want = std::min(total - have, chunk);
            bytes.resize(have + want);
            readExactly(bytes.data() + have, want, deadline);
        }
        return bytes;
    }

private:
    void readExactly(unsigned char* to, size_t size, double deadline)
    {
        size_t done = 0;
        while (done < size) {
            pollfd p = {fd_, POLLIN, 0};
            const int r = ::poll(&p, 1, pollMilliseconds(deadline));
            if (r < 0 && errno != EINTR) throw CouplerError(std::string("coupling: poll(): ") + std::strerror(errno));
            if (r <= 0) {
                if (now() >= deadline) throw peerSilent();
                continue;
            }
            const ssize_t n = ::recv(fd_, to + done, size - done, MSG_DONTWAIT);
            if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
            if (n == 0 || (n < 0 && errno == ECONNRESET)) throw peerClosed();
            if (n < 0) throw CouplerError(std::string("coupling: recv(): ") + std::strerror(errno));
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
        hints.ai_socktype = SOCK_STREAM;
        if (getaddrinfo(host.c_str(), nullptr, &hints, &res) != 0 || !res)
            throw CouplerError("coupling: unknown host '" + host + "'");
        a.sin_addr = reinterpret_cast<sockaddr_in*>(res->ai_addr)->sin_addr;
        freeaddrinfo(res);
    }
    return a;
}

std::unique_ptr<Transport> listenSocket(const Options& o)
{
    if (o.port < 0 || o.port > 65535) throw CouplerError("coupling: port " + std::to_string(o.port) + " out of range");
    const sockaddr_in wanted = address(o.host, o.port);
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) throw CouplerError(std::string("coupling: socket(): ") + std::strerror(errno));
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);  // restart at once on a fixed port
    sockaddr_in a = wanted;
    if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(fd, 1) != 0) {
        const std::string why = std::strerror(errno);
        ::close(fd);
        throw CouplerError("coupling: cannot listen on " + o.host + ":" + std::to_string(o.port) + ": " + why);
    }
    socklen_t len = sizeof a;
    getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    const int port = ntohs(a.sin_port);
    const std::string where = o.host + ":" + std::to_string(port);
    try {
        if (!o.portFile.empty()) {
            const std::string text = std::to_string(port) + "\n";
            writeFileAtomically(o.portFile, text.data(), text.size());
        }
    } catch (...) {
        ::close(fd);
        throw;
    }
    const double deadline = now() + o.connectTimeout;
    int conn = -1;
    std::string acceptError;
    while (conn < 0 && acceptError.empty() && now() < deadline) {
        pollfd p = {fd, POLLIN, 0};
        const int r = ::poll(&p, 1, pollMilliseconds(deadline));
        if (r < 0 && errno != EINTR) acceptError = std::string("poll(): ") + std::strerror(errno);
        if (r <= 0) continue;
        conn = ::accept(fd, nullptr, nullptr);
        if (conn < 0 && errno != EINTR && errno != ECONNABORTED)
            acceptError = std::string("accept(): ") + std::strerror(errno);
    }
    ::close(fd);
    // the port is not listened on any more: a port file left behind would mislead the next peer
    if (!o.portFile.empty()) std::remove(o.portFile.c_str());
    if (conn < 0) {
        if (acceptError.empty())
            throw CouplerError("coupling: no peer connected to " + where + " within " + seconds(o.connectTimeout) +
                               " (connect timeout): is the " + o.name + " running?" +
                               (o.portFile.empty() ? "" : " (it reads the port from " + o.portFile + ")"));
        throw CouplerError("coupling: waiting for a peer on " + where + ": " + acceptError);
    }
    return std::unique_ptr<Transport>(new Socket(o, conn, where));
}

// One non-blocking connect attempt bounded by `deadline`; returns the socket or -1 (why in `problem`).
int tryConnect(const sockaddr_in& a, double deadline, std::string& problem)
{
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) throw CouplerError(std::string("coupling: socket(): ") + std::strerror(errno));
    const int flags = fcntl(fd, F_GETFL, 0);
    fcntl(fd, F_SETFL, flags | O_NONBLOCK);
    int error = 0;
    if (::connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
        error = errno;
        if (error == EINPROGRESS) {
            // a host that drops SYNs would otherwise block us for minutes
            pollfd p = {fd, POLLOUT, 0};
            int r;
            while ((r = ::poll(&p, 1, pollMilliseconds(deadline))) == 0 && now() < deadline) {}
            socklen_t len = sizeof error;
            if (r > 0) getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &len);
            else error = ETIMEDOUT;
        }
    }
    if (error != 0) {
        problem = std::strerror(error);
        ::close(fd);
        return -1;
    }
    fcntl(fd, F_SETFL, flags);
    return fd;
}

std::unique_ptr<Transport> connectSocket(const Options& o)
{
    const double deadline = now() + o.connectTimeout;
    std::string where = o.host + ":" + std::to_string(o.port), problem = "nothing tried";
    while (true) {
        int port = o.port;
        if (!o.portFile.empty()) {
            std::vector<unsigned char> bytes;
            port = 0;
            if (!readFile(o.portFile, bytes)) {
                problem = "no port file " + o.portFile + " yet";
            } else {
                const std::string text(bytes.begin(), bytes.end());
                char* end = nullptr;
                const long p = std::strtol(text.c_str(), &end, 10);
                if (end == text.c_str() || p <= 0 || p > 65535)
                    problem = "port file " + o.portFile + " holds no port number: \"" + text.substr(0, 40) + "\"";
                else
                    port = int(p);
            }
        } else if (port <= 0 || port > 65535) {
            throw CouplerError("coupling: no valid port to connect to (port " + std::to_string(port) +
                               ", no port file)");
        }
        if (port > 0) {
            where = o.host + ":" + std::to_string(port);
            const int fd = tryConnect(address(o.host, port), std::min(deadline, now() + 2.0), problem);
            if (fd >= 0) return std::unique_ptr<Transport>(new Socket(o, fd, where));
            problem = where + ": " + problem;
        }
        if (now() >= deadline)
            throw CouplerError("coupling: could not connect to the " + o.name + " within " +
                               seconds(o.connectTimeout) + " (connect timeout; last attempt: " + problem +
                               "): is it running?");
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
}

// ---- file -----------------------------------------------------------------------------------------
// A directory shared by the two codes. Message k of a side is the file <k>.<side>.msg, written
// atomically. Each side also writes <side>.session ("session=<id> pid=<pid> host=<host>"): the
// listener (fluid) cleans the directory and writes its session first; the connector (dem) adopts
// that id. The session files tell a stale directory of an earlier run from a live peer, and let a
// side on the same host notice at once that the other process is gone.
struct Session {
    std::string id, host;
    long pid = 0;
    bool read(const std::string& path)
    {
        std::vector<unsigned char> bytes;
        if (!readFile(path, bytes)) return false;
        std::istringstream in(std::string(bytes.begin(), bytes.end()));
        std::string token;
        while (in >> token) {
            if (token.compare(0, 8, "session=") == 0) id = token.substr(8);
            else if (token.compare(0, 4, "pid=") == 0) pid = std::atol(token.c_str() + 4);
            else if (token.compare(0, 5, "host=") == 0) host = token.substr(5);
        }
        return !id.empty();
    }
    void write(const std::string& path) const
    {
        const std::string text = "session=" + id + " pid=" + std::to_string(pid) + " host=" + host + "\n";
        writeFileAtomically(path, text.data(), text.size());
    }
    // False only when we can tell for sure: same host, and no such process.
    bool alive() const
    {
        if (host != hostName() || pid <= 0) return true;
        return ::kill(pid_t(pid), 0) == 0 || errno == EPERM;
    }
};

class Directory : public Base {
public:
    Directory(const Options& o, bool listener) :
        Base(o), listener_(listener), me_(listener ? "fluid" : "dem"), peer_(listener ? "dem" : "fluid"),
        sent_(0), received_(0)
    {
        mine_.pid = getpid();
        mine_.host = hostName();
        listener_ ? listen() : connect();
    }
    void close() noexcept override {}
    std::string describe() const override { return "file transport in " + options_.directory; }

protected:
    std::string messagePath(uint64_t seq, const std::string& who) const
    {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%08llu", (unsigned long long)seq);
        return options_.directory + "/" + buf + "." + who + ".msg";
    }
    std::string sessionPath(const std::string& who) const { return options_.directory + "/" + who + ".session"; }

    void sendBytes(const std::vector<unsigned char>& bytes) override
    {
        writeFileAtomically(messagePath(++sent_, me_), bytes.data(), bytes.size());
        if (!handshakeDone_ && !listener_) unanswered_.push_back(bytes);
    }
    std::vector<unsigned char> receiveBytes() override
    {
        const std::string file = messagePath(received_ + 1, peer_);
        const double deadline = now() + receiveTimeout();
        double nextCheck = now() + 0.25, sleep = 50e-6;
        std::vector<unsigned char> bytes;
        while (!readFile(file, bytes)) {
            const double t = now();
            if (t >= nextCheck) {
                nextCheck = t + 0.25;
                checkPeer();
                if (readFile(file, bytes)) break;  // it may have written and ended meanwhile
            }
            if (t >= deadline) throw peerSilent();
            std::this_thread::sleep_for(std::chrono::duration<double>(sleep));
            sleep = std::min(2 * sleep, 5e-3);
        }
        ++received_;
        unanswered_.clear();
        return bytes;
    }

private:
    void prepareDirectory()
    {
        if (options_.directory.empty()) throw CouplerError("coupling: the file transport needs a directory");
        ::mkdir(options_.directory.c_str(), 0755);
        struct stat st;
        if (::stat(options_.directory.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
            throw CouplerError("coupling: cannot create the coupling directory " + options_.directory);
    }
    void listen()
    {
        prepareDirectory();
        // Messages of an earlier run would be taken for this one's.
        if (DIR* d = opendir(options_.directory.c_str())) {
            while (dirent* e = readdir(d)) {
                const std::string name = e->d_name;
                const bool ours = name.find(".msg") != std::string::npos || name.find(".session") != std::string::npos;
                if (ours) std::remove((options_.directory + "/" + name).c_str());
            }
            closedir(d);
        }
        mine_.id = mine_.host + "-" + std::to_string(mine_.pid) + "-" +
                   std::to_string((long long)(std::chrono::system_clock::now().time_since_epoch().count()));
        mine_.write(sessionPath(me_));
        // wait for the connector to join this session
        const double deadline = now() + options_.connectTimeout;
        Session peer;
        while (!(peer.read(sessionPath(peer_)) && peer.id == mine_.id && peer.alive())) {
            if (now() >= deadline)
                throw CouplerError("coupling: no peer joined the coupling directory " + options_.directory +
                                   " within " + seconds(options_.connectTimeout) + " (connect timeout): is the " +
                                   options_.name + " running?");
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    }
    void connect()
    {
        prepareDirectory();
        const double deadline = now() + options_.connectTimeout;
        Session peer;
        while (!(peer.read(sessionPath(peer_)) && peer.alive())) {
            if (now() >= deadline)
                throw CouplerError("coupling: the " + options_.name + " did not open the coupling directory " +
                                   options_.directory + " within " + seconds(options_.connectTimeout) +
                                   " (connect timeout): is it running?");
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        join(peer);
    }
    void join(const Session& peer)
    {
        mine_.id = peer.id;
        mine_.write(sessionPath(me_));
    }
    void checkPeer()
    {
        Session peer;
        const bool there = peer.read(sessionPath(peer_));
        if (!listener_ && !handshakeDone_ && there && peer.id != mine_.id && peer.alive()) {
            // A listener started after we joined a stale session and cleaned the directory: join
            // the new session and send again what we had sent (only the Hello, in practice).
            join(peer);
            for (size_t k = 0; k < unanswered_.size(); ++k)
                writeFileAtomically(messagePath(k + 1, me_), unanswered_[k].data(), unanswered_[k].size());
            return;
        }
        if (there && peer.id == mine_.id && !peer.alive()) throw peerClosed();
        if (handshakeDone_ && (!there || peer.id != mine_.id))
            throw CouplerError("coupling: another run took over the coupling directory " + options_.directory +
                               " (the " + options_.name + "'s session file changed)");
    }

    bool listener_;
    std::string me_, peer_;
    uint64_t sent_, received_;
    Session mine_;
    std::vector<std::vector<unsigned char> > unanswered_;  // connector: sent before the peer's first reply
};

Base* asBase(Transport* t) { return dynamic_cast<Base*>(t); }

}  // namespace

Message Transport::receive(MessageType expected)
{
    Message m = receive();
    if (m.type != expected) {
        Base* base = asBase(this);
        throw CouplerError(std::string("coupling: expected ") + messageTypeName(expected) + " from the " +
                           (base ? base->peerName() : std::string("peer")) + ", got " + messageTypeName(m.type) +
                           " (step " + std::to_string(m.step) + ", iteration " + std::to_string(m.iteration) + ")");
    }
    return m;
}

std::unique_ptr<Transport> listen(const Options& o)
{
    if (o.transport == "socket") return listenSocket(o);
    if (o.transport == "file") return std::unique_ptr<Transport>(new Directory(o, true));
    throw CouplerError("coupling: unknown transport '" + o.transport + "' (socket or file)");
}

std::unique_ptr<Transport> connect(const Options& o)
{
    if (o.transport == "socket") return connectSocket(o);
    if (o.transport == "file") return std::unique_ptr<Transport>(new Directory(o, false));
    throw CouplerError("coupling: unknown transport '" + o.transport + "' (socket or file)");
}

}  // namespace coupler
}  // namespace fdm
