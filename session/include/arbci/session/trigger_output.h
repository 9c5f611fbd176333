// Triggers out to the amplifier (eeg.trigger_out "serial"): a byte written to a serial port at
// each flash's presentation, so that the amplifier's own file carries every onset, as labs wire a
// USB-TTL trigger box (Brain Products' TriggerBox, a BioSemi USB trigger interface: both serial
// ports that set their output lines to the byte written). The byte is the flash's code as the
// recording has it (objects 1-N, grid rows and columns 100 + code), each shifted by its base;
// with `pulse` the lines go back to 0 on the next frame presented, so that two flashes of the
// same code are two edges. Each write is stamped on the host clock right after it returns, beside
// the swap it follows, and the session logs both ("trigger").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arbci/core/schema.h"

namespace arbci::session {

struct Flash;
struct FeedbackShown;

struct TriggerSettings {
  TriggerSettings();
  std::string device;  // "/dev/ttyUSB0", "/dev/ttyACM0"
  int baud;
  int object_base;    // an object's flash writes object_base + its code
  int grid_base;      // a grid row's or column's writes grid_base + its code
  int feedback_byte;  // written when a selection is shown (0: nothing)
  bool pulse;         // a 0 on the frame after each byte
};
const core::Schema<TriggerSettings>& triggerSchema();
// The choices of eeg.trigger_out.
const std::vector<std::string>& triggerOutputs();

// One byte written.
struct TriggerWrite {
  std::uint8_t byte = 0;
  std::string what;  // "object 2", "row 3", "feedback", "reset"
  std::int64_t frame = 0;
  double swap_host_s = 0.0;     // when the frame it marks reached the screen
  double written_host_s = 0.0;  // when write() returned
};

class TriggerOutput {
 public:
  // Opens the port raw (8 data bits, no parity, one stop bit) at settings.baud. Throws
  // std::runtime_error naming the device and why it cannot be used.
  explicit TriggerOutput(const TriggerSettings& settings);
  ~TriggerOutput();
  TriggerOutput(const TriggerOutput&) = delete;
  TriggerOutput& operator=(const TriggerOutput&) = delete;

  // The frame `frame` reached the screen at `swap_host_s`, showing `first_shown` for the first
  // time (and `feedback`, when it shows a selection): their bytes, in order, at once. This call
  // came `called_after_s` after the swap (0 on a stepped clock, whose swap is now); each write is
  // stamped on the swap's clock, that plus the time the writes took.
  void presented(std::int64_t frame, double swap_host_s, double called_after_s,
                 const std::vector<Flash>& first_shown, const FeedbackShown* feedback);
  // The writes since the last call.
  std::vector<TriggerWrite> take();
  // Why the last write failed (the device gone, its buffer full); empty while writes go out.
  const std::string& fault() const { return fault_; }
  int failedWrites() const { return failed_; }
  const std::string& device() const { return settings_.device; }

 private:
  void write(std::uint8_t byte, const std::string& what, std::int64_t frame, double swap_host_s);

  TriggerSettings settings_;
  int fd_ = -1;
  double called_host_s_ = 0.0, called_at_s_ = 0.0;  // presented()'s call: real, and swap's clock
  bool lines_high_ = false;  // a byte other than 0 is on the lines (pulse: reset next frame)
  std::vector<TriggerWrite> written_;
  std::string fault_;
  int failed_ = 0;
};

}  // namespace arbci::session
