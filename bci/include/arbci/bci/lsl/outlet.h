// An LSL outlet: publishes one stream so that any LSL client (ARBCI, LabRecorder, liblsl
// programs) can find it and take its samples. It answers discovery queries (UDP, on the
// configuration's discovery addresses and on its own service port), time-correction probes,
// and serves each connecting client on its own thread (TCP, data protocol 110).
//
// Samples pushed before a client connects are not kept for it (as with liblsl, a client gets the
// stream from when it connects). A client that falls more than `max_buffer_s` behind loses the
// oldest samples, counted in droppedSamples().
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "arbci/bci/lsl/config.h"
#include "arbci/bci/lsl/sample_codec.h"
#include "arbci/bci/lsl/stream_info.h"

namespace arbci::bci::lsl {

class DiscoveryResponder;

// The LSL clock: seconds of the host's steady clock, as liblsl's lsl_local_clock().
double localClock();

class Outlet {
 public:
  // `info` names the stream (name, type, channels, rate, format, source_id, channel
  // descriptions); the outlet fills in its uid, host, ports and creation time. Throws LslError
  // when it cannot bind its ports.
  Outlet(StreamInfo info, LslConfig config, double max_buffer_s = 360.0);
  ~Outlet();
  Outlet(const Outlet&) = delete;
  Outlet& operator=(const Outlet&) = delete;

  const StreamInfo& info() const { return info_; }
  // `samples` numeric samples (sample-major native values), the first stamped `timestamp` (LSL
  // clock) and the others deduced from the nominal rate (irregular streams: each stamped
  // `timestamp`).
  void pushRaw(const void* values, int samples, double timestamp);
  // One string sample (a marker), stamped `timestamp`.
  void pushStrings(const std::vector<std::string>& values, double timestamp);
  int clients() const;
  std::int64_t droppedSamples() const { return dropped_.load(); }
  // Why a discovery address could not be served (e.g. the port held without sharing), if any.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  struct Client;
  void serveDiscovery();
  void serveClient(std::shared_ptr<Client> client, int fd);
  void enqueue(std::string chunk, int samples);

  StreamInfo info_;
  LslConfig config_;
  SampleCodec codec_;
  std::size_t max_buffered_samples_;
  std::string shortinfo_, fullinfo_;
  std::vector<std::string> warnings_;
  struct Sockets;
  std::unique_ptr<Sockets> sockets_;
  std::atomic<bool> stop_{false};
  mutable std::mutex clients_mutex_;
  struct Session {
    std::shared_ptr<Client> client;
    std::thread thread;
  };
  std::list<Session> clients_;
  std::atomic<std::int64_t> dropped_{0};
  std::thread discovery_thread_;  // the service port (unicast queries, time) and clients
  std::shared_ptr<DiscoveryResponder> discovery_;  // the shared discovery port
};

}  // namespace arbci::bci::lsl
