// A non-blocking IPv4 UDP socket, closed on destruction.
#pragma once

#include <netinet/in.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace arbci::robot {

class SocketError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Endpoint {
  sockaddr_in address{};
  std::string toString() const;
  bool operator==(const Endpoint& other) const;
  // "127.0.0.1" or a host name, resolved now; throws SocketError.
  static Endpoint resolve(const std::string& host, int port);
};

// This machine only: where a backend listens and sockets bind unless told otherwise.
inline constexpr const char* kLoopback = "127.0.0.1";

struct Datagram {
  std::vector<std::uint8_t> bytes;
  Endpoint from;
};

class UdpSocket {
 public:
  // Bound to `port` on `host` (0: any free port). Throws SocketError with the reason.
  // `host`: the address to bind (this machine only by default).
  explicit UdpSocket(int port = 0, const std::string& host = kLoopback);
  ~UdpSocket();
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;

  int port() const;
  // Asks the kernel for a receive buffer of `bytes` (it may grant less); returns what it granted.
  int setReceiveBuffer(int bytes);
  int receiveBuffer() const;
  void sendTo(const std::vector<std::uint8_t>& bytes, const Endpoint& to);
  // One datagram if any is waiting (never blocks).
  std::optional<Datagram> receive();
  // Waits up to `milliseconds` for a datagram to arrive.
  bool wait(int milliseconds);
  bool wait(std::chrono::microseconds timeout);  // finer, for deadlines

 private:
  int fd_ = -1;
};

}  // namespace arbci::robot
