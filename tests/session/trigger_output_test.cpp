// The trigger output alone, on a pseudo-terminal (openpty) in place of a trigger box: each flash
// writes its base plus its code, in order; with pulse, the lines go back to 0 on the next frame;
// the feedback byte when set; every write stamped after its swap; a port that cannot be opened, or
// is no serial port, is refused naming it.
#include "arbci/session/trigger_output.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <unistd.h>

#include <stdexcept>

#include "arbci/session/cycle.h"

namespace arbci::session {
namespace {

struct Pty {
  Pty() {
    char name[256] = {};
    if (::openpty(&master, &slave, name, nullptr, nullptr) == 0) path = name;
  }
  ~Pty() {
    if (slave >= 0) ::close(slave);
    if (master >= 0) ::close(master);
  }
  std::vector<std::uint8_t> read() const {
    std::vector<std::uint8_t> out;
    pollfd p{master, POLLIN, 0};
    while (::poll(&p, 1, 100) > 0) {
      std::uint8_t buffer[64];
      const ssize_t n = ::read(master, buffer, sizeof buffer);
      if (n <= 0) break;
      out.insert(out.end(), buffer, buffer + n);
    }
    return out;
  }
  int master = -1, slave = -1;
  std::string path;
};

Flash flash(int code, bool objects) {
  Flash f;
  f.code = code;
  f.objects = objects;
  return f;
}

// A pseudo-terminal in place of the box, and settings naming it (skipped where the machine gives
// no pseudo-terminal).
class TriggerOutputOnPty : public ::testing::Test {
 protected:
  void SetUp() override {
    if (pty.path.empty()) GTEST_SKIP() << "this machine gives no pseudo-terminal (openpty failed)";
    settings.device = pty.path;
  }
  Pty pty;
  TriggerSettings settings;
};

TEST_F(TriggerOutputOnPty, EachFlashWritesItsCodeAndThePulseEndsOnTheNextFrame) {
  settings.feedback_byte = 200;
  TriggerOutput out(settings);
  FeedbackShown feedback;
  out.presented(1, 10.0, 0.0, {flash(3, true)}, nullptr);
  out.presented(2, 10.016, 0.002, {}, nullptr);
  out.presented(3, 10.032, 0.0, {flash(2, false)}, nullptr);
  out.presented(4, 10.048, 0.0, {}, &feedback);
  EXPECT_EQ(pty.read(), (std::vector<std::uint8_t>{3, 0, 102, 0, 200}));
  const std::vector<TriggerWrite> writes = out.take();
  ASSERT_EQ(writes.size(), 5u);
  EXPECT_EQ(writes[0].what, "object 3");
  EXPECT_EQ(writes[2].what, "grid 2");
  EXPECT_EQ(writes[1].what, "reset");
  EXPECT_EQ(writes[4].what, "feedback");
  for (const TriggerWrite& w : writes) EXPECT_GE(w.written_host_s, w.swap_host_s);
  EXPECT_GE(writes[1].written_host_s, 10.018);  // the call came 2 ms after its swap
  EXPECT_TRUE(out.take().empty());
  EXPECT_EQ(out.failedWrites(), 0);
}

TEST_F(TriggerOutputOnPty, BasesShiftTheCodesAndWithoutPulseNoResetIsWritten) {
  settings.object_base = 10;
  settings.grid_base = 50;
  settings.pulse = false;
  TriggerOutput out(settings);
  out.presented(1, 1.0, 0.0, {flash(1, true)}, nullptr);
  out.presented(2, 1.1, 0.0, {}, nullptr);
  out.presented(3, 1.2, 0.0, {flash(4, false)}, nullptr);
  EXPECT_EQ(pty.read(), (std::vector<std::uint8_t>{11, 54}));
}

// The box unplugged mid-run (the pseudo-terminal's other end closed): each write that fails is
// counted, the fault names the port, and nothing is stamped as written.
TEST_F(TriggerOutputOnPty, APortThatGoesAwayCountsItsFailedWrites) {
  TriggerOutput out(settings);
  out.presented(1, 1.0, 0.0, {flash(1, true)}, nullptr);
  ASSERT_EQ(out.take().size(), 1u);
  ::close(pty.master);
  ::close(pty.slave);
  pty.master = pty.slave = -1;
  out.presented(2, 1.1, 0.0, {flash(2, true)}, nullptr);
  out.presented(3, 1.2, 0.0, {flash(3, true)}, nullptr);
  EXPECT_GE(out.failedWrites(), 2);
  EXPECT_NE(out.fault().find(settings.device), std::string::npos) << out.fault();
  EXPECT_TRUE(out.take().empty());
}

TEST(TriggerOutput, APortThatCannotBeUsedIsRefusedNamingIt) {
  TriggerSettings settings;
  settings.device = "/dev/ttyUSB-arbci-missing";
  try {
    TriggerOutput out(settings);
    FAIL() << "a missing port was opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/ttyUSB-arbci-missing"), std::string::npos);
  }
  settings.device = "/dev/null";
  try {
    TriggerOutput out(settings);
    FAIL() << "/dev/null was taken for a serial port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a serial port"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arbci::session
