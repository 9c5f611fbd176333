#include "arbci/robot/udp_socket.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "arbci/robot/protocol.h"

namespace arbci::robot {

std::string Endpoint::toString() const {
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &address.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

bool Endpoint::operator==(const Endpoint& other) const {
  return address.sin_addr.s_addr == other.address.sin_addr.s_addr &&
         address.sin_port == other.address.sin_port;
}

Endpoint Endpoint::resolve(const std::string& host, int port) {
  if (port <= 0 || port > 65535)
    throw SocketError("port " + std::to_string(port) + " is not 1-65535");
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int status = getaddrinfo(host.c_str(), nullptr, &hints, &found);
  if (status != 0 || !found)
    throw SocketError("cannot resolve host '" + host + "': " + gai_strerror(status));
  Endpoint endpoint;
  std::memcpy(&endpoint.address, found->ai_addr, sizeof(sockaddr_in));
  endpoint.address.sin_port = htons(static_cast<std::uint16_t>(port));
  freeaddrinfo(found);
  return endpoint;
}

UdpSocket::UdpSocket(int port, const std::string& host) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0)
    throw SocketError(std::string("cannot create a UDP socket: ") + std::strerror(errno));
  Endpoint local = Endpoint::resolve(host, port == 0 ? 1 : port);
  local.address.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&local.address), sizeof local.address) != 0) {
    const std::string reason = std::strerror(errno);
    ::close(fd_);
    throw SocketError("cannot bind UDP " + host + ":" + std::to_string(port) + ": " + reason);
  }
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

int UdpSocket::port() const {
  sockaddr_in local{};
  socklen_t length = sizeof local;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&local), &length);
  return ntohs(local.sin_port);
}

int UdpSocket::setReceiveBuffer(int bytes) {
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes);
  return receiveBuffer();
}

int UdpSocket::receiveBuffer() const {
  int bytes = 0;
  socklen_t length = sizeof bytes;
  ::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &bytes, &length);
  return bytes;
}

void UdpSocket::sendTo(const std::vector<std::uint8_t>& bytes, const Endpoint& to) {
  // UDP may drop; a full send buffer is the same as a lost datagram, which the protocol handles.
  ::sendto(fd_, bytes.data(), bytes.size(), MSG_DONTWAIT,
           reinterpret_cast<const sockaddr*>(&to.address), sizeof to.address);
}

std::optional<Datagram> UdpSocket::receive() {
  std::uint8_t buffer[65536];
  Datagram d;
  socklen_t length = sizeof d.from.address;
  const ssize_t n = ::recvfrom(fd_, buffer, sizeof buffer, MSG_DONTWAIT,
                               reinterpret_cast<sockaddr*>(&d.from.address), &length);
  if (n < 0) return std::nullopt;
  d.bytes.assign(buffer, buffer + n);
  return d;
}

bool UdpSocket::wait(int milliseconds) {
  pollfd p{fd_, POLLIN, 0};
  return ::poll(&p, 1, milliseconds) > 0;
}

bool UdpSocket::wait(std::chrono::microseconds timeout) {
  pollfd p{fd_, POLLIN, 0};
  const long long us = std::max<long long>(0, timeout.count());
  const timespec t{static_cast<time_t>(us / 1000000), static_cast<long>(us % 1000000) * 1000};
  return ::ppoll(&p, 1, &t, nullptr) > 0;
}

}  // namespace arbci::robot
