// Message format of the fdm coupler (docs/coupling.md): a 40-byte little-endian header, the text,
// then count*width doubles.
#include "fdm/coupler.h"

#include <cstring>
#include <sstream>

namespace fdm {
namespace coupler {

namespace {
const char magic[4] = {'F', 'D', 'M', 'C'};
// Sanity limits: a corrupted header must give an error, not a huge allocation. The largest real
// record is the fluid Hello's 38 doubles (per particle: 13, StepDone with stresslets); 2^25 values
// (256 MiB) is 2.5 million particles of 13.
const uint32_t maxWidth = 64;
const uint64_t maxValues = 1ULL << 25;
const uint32_t maxText = 1u << 20;

template <class T> void put(std::vector<unsigned char>& b, size_t at, T v)
{
    for (size_t i = 0; i < sizeof(T); ++i) b[at + i] = (unsigned char)((uint64_t(v) >> (8 * i)) & 0xff);
}
template <class T> T get(const unsigned char* b, size_t at)
{
    uint64_t v = 0;
    for (size_t i = 0; i < sizeof(T); ++i) v |= uint64_t(b[at + i]) << (8 * i);
    return T(v);
}
}  // namespace

const char* messageTypeName(MessageType t)
{
    switch (t) {
        case MessageType::Hello: return "Hello";
        case MessageType::Step: return "Step";
        case MessageType::Volumes: return "Volumes";
        case MessageType::Integrals: return "Integrals";
        case MessageType::Velocities: return "Velocities";
        case MessageType::StepDone: return "StepDone";
        case MessageType::Finish: return "Finish";
        case MessageType::Error: return "Error";
    }
    return "unknown";
}

std::string Message::textValue(const std::string& key) const
{
    std::istringstream is(text);
    std::string token;
    while (is >> token) {
        const size_t eq = token.find('=');
        if (eq != std::string::npos && token.compare(0, eq, key) == 0 && eq == key.size())
            return token.substr(eq + 1);
    }
    throw CouplerError(std::string("coupling: ") + messageTypeName(type) + " message has no '" + key +
                       "=' entry (text: \"" + text + "\")");
}

double Message::textNumber(const std::string& key) const
{
    const std::string v = textValue(key);
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (end == v.c_str() || *end != '\0')
        throw CouplerError(std::string("coupling: ") + messageTypeName(type) + " entry " + key + "=" + v +
                           " is not a number");
    return x;
}

Message makeMessage(MessageType type, uint64_t step, uint32_t iteration, uint32_t count, uint32_t width,
                    const std::string& text)
{
    Message m;
    m.type = type;
    m.step = step;
    m.iteration = iteration;
    m.count = count;
    m.width = width;
    m.text = text;
    m.data.assign(size_t(count) * width, 0.0);
    return m;
}

std::vector<unsigned char> encode(const Message& m)
{
    if (m.data.size() != size_t(m.count) * m.width)
        throw CouplerError("coupling: cannot send a message whose data size does not match count*width");
    if (m.width > maxWidth || m.data.size() > maxValues || m.text.size() > maxText)
        throw CouplerError(std::string("coupling: ") + messageTypeName(m.type) +
                           " message too large for the wire format (" + std::to_string(m.count) + " records of " +
                           std::to_string(m.width) + " values, text " + std::to_string(m.text.size()) + " bytes)");
    std::vector<unsigned char> b(headerSize + m.text.size() + 8 * m.data.size());
    std::memcpy(&b[0], magic, 4);
    put<uint16_t>(b, 4, protocolVersion);
    put<uint16_t>(b, 6, uint16_t(m.type));
    put<uint64_t>(b, 8, m.step);
    put<uint32_t>(b, 16, m.iteration);
    put<uint32_t>(b, 20, m.count);
    put<uint32_t>(b, 24, m.width);
    put<uint32_t>(b, 28, uint32_t(m.text.size()));
    put<uint64_t>(b, 32, uint64_t(m.data.size()));
    if (!m.text.empty()) std::memcpy(&b[headerSize], m.text.data(), m.text.size());
    size_t at = headerSize + m.text.size();
    for (double x : m.data) {
        uint64_t bits;
        std::memcpy(&bits, &x, 8);
        put<uint64_t>(b, at, bits);
        at += 8;
    }
    return b;
}

// Header only: how many bytes the whole message has; throws if the header is malformed.
size_t encodedSize(const unsigned char* header)
{
    if (std::memcmp(header, magic, 4) != 0)
        throw CouplerError("coupling: malformed message (bad magic): the peer is not an fdm coupler");
    const uint16_t version = get<uint16_t>(header, 4);
    if (version != protocolVersion)
        throw CouplerError("coupling: protocol version mismatch: the peer speaks version " + std::to_string(version) +
                           ", this side speaks version " + std::to_string(protocolVersion));
    const uint16_t type = get<uint16_t>(header, 6);
    if (type < uint16_t(MessageType::Hello) || type > uint16_t(MessageType::Volumes))  // 1..8, Volumes the newest
        throw CouplerError("coupling: malformed message (unknown type " + std::to_string(type) + ")");
    const uint32_t count = get<uint32_t>(header, 20), width = get<uint32_t>(header, 24);
    const uint32_t textLength = get<uint32_t>(header, 28);
    const uint64_t payload = get<uint64_t>(header, 32);
    if (width > maxWidth || payload > maxValues || textLength > maxText || payload != uint64_t(count) * width)
        throw CouplerError("coupling: malformed message (absurd or inconsistent sizes: count " + std::to_string(count) + ", width " +
                           std::to_string(width) + ", text " + std::to_string(textLength) + " bytes, payload " +
                           std::to_string(payload) + " values)");
    return headerSize + textLength + 8 * payload;
}

Message decode(const unsigned char* bytes, size_t size)
{
    if (size < headerSize) throw CouplerError("coupling: malformed message (truncated header)");
    const size_t total = encodedSize(bytes);
    if (size != total)
        throw CouplerError("coupling: malformed message (" + std::to_string(size) + " bytes where the header says " +
                           std::to_string(total) + ")");
    Message m;
    m.type = MessageType(get<uint16_t>(bytes, 6));
    m.step = get<uint64_t>(bytes, 8);
    m.iteration = get<uint32_t>(bytes, 16);
    m.count = get<uint32_t>(bytes, 20);
    m.width = get<uint32_t>(bytes, 24);
    const uint32_t textLength = get<uint32_t>(bytes, 28);
    m.text.assign(reinterpret_cast<const char*>(bytes + headerSize), textLength);
    m.data.resize(size_t(m.count) * m.width);
    size_t at = headerSize + textLength;
    for (double& x : m.data) {
        const uint64_t bits = get<uint64_t>(bytes, at);
        std::memcpy(&x, &bits, 8);
        at += 8;
    }
    return m;
}

void Transport::sendError(const std::string& why) noexcept
{
    try {
        Error e;
        e.text = why;
        send(e.toMessage());
    } catch (...) {
    }
}

}  // namespace coupler
}  // namespace fdm
