// docs/robot-protocol.md is the wire: its version, every datagram type with its name and payload
// size, the reasons, the states, the STATUS reply's fields and its object record (the
// orientation's encoding and order included) and its constants are read from the page's tables
// and checked against what the code encodes. A change of the wire the page does not follow fails
// here.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "arbci/robot/protocol.h"

namespace arbci::robot {
namespace {

std::string page() {
  std::ifstream in(std::string(ARBCI_SOURCE_DIR) + "/docs/robot-protocol.md");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The rows of the table under the first line starting with `heading` (cells trimmed), the
// header and the separator left out.
std::vector<std::vector<std::string>> table(const std::string& text, const std::string& heading) {
  std::istringstream in(text);
  std::string line;
  bool found = false;
  int rows = 0;
  std::vector<std::vector<std::string>> out;
  while (std::getline(in, line)) {
    if (!found) {
      found = line.rfind(heading, 0) == 0;
      continue;
    }
    if (line.rfind("|", 0) != 0) {
      if (rows > 0) break;
      continue;
    }
    if (rows++ < 2) continue;
    std::vector<std::string> cells;
    std::stringstream cellsIn(line.substr(1));
    std::string cell;
    while (std::getline(cellsIn, cell, '|')) {
      const auto a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
      cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
    }
    out.push_back(cells);
  }
  return out;
}

int codeOf(const std::string& cell) {
  return static_cast<int>(std::stol(cell, nullptr, cell.rfind("0x", 0) == 0 ? 16 : 10));
}

// The payload's length as encoded for a message of `type` (texts empty, no objects).
size_t payloadBytes(MessageType type, bool with_clock = false, int objects = 0) {
  Message m;
  m.type = type;
  m.timestamp_ms = wallClockMs();
  if (with_clock) m.clock_s = 1.0;
  for (int i = 0; i < objects; ++i) m.status.objects.push_back(WorldObject{});
  const std::vector<std::uint8_t> bytes = encode(m, Key{});
  return bytes.size() - kHeaderBytes - kMacBytes;
}

TEST(ProtocolPage, ItsVersionIsTheCodes) {
  const std::string text = page();
  std::smatch found;
  ASSERT_TRUE(std::regex_search(text, found, std::regex("# ARBCI robot protocol, version (\\d+)")));
  EXPECT_EQ(std::stoi(found[1]), kProtocolVersion);
  ASSERT_TRUE(std::regex_search(text, found, std::regex("\\| 4 \\| 1 \\| version = (\\d+) \\|")));
  EXPECT_EQ(std::stoi(found[1]), kProtocolVersion);
}

TEST(ProtocolPage, EveryTypeHasItsNameAndPayloadSize) {
  const std::string text = page();
  std::map<int, std::string> sizes;
  for (const char* heading : {"Commands (client to backend)", "Replies (backend to client)"}) {
    const auto rows = table(text, heading);
    ASSERT_FALSE(rows.empty()) << heading;
    for (const auto& row : rows) {
      ASSERT_EQ(row.size(), 4u) << row[0];
      const auto type = static_cast<MessageType>(codeOf(row[0]));
      EXPECT_EQ(std::string(toString(type)), row[1]) << row[0];
      sizes[codeOf(row[0])] = row[3];
    }
  }
  EXPECT_EQ(sizes.size(), 16u);  // 9 commands, 7 replies
  for (const auto& [code, size] : sizes) {
    const auto type = static_cast<MessageType>(code);
    SCOPED_TRACE(toString(type));
    if (size == "0 or 8") {
      EXPECT_EQ(payloadBytes(type), 0u);
      EXPECT_EQ(payloadBytes(type, true), 8u);
    } else if (size == "1 + text") {
      EXPECT_EQ(payloadBytes(type), 1u + 2u);  // an empty text is its 2-byte length
    } else if (size.find("per object") != std::string::npos) {
      std::smatch n;
      ASSERT_TRUE(
          std::regex_search(size, n, std::regex("^(\\d+) \\+ texts \\+ (\\d+) per object")));
      EXPECT_EQ(payloadBytes(type), std::stoul(n[1]) + 2u * 2u);  // two empty texts
      EXPECT_EQ(payloadBytes(type, false, 1) - payloadBytes(type), std::stoul(n[2]));
    } else {
      EXPECT_EQ(payloadBytes(type), std::stoul(size));
    }
  }
}

TEST(ProtocolPage, TheReasonsAndStatesAreTheCodes) {
  const std::string text = page();
  const auto reasons = table(text, "Reasons of a REJECTED");
  ASSERT_EQ(reasons.size(), 11u);
  for (const auto& row : reasons)
    EXPECT_EQ(std::string(toString(static_cast<RejectReason>(codeOf(row[0])))), row[1]);
  const auto states = table(text, "States:");
  ASSERT_EQ(states.size(), 4u);
  for (const auto& row : states)
    EXPECT_EQ(std::string(toString(static_cast<RobotState>(codeOf(row[0])))), row[1]);
}

// The STATUS reply's fields add up to what is encoded, and the object record's orientation is
// four 16-bit integers w, x, y, z of value x 32767, at the record's end.
TEST(ProtocolPage, TheStatusReplyAndItsObjectRecordAreTheEncodedOnes) {
  const std::string text = page();
  size_t fixed = 0;
  for (const auto& row : table(text, "STATUS reply payload, in order"))
    fixed += std::stoul(row[1]);  // "2 + n": a text's length field
  EXPECT_EQ(fixed, payloadBytes(MessageType::StatusReply));
  size_t record = 0;
  std::vector<std::string> fields;
  for (const auto& row : table(text, "Each object record")) {
    record += std::stoul(row[1]);
    fields.push_back(row[0]);
  }
  EXPECT_EQ(fields, (std::vector<std::string>{"id", "top", "held", "orientation"}));
  EXPECT_EQ(record, payloadBytes(MessageType::StatusReply, false, 1) -
                        payloadBytes(MessageType::StatusReply));
  Message m;
  m.type = MessageType::StatusReply;
  m.timestamp_ms = wallClockMs();
  m.status.objects.push_back({7, {0.1, 0.5, 0.06}, false, {0.6, 0.8, 0.0, 0.0}});
  const std::vector<std::uint8_t> bytes = encode(m, Key{});
  const size_t end = bytes.size() - kMacBytes;
  std::int16_t q[4];
  std::memcpy(q, bytes.data() + end - 8, 8);  // little-endian, as this machine
  EXPECT_EQ(q[0], 19660);                     // w = 0.6
  EXPECT_EQ(q[1], 26214);                     // x = 0.8
  EXPECT_EQ(q[2], 0);
  EXPECT_EQ(q[3], 0);
  std::int32_t id = 0;
  std::memcpy(&id, bytes.data() + end - 37, 4);
  EXPECT_EQ(id, 7);
}

TEST(ProtocolPage, ItsConstantsAreTheCodes) {
  std::map<std::string, std::string> constants;
  for (const auto& row : table(page(), "Constants:")) constants[row[0]] = row[1];
  EXPECT_EQ(std::stoul(constants.at("replay window")), kReplayWindow);
  EXPECT_EQ(std::stoi(constants.at("heartbeats at their rate")), kStreamingHeartbeats);
  EXPECT_EQ(std::stoul(constants.at("maximum datagram")), kMaxDatagram);
  EXPECT_EQ(std::stoi(constants.at("objects")), kMaxWorldObjects);
}

}  // namespace
}  // namespace arbci::robot
