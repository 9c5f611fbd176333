#include "arbci/bci/lsl/outlet.h"

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <deque>
#include <iterator>
#include <random>
#include <sstream>

#include "arbci/core/text.h"
#include "lsl/discovery_responder.h"
#include "lsl/socket.h"

namespace arbci::bci::lsl {
namespace {

constexpr double kRequestTimeoutS = 5.0;
constexpr double kSendTimeoutS = 10.0;  // a client that takes nothing this long is dropped

std::string newUid() {
  std::random_device device;
  std::mt19937_64 random(device() ^ static_cast<std::uint64_t>(localClock() * 1e9));
  char text[40];
  const std::uint64_t a = random(), b = random();
  std::snprintf(text, sizeof text, "%08x-%04x-%04x-%04x-%012llx", static_cast<unsigned>(a >> 32),
                static_cast<unsigned>((a >> 16) & 0xffff), static_cast<unsigned>(a & 0xffff),
                static_cast<unsigned>(b >> 48),
                static_cast<unsigned long long>(b & 0xffffffffffffULL));
  return text;
}

std::string hostName() {
  char name[256] = "";
  if (::gethostname(name, sizeof name - 1) != 0) return "localhost";
  return name;
}

}  // namespace

double localClock() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Outlet::Sockets {
  net::Fd listener, service;
};

struct Outlet::Client {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<std::pair<std::string, int>> chunks;  // encoded samples, and how many
  std::size_t queued = 0;
  bool streaming = false, done = false;
};

Outlet::Outlet(StreamInfo info, LslConfig config, double max_buffer_s)
    : info_(std::move(info)),
      config_(std::move(config)),
      codec_(info_.channel_format, info_.channel_count),
      sockets_(std::make_unique<Sockets>()) {
  if (info_.name.empty()) throw LslError("an LSL stream needs a name");
  if (info_.nominal_srate < 0) throw LslError("an LSL stream's rate cannot be negative");
  const double rate = info_.nominal_srate > 0 ? info_.nominal_srate : 100.0;
  max_buffered_samples_ = static_cast<std::size_t>(std::max(1.0, max_buffer_s * rate));
  const std::string address = config_.machineOnly() ? "127.0.0.1" : "0.0.0.0";
  sockets_->listener = net::tcpListener(address, config_.base_port, config_.port_range,
                                        config_.allow_random_ports, &info_.v4data_port);
  sockets_->service = net::udpSocket();
  info_.v4service_port = net::bindInRange(sockets_->service, address, config_.base_port,
                                          config_.port_range, config_.allow_random_ports);
  info_.uid = newUid();
  info_.hostname = hostName();
  info_.session_id = config_.session_id;
  info_.version = kProtocolVersion;
  info_.created_at = localClock();
  info_.v4address.clear();  // the client takes it from where the reply came from
  shortinfo_ = info_.toXml(false);
  fullinfo_ = info_.toXml(true);

  discovery_ = DiscoveryResponder::shared(config_, warnings_);
  discovery_->add(this, info_, shortinfo_);
  discovery_thread_ = std::thread([this] { serveDiscovery(); });
}

Outlet::~Outlet() {
  discovery_->remove(this);
  stop_ = true;
  {
    std::lock_guard lock(clients_mutex_);
    for (auto& s : clients_) s.client->ready.notify_all();
  }
  if (discovery_thread_.joinable()) discovery_thread_.join();
  std::list<Session> sessions;
  {
    std::lock_guard lock(clients_mutex_);
    sessions.swap(clients_);
  }
  for (auto& s : sessions)
    if (s.thread.joinable()) s.thread.join();
}

int Outlet::clients() const {
  std::lock_guard lock(clients_mutex_);
  int n = 0;
  for (const auto& s : clients_) {
    const auto& c = s.client;
    std::lock_guard client_lock(c->mutex);
    n += c->streaming && !c->done;
  }
  return n;
}

void Outlet::pushRaw(const void* values, int samples, double timestamp) {
  if (codec_.format() == ChannelFormat::String) throw LslError("a string stream takes strings");
  std::string chunk;
  chunk.reserve(static_cast<size_t>(samples) * (codec_.rawBytes() + 9));
  const char* v = static_cast<const char*>(values);
  for (int s = 0; s < samples; ++s, v += codec_.rawBytes()) {
    const bool stamp = s == 0 || info_.nominal_srate <= 0;
    codec_.encodeRaw(chunk, v, stamp ? timestamp : -1.0);
  }
  enqueue(std::move(chunk), samples);
}

void Outlet::pushStrings(const std::vector<std::string>& values, double timestamp) {
  Sample sample;
  sample.timestamp = timestamp;
  sample.strings = values;
  std::string chunk;
  codec_.encode(chunk, sample);
  enqueue(std::move(chunk), 1);
}

void Outlet::enqueue(std::string chunk, int samples) {
  std::lock_guard lock(clients_mutex_);
  for (auto& s : clients_) {
    const auto& c = s.client;
    std::lock_guard client_lock(c->mutex);
    if (!c->streaming || c->done) continue;
    c->chunks.emplace_back(chunk, samples);
    c->queued += static_cast<std::size_t>(samples);
    while (c->queued > max_buffered_samples_ && c->chunks.size() > 1) {
      c->queued -= static_cast<std::size_t>(c->chunks.front().second);
      dropped_ += c->chunks.front().second;
      c->chunks.pop_front();
    }
    c->ready.notify_one();
  }
}

void Outlet::serveDiscovery() {
  std::vector<pollfd> watched;
  watched.push_back({sockets_->listener.get(), POLLIN, 0});
  watched.push_back({sockets_->service.get(), POLLIN, 0});
  while (!stop_) {
    for (auto& w : watched) w.revents = 0;
    if (::poll(watched.data(), watched.size(), 100) <= 0) continue;
    if (watched[0].revents & POLLIN) {
      const int fd = ::accept4(sockets_->listener.get(), nullptr, nullptr, SOCK_CLOEXEC);
      if (fd >= 0) {
        auto client = std::make_shared<Client>();
        std::lock_guard lock(clients_mutex_);
        // Forget clients that have finished (their threads have returned).
        for (auto it = clients_.begin(); it != clients_.end();) {
          bool done = false;
          {
            std::lock_guard client_lock(it->client->mutex);
            done = it->client->done;
          }
          if (!done) {
            ++it;
            continue;
          }
          it->thread.join();
          it = clients_.erase(it);
        }
        clients_.push_back({client, std::thread([this, client, fd] { serveClient(client, fd); })});
      }
    }
    for (size_t i = 1; i < watched.size(); ++i) {
      if (!(watched[i].revents & POLLIN)) continue;
      const double received_at = localClock();
      const net::Fd& socket = sockets_->service;
      auto datagram = net::receiveDatagram(socket, 0.0);
      if (!datagram) continue;
      std::istringstream request(datagram->bytes);
      std::string method;
      std::getline(request, method);
      method = core::trimmed(method);
      if (method == "LSL:shortinfo") {
        std::string rest((std::istreambuf_iterator<char>(request)),
                         std::istreambuf_iterator<char>());
        if (auto reply = shortinfoReply(rest, info_, shortinfo_)) {
          sockaddr_in to = datagram->from;
          to.sin_port = htons(static_cast<std::uint16_t>(reply->first));
          net::sendDatagram(socket, reply->second, to);
        }
      } else if (method == "LSL:timedata") {
        // " <wave id> <t0> <t1> <t2>": the client's send time, our receive and reply times.
        long long wave = 0;
        double t0 = 0;
        if (!(request >> wave >> t0)) continue;
        std::ostringstream reply;
        reply.precision(16);
        reply << ' ' << wave << ' ' << t0 << ' ' << received_at << ' ' << localClock();
        net::sendDatagram(socket, reply.str(), datagram->from);
      }
    }
  }
}

void Outlet::serveClient(std::shared_ptr<Client> client, int raw_fd) {
  net::TcpStream stream{net::Fd(raw_fd)};
  stream.setStop(&stop_);
  const auto finish = [&] {
    std::lock_guard lock(client->mutex);
    client->done = true;
  };
  try {
    const std::string method = core::trimmed(stream.readLine(kRequestTimeoutS));
    if (method == "LSL:shortinfo") {
      const std::string query = core::trimmed(stream.readLine(kRequestTimeoutS));
      bool match = false;
      try {
        match = info_.matches(query);
      } catch (const LslError&) {
      }
      if (match) stream.writeAll(shortinfo_, kSendTimeoutS);
    } else if (method == "LSL:fullinfo") {
      stream.writeAll(fullinfo_, kSendTimeoutS);
    } else if (method.rfind("LSL:streamfeed/", 0) == 0) {
      std::istringstream parts(method.substr(15));
      int version = 0;
      std::string uid;
      parts >> version >> uid;
      std::string value_size_text;
      for (std::string line; !(line = stream.readLine(kRequestTimeoutS)).empty();) {
        const auto colon = line.find(':');
        if (colon == std::string::npos) continue;
        const std::string key = core::lowerCase(core::trimmed(line.substr(0, colon)));
        if (key == "value-size") value_size_text = core::trimmed(line.substr(colon + 1));
      }
      const std::string status = "LSL/" + std::to_string(kProtocolVersion);
      if (version / 100 > kProtocolVersion / 100) {
        stream.writeAll(status + " 505 Version not supported\r\n", kSendTimeoutS);
      } else if (!uid.empty() && uid != info_.uid) {
        stream.writeAll(status + " 404 Not found\r\n", kSendTimeoutS);
      } else if (version < 110 ||
                 (codec_.format() != ChannelFormat::String && !value_size_text.empty() &&
                  value_size_text != std::to_string(formatSize(codec_.format())))) {
        // Protocol 100 (Boost serialization) is not spoken; a client asks for it only when
        // told to, or when its value sizes differ.
        stream.writeAll(
            status + " 505 Version not supported (ARBCI serves data protocol 110 only)\r\n",
            kSendTimeoutS);
      } else {
        std::string header = status + " 200 OK\r\nUID: " + info_.uid +
                             "\r\nByte-Order: 1234\r\nSuppress-Subnormals: 0\r\n"
                             "Data-Protocol-Version: 110\r\n\r\n";
        for (int pattern : {4, 2}) codec_.encode(header, codec_.testPattern(pattern));
        {
          std::lock_guard lock(client->mutex);
          client->streaming = true;
        }
        stream.writeAll(header, kSendTimeoutS);
        std::string batch;
        while (!stop_) {
          {
            std::unique_lock lock(client->mutex);
            client->ready.wait_for(lock, std::chrono::milliseconds(100),
                                   [&] { return stop_ || !client->chunks.empty(); });
            batch.clear();
            while (!client->chunks.empty() && batch.size() < (1u << 20)) {
              batch += client->chunks.front().first;
              client->queued -= static_cast<std::size_t>(client->chunks.front().second);
              client->chunks.pop_front();
            }
          }
          if (!batch.empty()) stream.writeAll(batch, kSendTimeoutS);
          // A client that hung up shows as readable with nothing to read.
          if (net::waitReadable(stream.fd().get(), 0.0)) {
            char probe;
            if (::recv(stream.fd().get(), &probe, 1, MSG_DONTWAIT | MSG_PEEK) == 0) break;
          }
        }
      }
    }
  } catch (const LslError&) {
    // The client went away or sent garbage: its session ends, the outlet goes on.
  }
  finish();
}

}  // namespace arbci::bci::lsl
