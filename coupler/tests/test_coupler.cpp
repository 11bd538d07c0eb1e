// Unit tests of the coupler: wire format, both transports, and every failure a user can meet.
#include "fdm/coupler.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <thread>
#include <unistd.h>

using namespace fdm::coupler;

namespace {
double since(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
std::string tempPath(const std::string& name)
{
    return "/tmp/fdmCouplerTest." + std::to_string(getpid()) + "." + name;
}
// Both ends of a socket connection: the listening end accepts in a thread.
struct Connection {
    std::unique_ptr<Transport> server, client;
};
Connection connectedPair(const Options& o)
{
    Connection c;
    std::thread t([&] { c.server = listen(o); });
    c.client = connect(o);
    t.join();
    return c;
}
Message sample()
{
    Message m = makeMessage(MessageType::Integrals, 12, 3, 2, layout::integralsWidth, "dt=0.5 lastStep=9");
    for (size_t i = 0; i < m.data.size(); ++i) m.data[i] = 1.0 / (i + 1) - 0.25;
    return m;
}
}  // namespace

TEST(Message, RoundTripIsExact)
{
    const Message m = sample();
    const std::vector<unsigned char> bytes = encode(m);
    const Message back = decode(bytes.data(), bytes.size());
    EXPECT_EQ(back.type, m.type);
    EXPECT_EQ(back.step, 12u);
    EXPECT_EQ(back.iteration, 3u);
    EXPECT_EQ(back.count, 2u);
    EXPECT_EQ(back.text, m.text);
    EXPECT_EQ(back.data, m.data);  // bit-exact
    EXPECT_DOUBLE_EQ(back.textNumber("dt"), 0.5);
    EXPECT_THROW(back.textNumber("missing"), CouplerError);
}

TEST(Message, MalformedInputIsRejected)
{
    std::vector<unsigned char> bytes = encode(sample());
    std::vector<unsigned char> bad = bytes;
    bad[0] = 'X';
    EXPECT_THROW(decode(bad.data(), bad.size()), CouplerError);
    bad = bytes;
    bad[4] = protocolVersion + 1;
    try {
        decode(bad.data(), bad.size());
        FAIL() << "version mismatch accepted";
    } catch (const CouplerError& e) {
        EXPECT_NE(std::string(e.what()).find("version " + std::to_string(protocolVersion + 1)), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("version " + std::to_string(protocolVersion)), std::string::npos);
    }
    EXPECT_THROW(decode(bytes.data(), bytes.size() - 3), CouplerError);  // truncated
    EXPECT_THROW(decode(bytes.data(), 10), CouplerError);
    bad = bytes;
    bad[23] = 0x7f;  // absurd record count
    EXPECT_THROW(decode(bad.data(), bad.size()), CouplerError);
}

TEST(Socket, PingPongBetweenThreads)
{
    Options o;
    o.portFile = tempPath("port");
    o.connectTimeout = 10;
    Connection c = connectedPair(o);
    std::unique_ptr<Transport>& server = c.server;
    std::unique_ptr<Transport>& client = c.client;
    client->send(sample());
    Message got = server->receive(MessageType::Integrals);
    EXPECT_EQ(got.data, sample().data);
    server->send(makeMessage(MessageType::Finish, 1, 0, 0, 0));
    EXPECT_EQ(client->receive().type, MessageType::Finish);
    server->close();
    EXPECT_THROW(client->receive(MessageType::Step), CouplerError);  // the peer is gone
}

TEST(Socket, PeerThatNeverConnects)
{
    Options o;
    o.portFile = tempPath("never");
    o.connectTimeout = 1;
    const auto t0 = std::chrono::steady_clock::now();
    try {
        listen(o);
        FAIL();
    } catch (const CouplerError& e) {
        EXPECT_NE(std::string(e.what()).find("no peer connected"), std::string::npos);
    }
    EXPECT_LT(since(t0), 3.0);
    const auto t1 = std::chrono::steady_clock::now();
    EXPECT_THROW(connect(o), CouplerError);  // no port file
    EXPECT_LT(since(t1), 3.0);
}

TEST(Socket, PeerThatDiesIsDetectedAtOnce)
{
    Options o;
    o.portFile = tempPath("dies");
    o.receiveTimeout = 60;
    Connection c = connectedPair(o);
    std::unique_ptr<Transport>& server = c.server;
    std::unique_ptr<Transport>& client = c.client;
    client->close();  // as when the process dies: the kernel closes the socket
    const auto t0 = std::chrono::steady_clock::now();
    try {
        server->receive();
        FAIL();
    } catch (const CouplerError& e) {
        EXPECT_NE(std::string(e.what()).find("closed the connection"), std::string::npos);
    }
    EXPECT_LT(since(t0), 1.0);
}

TEST(Socket, SilentPeerTimesOut)
{
    Options o;
    o.portFile = tempPath("silent");
    o.receiveTimeout = 0.5;
    Connection c = connectedPair(o);
    std::unique_ptr<Transport>& server = c.server;
    std::unique_ptr<Transport>& client = c.client;
    client->send(sample());
    server->receive();  // the first receive uses connectTimeout
    EXPECT_THROW(server->receive(), CouplerError);
}

TEST(Socket, ErrorMessageCarriesItsText)
{
    Options o;
    o.portFile = tempPath("error");
    o.name = "particle code";
    Connection c = connectedPair(o);
    std::unique_ptr<Transport>& server = c.server;
    std::unique_ptr<Transport>& client = c.client;
    client->sendError("particle 7 overlaps particle 9");
    try {
        server->receive();
        FAIL();
    } catch (const CouplerError& e) {
        EXPECT_NE(std::string(e.what()).find("particle 7 overlaps particle 9"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("particle code"), std::string::npos);
    }
}

TEST(File, RoundTripAndRecord)
{
    Options o;
    o.transport = "file";
    o.directory = tempPath("dir");
    o.connectTimeout = 2;
    o.receiveTimeout = 2;
    std::unique_ptr<Transport> fluid = listen(o);
    Options od = o;
    od.recordFile = tempPath("record");
    std::remove(od.recordFile.c_str());
    std::unique_ptr<Transport> dem = connect(od);
    dem->send(sample());
    EXPECT_EQ(fluid->receive().data, sample().data);
    fluid->send(makeMessage(MessageType::StepDone, 12, 4, 0, 0, "iterations=4"));
    EXPECT_EQ(dem->receive().text, "iterations=4");
    EXPECT_THROW(dem->receive(), CouplerError);  // nothing more within receiveTimeout
    FILE* f = std::fopen(od.recordFile.c_str(), "rb");
    ASSERT_TRUE(f != nullptr);
    std::fclose(f);
}
