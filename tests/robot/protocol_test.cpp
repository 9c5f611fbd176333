// The wire format: every message survives a round trip; any change to the bytes, another key,
// another version, a reserved field set or a cut is caught; key files are private, regular,
// exactly 64 hex digits and random-looking.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "arbci/robot/key_file.h"
#include "arbci/robot/protocol.h"

namespace arbci::robot {
namespace {

Key testKey(std::uint8_t fill = 7) {
  Key key{};
  key.fill(fill);
  return key;
}

Message statusMessage() {
  Message m;
  m.type = MessageType::StatusReply;
  m.session = 0x1122334455667788ULL;
  m.sequence = 42;
  m.timestamp_ms = 1700000000123ULL;
  m.boot = 99;
  m.status.state = RobotState::Moving;
  m.status.tool = {0.1, 0.5, 0.3};
  m.status.gripper_opening = 0.25;
  m.status.holding = 3;
  m.status.current_command = MessageType::Grasp;
  m.status.current_sequence = 41;
  m.status.progress = 0.6;
  m.status.last_finished_sequence = 40;
  m.status.last_outcome = Outcome::Stopped;
  m.status.last_outcome_text = "stopped by STOP";
  m.status.current_is_yours = true;
  m.status.stop_reason = "halted: link lost";
  m.status.objects = {{1, {0.1, 0.6, 0.06}, false}, {3, {0.1, 0.5, 0.25}, true}};
  return m;
}

TEST(Protocol, EveryMessageSurvivesARoundTrip) {
  const Key key = testKey();
  Message grasp;
  grasp.type = MessageType::Grasp;
  grasp.session = 5;
  grasp.sequence = 17;
  grasp.timestamp_ms = 123;
  grasp.target = {0.12, -0.5, 0.061};
  auto bytes = encode(grasp, key);
  Decoded d = decode(bytes.data(), bytes.size(), key);
  ASSERT_TRUE(d.ok()) << toString(d.error);
  EXPECT_EQ(d.message.type, MessageType::Grasp);
  EXPECT_EQ(d.message.sequence, 17u);
  EXPECT_EQ(d.message.target.y, -0.5);

  const Message status = statusMessage();
  bytes = encode(status, key);
  d = decode(bytes.data(), bytes.size(), key);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.message.status.holding, 3);
  EXPECT_EQ(d.message.status.last_outcome_text, "stopped by STOP");
  ASSERT_EQ(d.message.status.objects.size(), 2u);
  EXPECT_TRUE(d.message.status.objects[1].held);
  EXPECT_EQ(d.message.boot, 99u);
  EXPECT_TRUE(d.message.status.current_is_yours);
  EXPECT_EQ(d.message.status.stop_reason, "halted: link lost");

  Message heartbeat;
  heartbeat.type = MessageType::Heartbeat;
  heartbeat.abandon_below = 0xfffffffffffffff0ULL;
  bytes = encode(heartbeat, key);
  d = decode(bytes.data(), bytes.size(), key);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.message.abandon_below, heartbeat.abandon_below);
  Message welcome;
  welcome.type = MessageType::Welcome;
  welcome.watchdog_ms = 100;
  welcome.boot = 0x0123456789abcdefULL;
  bytes = encode(welcome, key);
  d = decode(bytes.data(), bytes.size(), key);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.message.watchdog_ms, 100u);
  EXPECT_EQ(d.message.boot, welcome.boot);
  for (const MessageType type : {MessageType::Hello, MessageType::Reset}) {
    Message bare;
    bare.type = type;
    bytes = encode(bare, key);
    d = decode(bytes.data(), bytes.size(), key);
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d.message.type, type);
  }

  Message rejected;
  rejected.type = MessageType::Rejected;
  rejected.reason = RejectReason::OutsideWorkspace;
  rejected.text = "(2, 0, 0) lies outside the workspace";
  bytes = encode(rejected, key);
  d = decode(bytes.data(), bytes.size(), key);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.message.reason, RejectReason::OutsideWorkspace);
  EXPECT_EQ(d.message.text, rejected.text);
}

