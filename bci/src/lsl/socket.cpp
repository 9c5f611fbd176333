#include "lsl/socket.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "arbci/bci/lsl/config.h"

namespace arbci::bci::lsl::net {
namespace {

std::string systemError(const std::string& what) {
  return what + ": " + std::strerror(errno);
}

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

Fd& Fd::operator=(Fd&& other) noexcept {
  if (this != &other) {
    reset();
    fd_ = other.release();
  }
  return *this;
}

int Fd::release() {
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

void Fd::reset() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void Fd::shutdown() const {
  if (fd_ >= 0) ::shutdown(fd_, SHUT_RDWR);
}

sockaddr_in endpoint(const std::string& address, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (address.empty() || address == "0.0.0.0") {
    a.sin_addr.s_addr = htonl(INADDR_ANY);
  } else if (inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1) {
    throw LslError("\"" + address + "\" is not an IPv4 address");
  }
  return a;
}

std::string addressText(const sockaddr_in& a) {
  char text[INET_ADDRSTRLEN] = "";
  inet_ntop(AF_INET, &a.sin_addr, text, sizeof text);
  return text;
}

Fd udpSocket() {
  Fd fd(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  if (!fd) throw LslError(systemError("cannot open a UDP socket"));
  return fd;
}

int bindInRange(const Fd& fd, const std::string& address, int base, int range, bool allow_random) {
  for (int port = base; port < base + range && port <= 65535; ++port) {
    const sockaddr_in a = endpoint(address, port);
    if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0) return port;
  }
  if (allow_random) {
    sockaddr_in a = endpoint(address, 0);
    if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0) {
      socklen_t length = sizeof a;
      ::getsockname(fd.get(), reinterpret_cast<sockaddr*>(&a), &length);
      return ntohs(a.sin_port);
    }
  }
  throw LslError(
      "no free port in " + std::to_string(base) + "-" + std::to_string(base + range - 1) + " on " +
      address + " (more LSL streams than the configured PortRange, or another program holds them)");
}

void bindExact(const Fd& fd, const std::string& address, int port, bool reuse) {
  if (reuse) {
    const int one = 1;
    ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  }
  const sockaddr_in a = endpoint(address, port);
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0)
    throw LslError(systemError("cannot bind " + address + ":" + std::to_string(port)));
}

Fd tcpListener(const std::string& address, int base, int range, bool allow_random, int* port) {
  Fd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd) throw LslError(systemError("cannot open a TCP socket"));
  *port = bindInRange(fd, address, base, range, allow_random);
  if (::listen(fd.get(), 16) != 0) throw LslError(systemError("cannot listen for LSL clients"));
  return fd;
}

Fd tcpConnect(const sockaddr_in& to, double timeout_s) {
  Fd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!fd) throw LslError(systemError("cannot open a TCP socket"));
  const std::string where = addressText(to) + ":" + std::to_string(ntohs(to.sin_port));
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0) {
    if (errno != EINPROGRESS) throw LslError(systemError("cannot connect to " + where));
    pollfd p{fd.get(), POLLOUT, 0};
    if (::poll(&p, 1, static_cast<int>(timeout_s * 1000)) <= 0)
      throw LslError("no answer from " + where + " within " + std::to_string(timeout_s) + " s");
    int error = 0;
    socklen_t length = sizeof error;
    ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &error, &length);
    if (error != 0) {
      errno = error;
      throw LslError(systemError("cannot connect to " + where));
    }
  }
  ::fcntl(fd.get(), F_SETFL, ::fcntl(fd.get(), F_GETFL) & ~O_NONBLOCK);
  const int one = 1;
  ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

bool waitReadable(int fd, double timeout_s) {
  pollfd p{fd, POLLIN, 0};
  const int ms = timeout_s <= 0 ? 0 : static_cast<int>(timeout_s * 1000 + 0.999);
  return ::poll(&p, 1, ms) > 0;
}

