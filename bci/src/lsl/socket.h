// The few socket operations LSL needs (IPv4): RAII descriptors, binding within liblsl's port
// range, UDP datagrams and a buffered TCP stream with deadlines. Every wait is bounded.
#pragma once

#include <netinet/in.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

namespace arbci::bci::lsl::net {

class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() { reset(); }
  Fd(Fd&& other) noexcept : fd_(other.release()) {}
  Fd& operator=(Fd&& other) noexcept;
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  explicit operator bool() const { return fd_ >= 0; }
  int release();
  void reset();
  // Shuts both directions down so a thread blocked on it wakes (the descriptor stays open).
  void shutdown() const;

 private:
  int fd_ = -1;
};

sockaddr_in endpoint(const std::string& address, int port);  // throws LslError
std::string addressText(const sockaddr_in& a);

// A UDP socket bound to `address` at a port in [base, base + range), or any port when
// `allow_random` and the range is full; `reuse` lets several outlets share a discovery port.
Fd udpSocket();
int bindInRange(const Fd& fd, const std::string& address, int base, int range, bool allow_random);
void bindExact(const Fd& fd, const std::string& address, int port, bool reuse);
Fd tcpListener(const std::string& address, int base, int range, bool allow_random, int* port);
// Connects within `timeout_s`; throws LslError naming the endpoint.
Fd tcpConnect(const sockaddr_in& to, double timeout_s);

// Waits up to `timeout_s` for `fd` to be readable.
bool waitReadable(int fd, double timeout_s);

struct Datagram {
  std::string bytes;
  sockaddr_in from{};
};
std::optional<Datagram> receiveDatagram(const Fd& fd, double timeout_s);
void sendDatagram(const Fd& fd, const std::string& bytes, const sockaddr_in& to);

// A TCP stream read through a buffer. Reads wait at most `timeout_s` for each arrival and give
// up early when `stop` is set; both, and the peer closing, throw LslError.
class TcpStream {
 public:
  explicit TcpStream(Fd fd) : fd_(std::move(fd)) {}
  void setStop(const std::atomic<bool>* stop) { stop_ = stop; }
  void read(void* into, size_t bytes, double timeout_s);
  std::uint8_t readByte(double timeout_s);
  // Up to and including "\n" (the "\r\n" stripped); throws past `max_bytes`.
  std::string readLine(double timeout_s, size_t max_bytes = 16384);
  // Everything until the peer closes (at most `max_bytes`).
  std::string readAll(double timeout_s, size_t max_bytes = 1 << 24);
  void writeAll(const void* data, size_t bytes, double timeout_s);
  void writeAll(const std::string& text, double timeout_s) {
    writeAll(text.data(), text.size(), timeout_s);
  }
  const Fd& fd() const { return fd_; }
  // Bytes received and not yet read.
  size_t buffered() const { return end_ - begin_; }

 private:
  bool fill(double timeout_s);  // false: the peer closed
  Fd fd_;
  const std::atomic<bool>* stop_ = nullptr;
  char buffer_[1 << 16];
  size_t begin_ = 0, end_ = 0;
};

}  // namespace arbci::bci::lsl::net