TEST(Protocol, AStatusCarriesTheRequestersClockOrNothing) {
  const Key key = testKey();
  Message status;
  status.type = MessageType::Status;
  status.sequence = 3;
  auto bytes = encode(status, key);
  Decoded plain = decode(bytes.data(), bytes.size(), key);
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain.message.clock_s.has_value());
  status.clock_s = 12.345;
  const auto with_clock = encode(status, key);
  EXPECT_EQ(with_clock.size(), bytes.size() + 8);
  Decoded clocked = decode(with_clock.data(), with_clock.size(), key);
  ASSERT_TRUE(clocked.ok());
  ASSERT_TRUE(clocked.message.clock_s.has_value());
  EXPECT_EQ(*clocked.message.clock_s, 12.345);
  status.clock_s = -1.0;  // a clock before its start is refused
  const auto negative = encode(status, key);
  EXPECT_FALSE(decode(negative.data(), negative.size(), key).ok());
}

TEST(Protocol, TamperingOtherKeysVersionsAndCutsAreCaught) {
  const Key key = testKey();
  const auto bytes = encode(statusMessage(), key);
  for (size_t i = 0; i < bytes.size(); ++i) {
    auto changed = bytes;
    changed[i] ^= 0x01;
    EXPECT_FALSE(decode(changed.data(), changed.size(), key).ok()) << "byte " << i;
  }
  EXPECT_EQ(decode(bytes.data(), bytes.size(), testKey(8)).error, DecodeError::BadMac);
  auto version = bytes;
  version[4] = 1;  // the first protocol: no boot ids, no latched stop
  EXPECT_EQ(decode(version.data(), version.size(), key).error, DecodeError::BadVersion);
  for (const size_t at : {6u, 7u}) {
    auto reserved = bytes;
    reserved[at] = 1;
    EXPECT_EQ(decode(reserved.data(), reserved.size(), key).error, DecodeError::BadReserved);
  }
  EXPECT_EQ(decode(bytes.data(), bytes.size() - 1, key).error, DecodeError::BadLength);
  EXPECT_EQ(decode(bytes.data(), 20, key).error, DecodeError::TooShort);
  std::vector<std::uint8_t> huge(5000, 0);
  EXPECT_EQ(decode(huge.data(), huge.size(), key).error, DecodeError::TooLong);
  // A NaN target is malformed even when authenticated.
  Message nan;
  nan.type = MessageType::Drop;
  nan.target = {std::nan(""), 0.0, 0.0};
  const auto bad = encode(nan, key);
  EXPECT_EQ(decode(bad.data(), bad.size(), key).error, DecodeError::BadPayload);
}

