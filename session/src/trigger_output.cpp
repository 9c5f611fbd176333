#include "arbci/session/trigger_output.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "arbci/bci/sample_clock.h"
#include "arbci/session/cycle.h"

namespace arbci::session {
namespace {

speed_t speedOf(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      return B0;
  }
}

}  // namespace

const core::Schema<TriggerSettings>& triggerSchema() {
  static const core::Schema<TriggerSettings> table = [] {
    using T = TriggerSettings;
    core::Schema<T> t("trigger",
                      "The serial port a trigger box hangs on (eeg.trigger_out \"serial\"): a byte "
                      "at each flash's presentation, into the amplifier's own file");
    t.text("device", &T::device, "", "the port: /dev/ttyUSB0, /dev/ttyACM0, ...")
        .integer("baud", &T::baud, 115200, 9600, 921600,
                 "its rate: 9600, 19200, 38400, 57600, 115200, 230400, 460800 or 921600")
        .integer("object_base", &T::object_base, 0, 0, 255,
                 "an object's flash writes this plus its code (0: the recording's code, 1-N)")
        .integer("grid_base", &T::grid_base, 100, 0, 255,
                 "a grid row's or column's flash writes this plus its code (100: the "
                 "recording's, 100 + code)")
        .integer("feedback_byte", &T::feedback_byte, 0, 0, 255,
                 "written when a selection is shown (0: nothing)")
        .boolean("pulse", &T::pulse, true,
                 "the lines back to 0 on the next frame, so that each flash is an edge");
    t.rule([](const nlohmann::json& j) -> std::optional<std::pair<std::string, std::string>> {
      if (speedOf(j["baud"].get<int>()) == B0)
        return std::pair{"baud",
                         "must be one of 9600, 19200, 38400, 57600, 115200, 230400, "
                         "460800, 921600"};
      return std::nullopt;
    });
    return t;
  }();
  return table;
}

const std::vector<std::string>& triggerOutputs() {
  static const std::vector<std::string> choices{"none", "serial"};
  return choices;
}

TriggerSettings::TriggerSettings() {
  triggerSchema().applyDefaults(*this);
}

TriggerOutput::TriggerOutput(const TriggerSettings& settings) : settings_(settings) {
  if (settings_.device.empty())
    throw std::runtime_error("eeg.trigger.device is empty: name the trigger box's serial port");
  // Non-blocking: a port whose buffer is full fails a write (counted) rather than holding the
  // frame.
  fd_ = ::open(settings_.device.c_str(), O_WRONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0)
    throw std::runtime_error("cannot open the trigger port " + settings_.device + ": " +
                             std::strerror(errno) + " (is the trigger box plugged in?)");
  termios port{};
  if (::tcgetattr(fd_, &port) != 0) {
    const int error = errno;
    ::close(fd_);
    throw std::runtime_error("the trigger port " + settings_.device +
                             " is not a serial port: " + std::strerror(error));
  }
  ::cfmakeraw(&port);
  port.c_cflag |= CLOCAL;
  port.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB);
  ::cfsetospeed(&port, speedOf(settings_.baud));
  ::cfsetispeed(&port, speedOf(settings_.baud));
  if (::tcsetattr(fd_, TCSANOW, &port) != 0) {
    const int error = errno;
    ::close(fd_);
    throw std::runtime_error("cannot set the trigger port " + settings_.device + " to " +
                             std::to_string(settings_.baud) + " baud: " + std::strerror(error));
  }
}

TriggerOutput::~TriggerOutput() {
  if (fd_ < 0) return;
  if (lines_high_) {
    const std::uint8_t zero = 0;
    [[maybe_unused]] const ssize_t ignored = ::write(fd_, &zero, 1);
  }
  ::close(fd_);
}

void TriggerOutput::presented(std::int64_t frame, double swap_host_s, double called_after_s,
                              const std::vector<Flash>& first_shown,
                              const FeedbackShown* feedback) {
  called_host_s_ = bci::hostSeconds();
  called_at_s_ = swap_host_s + called_after_s;
  if (settings_.pulse && lines_high_) write(0, "reset", frame, swap_host_s);
  for (const Flash& f : first_shown) {
    const int byte = (f.objects ? settings_.object_base : settings_.grid_base) + f.code;
    write(static_cast<std::uint8_t>(byte & 0xff),
          (f.objects ? "object " : "grid ") + std::to_string(f.code), frame, swap_host_s);
  }
  if (feedback && settings_.feedback_byte != 0)
    write(static_cast<std::uint8_t>(settings_.feedback_byte), "feedback", frame, swap_host_s);
}

void TriggerOutput::write(std::uint8_t byte, const std::string& what, std::int64_t frame,
                          double swap_host_s) {
  const ssize_t n = ::write(fd_, &byte, 1);
  const double now = called_at_s_ + (bci::hostSeconds() - called_host_s_);
  if (n != 1) {
    ++failed_;
    fault_ = "the trigger port " + settings_.device +
             " took no byte: " + (n < 0 ? std::strerror(errno) : "nothing written");
    return;
  }
  fault_.clear();
  lines_high_ = byte != 0;
  written_.push_back({byte, what, frame, swap_host_s, now});
}

std::vector<TriggerWrite> TriggerOutput::take() {
  return std::exchange(written_, {});
}

}  // namespace arbci::session
