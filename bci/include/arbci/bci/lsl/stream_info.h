// An LSL stream's description, as liblsl writes it into XML: the short form that discovery
// replies carry, and the full form (with <desc>, where the channel labels live) that a client
// asks the outlet for. Queries are XPath predicates over it, as liblsl evaluates them
// (e.g. "session_id='default' and name='ActiChamp'").
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace arbci::bci::lsl {

// liblsl's channel_format codes (their numbers travel nowhere; the names do).
enum class ChannelFormat {
  Float32 = 1,
  Double64 = 2,
  String = 3,
  Int32 = 4,
  Int16 = 5,
  Int8 = 6,
  Int64 = 7
};
const char* formatName(ChannelFormat format);
// Throws LslError for a name liblsl does not define.
ChannelFormat formatFromName(const std::string& name);
// Bytes per value (0 for strings, whose values carry their own length).
int formatSize(ChannelFormat format);

// The protocol version ARBCI speaks (liblsl 1.13 to 1.16 speak 110).
constexpr int kProtocolVersion = 110;
// The nominal rate of a stream without a regular rate (markers).
constexpr double kIrregularRate = 0.0;

struct ChannelDescription {
  std::string label, unit, type;
  // <impedance>, as amplifier apps that measure it write it (g.tec's, for one); the text as
  // given: LSL's metadata conventions state no unit for it.
  std::string impedance;
};

struct StreamInfo {
  std::string name, type;
  int channel_count = 0;
  double nominal_srate = kIrregularRate;
  ChannelFormat channel_format = ChannelFormat::Float32;
  std::string source_id;
  int version = kProtocolVersion;
  double created_at = 0.0;
  std::string uid, session_id = "default", hostname;
  std::string v4address;
  int v4data_port = 0, v4service_port = 0;
  std::vector<ChannelDescription> channels;  // from <desc><channels>; empty when not described
  // <desc><arbci><parameter name="..">: what ARBCI's marker outlets say of the paradigm (the
  // stimulus layout), so that a recorder's file (XDF) carries it as a BDF's Param annotations do.
  std::vector<std::pair<std::string, std::string>> parameters;

  // Serialized for the wire. `full` adds <desc> with the channels.
  std::string toXml(bool full) const;
  // Parses liblsl's XML (short or full). Throws LslError naming what is missing or malformed.
  static StreamInfo fromXml(const std::string& xml);
  // Whether the XPath predicate `query` holds for this stream (an empty query matches all).
  // Throws LslError for a query that is not valid XPath.
  bool matches(const std::string& query) const;
  // The labels of the channels, "Ch1".. where the stream does not name them.
  std::vector<std::string> channelLabels() const;
};

// A query for streams by name, type, source id and/or host in a session: "session_id='S' and
// name='N' and type='T' and source_id='I' and hostname='H'" (empty fields left out; single quotes
// in values are refused: XPath 1.0 has no escape for them).
std::string buildQuery(const std::string& session_id, const std::string& name,
                       const std::string& type, const std::string& source_id = "",
                       const std::string& hostname = "");

}  // namespace arbci::bci::lsl
