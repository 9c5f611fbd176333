#include "support/xdf_writer.h"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

namespace arbci::test {
namespace {

template <typename T>
void put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

// XDF's variable-length integer: a byte saying 1, 4 or 8, then the value.
void putLength(std::string& out, std::uint64_t n) {
  if (n < 256) {
    out += static_cast<char>(1);
    out += static_cast<char>(n);
  } else if (n <= 0xffffffffu) {
    out += static_cast<char>(4);
    put(out, static_cast<std::uint32_t>(n));
  } else {
    out += static_cast<char>(8);
    put(out, n);
  }
}

void chunk(std::ofstream& file, std::uint16_t tag, const std::string& content) {
  std::string out;
  putLength(out, content.size() + 2);
  put(out, tag);
  file << out << content;
}

std::string withStream(std::uint32_t id, const std::string& rest) {
  std::string out;
  put(out, id);
  return out + rest;
}

}  // namespace

void writeXdf(const std::filesystem::path& path, const XdfNumericStream& eeg,
              const std::vector<XdfMarker>& markers, const XdfExtras& extras) {
  std::ofstream file(path, std::ios::binary);
  file << "XDF:";
  chunk(file, 1, "<?xml version=\"1.0\"?><info><version>1.0</version></info>");
  std::string channels;
  for (const auto& l : eeg.labels)
    channels +=
        "<channel><label>" + l + "</label><unit>" + eeg.unit + "</unit><type>EEG</type></channel>";
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.17g", eeg.rate);
  chunk(file, 2,
        withStream(1, "<?xml version=\"1.0\"?><info><name>" + eeg.name + "</name><type>" +
                          eeg.type + "</type><channel_count>" + std::to_string(eeg.labels.size()) +
                          "</channel_count><nominal_srate>" + rate +
                          "</nominal_srate><channel_format>float32</channel_format>"
                          "<created_at>50.0</created_at><desc><channels>" +
                          channels + "</channels></desc></info>"));
  std::string parameters;
  for (const auto& [name, value] : extras.marker_parameters)
    parameters += "<parameter name=\"" + name + "\">" + value + "</parameter>";
  chunk(file, 2,
        withStream(2, "<?xml version=\"1.0\"?><info><name>" + eeg.name +
                          "-Markers</name>"
                          "<type>Markers</type><channel_count>" +
                          std::to_string(extras.marker_channels) +
                          "</channel_count><nominal_srate>0"
                          "</nominal_srate><channel_format>string</channel_format>"
                          "<created_at>50.0</created_at><desc><arbci>" +
                          parameters + "</arbci></desc></info>"));
  if (extras.empty_stream) {
    chunk(file, 2,
          withStream(3,
                     "<?xml version=\"1.0\"?><info><name>Empty</name><type>EEG</type>"
                     "<channel_count>2</channel_count><nominal_srate>100</nominal_srate>"
                     "<channel_format>float32</channel_format><desc/></info>"));
  }
  const size_t n = eeg.samples.size();
  auto stamp = [&](size_t s) {
    return extras.eeg_stamps.empty() ? eeg.first_timestamp + static_cast<double>(s) / eeg.rate
                                     : extras.eeg_stamps[s];
  };
  for (size_t first = 0; first < n; first += 100) {
    const size_t count = std::min<size_t>(100, n - first);
    std::string content;
    putLength(content, count);
    for (size_t s = first; s < first + count; ++s) {
      content += static_cast<char>(8);
      put(content, stamp(s));
      for (float v : eeg.samples[s]) put(content, v);
    }
    chunk(file, 3, withStream(1, content));
  }
  for (const auto& m : markers) {
    std::string content;
    putLength(content, 1);
    content += static_cast<char>(8);
    put(content, m.timestamp);
    for (int c = 0; c < extras.marker_channels; ++c) {
      const std::string& text = c == 0 ? m.text
                                : static_cast<size_t>(c) <= m.more.size()
                                    ? m.more[static_cast<size_t>(c - 1)]
                                    : std::string();
      putLength(content, text.size());
      content += text;
    }
    chunk(file, 3, withStream(2, content));
  }
  const std::vector<std::pair<double, double>> one{{eeg.first_timestamp, 0.0}};
  for (std::uint32_t id : {1u, 2u}) {
    const auto& offsets = id == 1 ? extras.eeg_offsets : extras.marker_offsets;
    for (const auto& [time, value] : offsets.empty() ? one : offsets) {
      std::string content;
      put(content, time);
      put(content, value);
      chunk(file, 4, withStream(id, content));
    }
  }
  if (!extras.footers) return;
  char last[32];
  std::snprintf(last, sizeof last, "%.17g", n > 0 ? stamp(n - 1) : 0.0);
  chunk(
      file, 6,
      withStream(1, "<?xml version=\"1.0\"?><info><first_timestamp>" +
                        std::to_string(eeg.first_timestamp) + "</first_timestamp><last_timestamp>" +
                        last + "</last_timestamp><sample_count>" + std::to_string(n) +
                        "</sample_count></info>"));
  chunk(file, 6,
        withStream(2, "<?xml version=\"1.0\"?><info><sample_count>" +
                          std::to_string(markers.size()) + "</sample_count></info>"));
  if (extras.empty_stream && extras.empty_stream_footer)
    chunk(file, 6,
          withStream(3,
                     "<?xml version=\"1.0\"?><info><sample_count>0</sample_count>"
                     "</info>"));
}

}  // namespace arbci::test
