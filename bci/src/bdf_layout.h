// The BDF+ layout ARBCI writes: header fields, 24-bit samples and annotation onsets as text.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

namespace arbci::bci::bdf {

constexpr double kDigitalMin = -8388608.0;
constexpr double kDigitalMax = 8388607.0;
constexpr int kRecordCountOffset = 236;
// Bytes of the annotation signal per record (a multiple of 3: 171 24-bit "samples").
constexpr int kAnnotationBytes = 513;
// Annotation that marks where the signal ends inside the zero-padded last record.
constexpr const char* kEndMarker = "ARBCI end of signal at sample ";

struct Signal {
  std::string label;
  std::string unit;
  double physical_min = 0.0;
  double physical_max = 0.0;
  int samples_per_record = 0;
};

struct HeaderFields {
  std::string subject = "X";
  std::string recording_id = "ARBCI";
  std::time_t start = 0;
  double record_seconds = 0.25;
  std::vector<Signal> signals;  // without the annotation signal
  int annotation_samples = kAnnotationBytes / 3;
};

inline int headerBytes(int signals_with_annotations) {
  return 256 * (signals_with_annotations + 1);
}

// A space-padded ASCII field of exactly `width` characters.
inline std::string field(std::string text, size_t width) {
  for (char& c : text) {
    if (c < 32 || c > 126) c = '_';
  }
  text.resize(width, ' ');
  return text;
}

// Seconds as EDF+ onsets write them: no exponent, no trailing zeros.
inline std::string seconds(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.8f", value);
  std::string out(text);
  while (!out.empty() && out.back() == '0') out.pop_back();
  if (!out.empty() && out.back() == '.') out.pop_back();
  return out.empty() ? "0" : out;
}

// EDF+ subfields are separated by spaces; "X" stands for unknown.
inline std::string noSpaces(std::string text) {
  for (char& c : text) {
    if (c == ' ') c = '_';
  }
  return text.empty() ? "X" : text;
}

inline std::string number(double value, size_t width) {
  for (int decimals = 6; decimals >= 0; --decimals) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", decimals, value);
    std::string out(text);
    if (out.find('.') != std::string::npos) {
      while (out.back() == '0') out.pop_back();
      if (out.back() == '.') out.pop_back();
    }
    if (out.size() <= width) return field(out, width);
  }
  return field(std::to_string(static_cast<long long>(value)), width);
}

// The digital value of a physical one (unclamped, may be NaN).
inline double digital(double physical, double physical_min, double physical_max) {
  return std::round((physical - physical_min) / (physical_max - physical_min) *
                        (kDigitalMax - kDigitalMin) +
                    kDigitalMin);
}

inline void appendInt24(std::string& out, std::int32_t value) {
  const auto bits = static_cast<std::uint32_t>(value);
  out.push_back(static_cast<char>(bits & 0xff));
  out.push_back(static_cast<char>((bits >> 8) & 0xff));
  out.push_back(static_cast<char>((bits >> 16) & 0xff));
}

inline std::string header(const HeaderFields& h) {
  const int ns = static_cast<int>(h.signals.size()) + 1;
  std::tm start{};
  gmtime_r(&h.start, &start);
  static const char* kMonths[] = {"JAN", "FEB", "MAR", "APR", "MAY", "JUN",
                                  "JUL", "AUG", "SEP", "OCT", "NOV", "DEC"};
  char date[32], time_of_day[32], edf_date[32];
  std::snprintf(date, sizeof date, "%02d.%02d.%02d", start.tm_mday, start.tm_mon + 1,
                start.tm_year % 100);
  std::snprintf(time_of_day, sizeof time_of_day, "%02d.%02d.%02d", start.tm_hour, start.tm_min,
                start.tm_sec);
  std::snprintf(edf_date, sizeof edf_date, "%02d-%s-%04d", start.tm_mday, kMonths[start.tm_mon],
                start.tm_year + 1900);

  std::string out;
  out += std::string("\xff") + "BIOSEMI";
  out += field(noSpaces(h.subject) + " X X X", 80);
  out += field(std::string("Startdate ") + edf_date + " " + noSpaces(h.recording_id) + " X X", 80);
  out += field(date, 8) + field(time_of_day, 8);
  out += field(std::to_string(headerBytes(ns)), 8);
  out += field("BDF+C", 44);
  out += field("-1", 8);  // records: updated after each record
  out += number(h.record_seconds, 8);
  out += field(std::to_string(ns), 4);

  std::vector<Signal> all = h.signals;
  all.push_back({"BDF Annotations", "", -1.0, 1.0, h.annotation_samples});
  for (const Signal& s : all) out += field(s.label, 16);
  for (size_t i = 0; i < all.size(); ++i)
    out += field(i + 1 < all.size() ? "AgAgCl electrode" : "", 80);
  for (const Signal& s : all) out += field(s.unit, 8);
  for (const Signal& s : all) out += number(s.physical_min, 8);
  for (const Signal& s : all) out += number(s.physical_max, 8);
  for (size_t i = 0; i < all.size(); ++i) out += field("-8388608", 8);
  for (size_t i = 0; i < all.size(); ++i) out += field("8388607", 8);
  for (size_t i = 0; i < all.size(); ++i) out += field("", 80);
  for (const Signal& s : all) out += field(std::to_string(s.samples_per_record), 8);
  for (size_t i = 0; i < all.size(); ++i) out += field("", 32);
  return out;
}

}  // namespace arbci::bci::bdf