TEST(KeyFile, WrittenPrivateAndCheckedOnLoad) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("arbci_test_" + std::to_string(::getpid()) + ".key");
  std::filesystem::remove(path);
  const Key key = generateKey();
  saveKey(path, key);
  struct stat info {};
  ASSERT_EQ(stat(path.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
  EXPECT_EQ(loadKey(path), key);
  EXPECT_NE(generateKey(), key);
  chmod(path.c_str(), 0644);
  EXPECT_THROW(loadKey(path), KeyError);
  std::filesystem::remove(path);
  std::ofstream(path) << "not hex";
  chmod(path.c_str(), 0600);
  try {
    loadKey(path);
    FAIL();
  } catch (const KeyError& error) {
    EXPECT_NE(std::string(error.what()).find("64 hex"), std::string::npos);
  }
  EXPECT_THROW(loadKey(path.string() + ".missing"), KeyError);
}

// What a hand-made key file gets wrong: each refused with a reason, none read as a key.
TEST(KeyFile, RefusesWeakKeysTrailingTextFifosAndDevices) {
  const auto dir = std::filesystem::temp_directory_path() / "arbci_key_checks";
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& text) {
    const auto path = dir / name;
    std::filesystem::remove(path);
    std::ofstream(path) << text;
    chmod(path.c_str(), 0600);
    return path;
  };
  auto refusal = [](const std::filesystem::path& path) -> std::string {
    try {
      loadKey(path);
    } catch (const KeyError& error) {
      return error.what();
    }
    return "";
  };
  const std::string good = "3f9a1c77e20b5d4468f1a0c93e7b2d5106a8e4f19c3b7d20e5a6f8014c9d2b73";
  EXPECT_EQ(refusal(write("good.key", good + "\n")), "");
  EXPECT_NE(refusal(write("zero.key", std::string(64, '0') + "\n")).find("does not look random"),
            std::string::npos);
  std::string pattern;
  for (int i = 0; i < 16; ++i) pattern += "abcd";
  EXPECT_NE(refusal(write("pattern.key", pattern + "\n")).find("does not look random"),
            std::string::npos);
  EXPECT_NE(refusal(write("trailing.key", good + "ff\n")).find("64 hex"), std::string::npos);
  EXPECT_NE(refusal(write("second.key", good + "\n" + good + "\n")).find("64 hex"),
            std::string::npos);
  // A FIFO would block a reader forever; a device is not a key.
  const auto fifo = dir / "fifo.key";
  std::filesystem::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(refusal(fifo).find("not a regular file"), std::string::npos);
  EXPECT_NE(refusal("/dev/null").find("not a regular file"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// What the last round's review found accepted: each is refused now, with its reason.
TEST(KeyFile, RefusesLineEndingsOtherThanOneLfAndGuessableKeys) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("arbci_key_strict_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto refusal = [&](const std::string& name, const std::string& text) -> std::string {
    const auto path = dir / name;
    std::ofstream(path) << text;
    chmod(path.c_str(), 0600);
    try {
      loadKey(path);
    } catch (const KeyError& error) {
      return error.what();
    }
    return "";
  };
  auto hexOf = [](const std::vector<int>& bytes) {
    std::string text;
    char two[3];
    for (int b : bytes) {
      std::snprintf(two, sizeof two, "%02x", b & 0xff);
      text += two;
    }
    return text;
  };
  const std::string good = "3f9a1c77e20b5d4468f1a0c93e7b2d5106a8e4f19c3b7d20e5a6f8014c9d2b73";
  EXPECT_EQ(refusal("good.key", good + "\n"), "");
  EXPECT_NE(refusal("crlf.key", good + "\r\n").find("one newline"), std::string::npos);
  EXPECT_NE(refusal("lflf.key", good + "\n\n").find("one newline"), std::string::npos);
  EXPECT_NE(refusal("none.key", good).find("one newline"), std::string::npos);
  EXPECT_NE(refusal("garbage.key", good + "\n# my key").find("one newline"), std::string::npos);
  std::vector<int> counting, passphrase, twelve;
  const std::string phrase = "Tr0ub4dor&3-Zx!qWmK9#pL@vN$yB^hJ";  // 32 distinct characters
  for (int i = 0; i < 32; ++i) {
    counting.push_back(i);
    passphrase.push_back(phrase[i]);
    twelve.push_back((i % 12) * 17 + 3);
  }
  EXPECT_NE(refusal("count.key", hexOf(counting) + "\n").find("constant step"), std::string::npos);
  EXPECT_NE(refusal("phrase.key", hexOf(passphrase) + "\n").find("printable"), std::string::npos);
  EXPECT_NE(refusal("twelve.key", hexOf(twelve) + "\n").find("distinct bytes"), std::string::npos);
  // What keygen makes always loads.
  for (int i = 0; i < 200; ++i) {
    const auto path = dir / ("made" + std::to_string(i) + ".key");
    const Key key = generateKey();
    saveKey(path, key);
    EXPECT_EQ(loadKey(path), key);
  }
  std::filesystem::remove_all(dir);
}

// keygen writes only a new regular file: a FIFO (which would block the writer), a device node, a
// link or an existing key are refused and left as they were; --force replaces only a key file.
TEST(KeyFile, SavedOnlyToANewRegularFileOrOverAKeyWhenAskedTo) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("arbci_key_save_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto refusal = [](const std::filesystem::path& path, bool replace) -> std::string {
    try {
      saveKey(path, generateKey(), replace);
    } catch (const KeyError& error) {
      return error.what();
    }
    return "";
  };
  const auto fifo = dir / "fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(refusal(fifo, true).find("not a regular file"), std::string::npos);
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_NE(refusal("/dev/null", true).find("not a regular file"), std::string::npos);
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));
  const auto target = dir / "notes.txt", link = dir / "link.key";
  std::ofstream(target) << "not a key\n";
  std::filesystem::create_symlink(target, link);
  EXPECT_NE(refusal(link, true).find("not a regular file"), std::string::npos);
  EXPECT_EQ(std::filesystem::file_size(target), 10u);
  EXPECT_NE(refusal(dir, true).find("not a regular file"), std::string::npos);

  const auto key_file = dir / "robot.key";
  const Key first = generateKey();
  saveKey(key_file, first);
  EXPECT_NE(refusal(key_file, false).find("--force"), std::string::npos);
  EXPECT_EQ(loadKey(key_file), first);  // untouched
  const Key second = generateKey();
  saveKey(key_file, second, true);
  EXPECT_EQ(loadKey(key_file), second);
  struct stat info {};
  ASSERT_EQ(stat(key_file.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
  // Nothing else left behind in the folder (no half-written temporary).
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 4);  // fifo, notes.txt, link.key, robot.key
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace arbci::robot