std::optional<Datagram> receiveDatagram(const Fd& fd, double timeout_s) {
  if (!waitReadable(fd.get(), timeout_s)) return std::nullopt;
  Datagram d;
  d.bytes.resize(65536);
  socklen_t length = sizeof d.from;
  const ssize_t n = ::recvfrom(fd.get(), d.bytes.data(), d.bytes.size(), MSG_DONTWAIT,
                               reinterpret_cast<sockaddr*>(&d.from), &length);
  if (n < 0) return std::nullopt;
  d.bytes.resize(static_cast<size_t>(n));
  return d;
}

void sendDatagram(const Fd& fd, const std::string& bytes, const sockaddr_in& to) {
  // A datagram that cannot be sent (no route, a full buffer) is lost as UDP may lose it; the
  // protocol asks again.
  (void)::sendto(fd.get(), bytes.data(), bytes.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
                 reinterpret_cast<const sockaddr*>(&to), sizeof to);
}

bool TcpStream::fill(double timeout_s) {
  if (begin_ == end_) begin_ = end_ = 0;
  if (end_ == sizeof buffer_) {
    std::memmove(buffer_, buffer_ + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  const double deadline = now() + timeout_s;
  for (;;) {
    if (stop_ && stop_->load()) throw LslError("stopped");
    const double left = deadline - now();
    if (left <= 0) throw LslError("no data for " + std::to_string(timeout_s) + " s");
    if (!waitReadable(fd_.get(), std::min(left, 0.1))) continue;
    const ssize_t n = ::recv(fd_.get(), buffer_ + end_, sizeof buffer_ - end_, 0);
    if (n > 0) {
      end_ += static_cast<size_t>(n);
      return true;
    }
    if (n == 0) return false;
    if (errno != EINTR && errno != EAGAIN) throw LslError(systemError("connection broken"));
  }
}

void TcpStream::read(void* into, size_t bytes, double timeout_s) {
  char* out = static_cast<char*>(into);
  while (bytes > 0) {
    if (begin_ == end_ && !fill(timeout_s)) throw LslError("the other side closed the connection");
    const size_t n = std::min(bytes, end_ - begin_);
    std::memcpy(out, buffer_ + begin_, n);
    begin_ += n;
    out += n;
    bytes -= n;
  }
}

std::uint8_t TcpStream::readByte(double timeout_s) {
  if (begin_ == end_ && !fill(timeout_s)) throw LslError("the other side closed the connection");
  return static_cast<std::uint8_t>(buffer_[begin_++]);
}

std::string TcpStream::readLine(double timeout_s, size_t max_bytes) {
  std::string line;
  for (;;) {
    const char c = static_cast<char>(readByte(timeout_s));
    if (c == '\n') break;
    line += c;
    if (line.size() > max_bytes)
      throw LslError("a protocol line longer than " + std::to_string(max_bytes) + " bytes");
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

std::string TcpStream::readAll(double timeout_s, size_t max_bytes) {
  std::string all(buffer_ + begin_, end_ - begin_);
  begin_ = end_ = 0;
  while (all.size() <= max_bytes && fill(timeout_s)) {
    all.append(buffer_ + begin_, end_ - begin_);
    begin_ = end_ = 0;
  }
  return all;
}

void TcpStream::writeAll(const void* data, size_t bytes, double timeout_s) {
  const char* from = static_cast<const char*>(data);
  const double deadline = now() + timeout_s;
  while (bytes > 0) {
    if (stop_ && stop_->load()) throw LslError("stopped");
    pollfd p{fd_.get(), POLLOUT, 0};
    if (::poll(&p, 1, 100) <= 0) {
      if (now() > deadline) throw LslError("the other side takes no data");
      continue;
    }
    const ssize_t n = ::send(fd_.get(), from, bytes, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      throw LslError(systemError("connection broken"));
    }
    from += n;
    bytes -= static_cast<size_t>(n);
  }
}

}  // namespace arbci::bci::lsl::net
