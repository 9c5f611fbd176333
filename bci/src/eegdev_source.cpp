#include "arbci/bci/eegdev_source.h"

#include <eegdev.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "arbci/bci/units.h"

namespace arbci::bci {
namespace {

// The labels of a device's channels of sensor type `type`, comma-separated.
std::string labelsOf(eegdev* device, const char* type) {
  const int stype = egd_sensor_type(type);
  const int count = egd_get_numch(device, stype);
  std::string out;
  for (int c = 0; c < count; ++c) {
    char label[64] = "";
    egd_channel_info(device, stype, static_cast<unsigned>(c), EGD_LABEL, label, EGD_EOL);
    out += (out.empty() ? "" : ", ") + std::string(label[0] ? label : "(no label)");
  }
  return out;
}

// eegdev decides a channel's type from its label (checked on BDF files played by its datafile
// device): EEG when the label starts with "EEG", "E" and a number, or a 10-20/10-10 electrode
// name as usually written (Fz, Cz, Fp1, AF3, T7, TP9, ...); "Status" is the trigger; anything
// else (Ch1, EXG1, M1, a lower-case "fz") is "undefined" and not EEG.
std::string whyNoEeg(eegdev* device) {
  const std::string undefined = labelsOf(device, "undefined");
  return std::string(
             " (eegdev takes a channel as EEG only when its label starts with \"EEG\", \"E\" and "
             "a number, or a 10-20 electrode name as usually written: Fz, Cz, Fp1, AF3, T7, ...)") +
         (undefined.empty() ? ""
                            : "; its other channels are labelled " + undefined +
                                  " (relabel them, or read the "
                                  "file with eeg.source \"file\", which takes every "
                                  "channel)");
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
  if (channels <= 0) throw EegdevError(where + ": has no EEG channels" + whyNoEeg(device_.get()));
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
  // eegdev reports an error only once every sample before it has been read.
  const ssize_t available = egd_get_available(device_.get());
  if (available < 0) {
    const int error = errno;
    // The samples short of a whole block are delivered too: nothing read is lost at a fault.
    const size_t partial = pending_.size() / static_cast<size_t>(channels);
    if (partial > 0) out.push_back(takeBlock(static_cast<int>(partial)));
    const bool file = settings_.device.rfind("datafile", 0) == 0;
    const std::string samples = std::to_string(next_sample_) + " samples";
    fault_ =
        "eegdev device \"" + settings_.device + "\" stopped: " +
        (file && (error == EAGAIN || error == ENOMEM) ? "the file ended (" + samples + " played)"
         : error == EAGAIN ? "connection lost (a cable, or the power) after " + samples
         : error == EIO    ? "synchronisation lost after " + samples
         : error == ENOMEM ? "its buffer overflowed after " + samples
                           : std::string(std::strerror(error)) + " after " + samples);
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
  while (pending_.size() >= per_block) out.push_back(takeBlock(info_.block_size));
  return out;
}

Block EegdevSource::takeBlock(int samples) {
  const int channels = info_.channelCount();
  Block block(next_sample_, channels, samples);
  for (int s = 0; s < samples; ++s)
    for (int c = 0; c < channels; ++c)
      block.at(c, s) =
          static_cast<float>(pending_[static_cast<size_t>(s) * channels + c] * scale_[c]);
  pending_.erase(pending_.begin(),
                 pending_.begin() + static_cast<std::ptrdiff_t>(samples) * channels);
  next_sample_ += samples;
  return block;
}

std::string EegdevSource::describe() const {
  return "eegdev \"" + settings_.device + "\" (" +
         (device_type_.empty() ? "device" : device_type_) +
         "): " + std::to_string(info_.channelCount()) + " EEG channels at " +
         std::to_string(static_cast<int>(info_.rate_hz)) + " Hz";
}

}  // namespace arbci::bci
