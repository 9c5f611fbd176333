#include "arbci/bci/eegdev_source.h"

#include <eegdev.h>

#include <cerrno>
#include <cmath>
#include <cstring>

namespace arbci::bci {
namespace {

double microvoltsPer(const std::string& unit) {
  std::string u;
  for (char c : unit) u += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (u == "v" || u == "volt" || u == "volts") return 1e6;
  if (u == "mv" || u == "millivolt" || u == "millivolts") return 1e3;
  return 1.0;  // uV (eegdev's usual unit), or not said
}

}  // namespace

void EegdevSource::Closer::operator()(eegdev* device) const {
  egd_stop(device);
  egd_close(device);
}

EegdevSource::EegdevSource(const EegdevSourceSettings& settings) : settings_(settings) {
  const std::string where = "eegdev device \"" + settings.device + "\"";
  errno = 0;
  device_.reset(egd_open(settings.device.c_str()));
  if (!device_) {
    const int error = errno;
    std::string why = error == ENOSYS   ? "no installed eegdev plugin serves this device"
                      : error == ENODEV ? "the device is not connected"
                      : error == EBUSY  ? "the device is in use by another program"
                      : error != 0      ? std::strerror(error)
                                        : "not opened";
    throw EegdevError(where + ": cannot open it (" + why +
                      "). The string is device|option|value|..., e.g. datafile|path|/data/s01.bdf, "
                      "biosemi, tobiia|host|amp-pc|port|38500");
  }
  int rate = 0;
  egd_get_cap(device_.get(), EGD_CAP_FS, &rate);
  if (rate <= 0)
    throw EegdevError(where + ": reports no valid sampling rate (" + std::to_string(rate) +
                      "). The datafile device reads BDF/EDF/GDF through xdffileio, which needs "
                      "1-second records and no annotation channel");
  if (settings.expected_rate_hz > 0 && std::abs(rate - settings.expected_rate_hz) > 1e-6)
    throw EegdevError(
        where + " samples at " + std::to_string(rate) + " Hz but the session expects " +
        std::to_string(settings.expected_rate_hz) +
        " Hz (eeg.rate_hz); ARBCI does not resample: set eeg.rate_hz to the device's rate");
  const int eeg = egd_sensor_type("eeg");
  const int channels = egd_get_numch(device_.get(), eeg);
  if (channels <= 0) throw EegdevError(where + ": has no EEG channels");
  info_.rate_hz = rate;
  info_.block_size = std::max(1, settings.block_size);
  for (int c = 0; c < channels; ++c) {
    char label[64] = "", unit[32] = "";
    egd_channel_info(device_.get(), eeg, static_cast<unsigned>(c), EGD_LABEL, label, EGD_UNIT, unit,
                     EGD_EOL);
    info_.channels.push_back(label[0] ? label : "Ch" + std::to_string(c + 1));
    scale_.push_back(microvoltsPer(unit));
  }
  const char* type = nullptr;
  if (egd_get_cap(device_.get(), EGD_CAP_DEVTYPE, &type) > 0 && type) device_type_ = type;
  const size_t stride = static_cast<size_t>(channels) * sizeof(float);
  grpconf group{eeg, 0, static_cast<unsigned>(channels), 0, 0, EGD_FLOAT};
  if (egd_acq_setup(device_.get(), 1, &stride, 1, &group) != 0)
    throw EegdevError(where + ": cannot set up the acquisition (" + std::strerror(errno) + ")");
  if (egd_start(device_.get()) != 0)
    throw EegdevError(where + ": cannot start the acquisition (" + std::strerror(errno) + ")");
}

EegdevSource::~EegdevSource() = default;

std::vector<Block> EegdevSource::poll(int max_blocks) {
  std::vector<Block> out;
  if (!fault_.empty()) return out;
  const int channels = info_.channelCount();
  const ssize_t available = egd_get_available(device_.get());
  if (available < 0) {
    const int error = errno;
    fault_ = "eegdev device \"" + settings_.device + "\" stopped: " +
             (error == EAGAIN   ? std::string("connection lost (a cable, or the power)")
              : error == EIO    ? std::string("synchronisation lost")
              : error == ENOMEM ? std::string("its buffer overflowed, or the file ended")
                                : std::string(std::strerror(error)));
    return out;
  }
  const size_t wanted = std::min<size_t>(static_cast<size_t>(available),
                                         static_cast<size_t>(max_blocks) * info_.block_size);
  if (wanted > 0) {
    std::vector<float> samples(wanted * channels);
    const ssize_t read = egd_get_data(device_.get(), wanted, samples.data());
    if (read > 0)
      pending_.insert(pending_.end(), samples.begin(), samples.begin() + read * channels);
  }
  const size_t per_block = static_cast<size_t>(info_.block_size) * channels;
  size_t used = 0;
  while (pending_.size() - used >= per_block) {
    Block block(next_sample_, channels, info_.block_size);
    for (int s = 0; s < info_.block_size; ++s)
      for (int c = 0; c < channels; ++c)
        block.at(c, s) =
            static_cast<float>(pending_[used + static_cast<size_t>(s) * channels + c] * scale_[c]);
    used += per_block;
    next_sample_ += info_.block_size;
    out.push_back(std::move(block));
  }
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(used));
  return out;
}

std::string EegdevSource::describe() const {
  return "eegdev \"" + settings_.device + "\" (" +
         (device_type_.empty() ? "device" : device_type_) +
         "): " + std::to_string(info_.channelCount()) + " EEG channels at " +
         std::to_string(static_cast<int>(info_.rate_hz)) + " Hz";
}

}  // namespace arbci::bci
