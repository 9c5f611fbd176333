// XDF (LabRecorder's format) by a reader of our own: the EEG stream as the recording, the string
// streams' markers as its stimuli and annotations. (Debian's libxdf 0.99.8 crashed on the public
// example files and on files cut short; the parser in xdf/ checks every length instead.)
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>

#include "arbci/bci/recording.h"
#include "arbci/bci/units.h"
#include "arbci/core/text.h"
#include "xdf/xdf_clock.h"
#include "xdf/xdf_file.h"

namespace arbci::bci {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw RecordingError(path.string() + ": " + what);
}

// ARBCI's markers ("flash <code> target|nontarget|unknown"), "<code> [target|nontarget]" or a bare
// code are stimuli; anything else is an annotation.
bool asStimulus(const std::string& text, StimulusEvent& event) {
  std::istringstream words(text);
  std::string first;
  if (!(words >> first)) return false;
  if (first == "flash" && !(words >> first)) return false;
  try {
    size_t used = 0;
    event.code = std::stoi(first, &used);
    if (used != first.size() || event.code <= 0) return false;
  } catch (const std::exception&) {
    return false;
  }
  std::string label;
  words >> label;
  event.known = label == "target" || label == "nontarget";
  event.target = label == "target";
  std::string rest;
  return !(words >> rest);  // nothing more
}

// How a stream is named in messages.
std::string quoted(const xdf::Stream& s) {
  return std::to_string(s.id) + " (\"" + s.name + "\")";
}

std::string describe(const xdf::Stream& s) {
  std::ostringstream out;
  out << s.channel_count << " " << s.format << " channel(s), ";
  if (s.nominal_rate > 0)
    out << s.nominal_rate << " Hz";
  else
    out << "irregular";
  out << ", " << s.samples() << " samples";
  return out.str();
}

}  // namespace

Recording readXdf(const std::filesystem::path& path, const ReadOptions& options) {
  const xdf::File file = xdf::parse(path);
  std::string cut, footer_note;
  if (file.cut_short) {
    cut = "cut short at byte " + std::to_string(file.whole_bytes) + " (a recording interrupted?)";
  } else {
    // LabRecorder writes each stream's footer when the recording stops: without them the file was
    // cut (at a chunk's end) before it was closed.
    // A stream that never had a sample may have no footer in a file closed properly (pyxdf
    // reads such files): only a stream with samples and no footer says the file was cut.
    std::string missing, empty_without;
    for (const xdf::Stream& s : file.streams) {
      if (s.footer) continue;
      std::string& list = s.samples() > 0 ? missing : empty_without;
      list += (list.empty() ? "" : ", ") + quoted(s);
    }
    if (missing.empty() && !empty_without.empty())
      footer_note = "stream " + empty_without + " has no samples and no footer (read as empty)";
    if (!missing.empty())
      cut = "ends without the footer of stream " + missing +
            " (the recording was not closed: cut short at a chunk's end?)";
  }
  if (!cut.empty() && !options.salvage_truncated)
    fail(path, cut + "; --salvage reads what it holds");
  // The EEG: the first regular numeric stream of type EEG with samples, else the regular numeric
  // one with most channels (and samples).
  const xdf::Stream* eeg = nullptr;
  for (const xdf::Stream& s : file.streams) {
    if (s.nominal_rate <= 0 || !s.numeric() || s.samples() == 0) continue;
    if (core::lowerCase(s.type) == "eeg") {
      eeg = &s;
      break;
    }
    if (!eeg || s.channel_count > eeg->channel_count) eeg = &s;
  }
  if (!eeg) {
    std::string streams;
    for (const xdf::Stream& s : file.streams)
      streams += std::string(streams.empty() ? "" : "; ") + quoted(s) + ": " + describe(s);
    fail(path, "has no regular numeric stream with samples (no EEG to read); its streams: " +
                   (streams.empty() ? std::string("none") : streams));
  }
  Recording r;
  r.source = path.string();
  r.format = "XDF";
  r.info.rate_hz = eeg->nominal_rate;
  const int channels = eeg->channel_count;
  std::vector<double> scale(static_cast<size_t>(channels), 1.0);
  for (int c = 0; c < channels; ++c) {
    const auto k = static_cast<size_t>(c);
    const std::string label = k < eeg->labels.size() ? eeg->labels[k] : "";
    if (k < eeg->units.size()) scale[k] = microvoltsPer(eeg->units[k]);
    r.info.channels.push_back(label.empty() ? "Ch" + std::to_string(c + 1) : label);
  }
  r.samples = static_cast<std::int64_t>(eeg->samples());
  r.data.resize(static_cast<size_t>(channels) * static_cast<size_t>(r.samples));
  for (std::int64_t s = 0; s < r.samples; ++s)
    for (int c = 0; c < channels; ++c)
      r.data[static_cast<size_t>(c) * r.samples + s] = static_cast<float>(
          eeg->values[static_cast<size_t>(s) * channels + c] * scale[static_cast<size_t>(c)]);
  if (!footer_note.empty()) r.notes.push_back(footer_note);
  if (std::string note = nonVoltageNote(r.info.channels, eeg->units); !note.empty())
    r.notes.push_back(std::move(note));
  r.parameters["XdfStream"] = eeg->name;
  r.parameters["XdfStreamType"] = eeg->type;
  if (!cut.empty()) {
    r.truncated = true;
    r.truncation_note = cut + "; read up to its last whole chunk";
  }

  xdf::ClockReport eeg_clock;
  const std::vector<double> stamps = xdf::recorderStamps(*eeg, eeg_clock);
  if (eeg_clock.resets > 0)
    r.notes.push_back("the EEG stream's clock was reset " + std::to_string(eeg_clock.resets) +
                      " time(s); its stamps were re-anchored on the recorder's clock");
  for (const auto& b : eeg_clock.breaks) {
    char text[200];
    std::snprintf(text, sizeof text,
                  b.seconds >= 0 ? "XDF: %.3f s without EEG samples before this one (joined here; "
                                   "events keep their samples)"
                                 : "XDF: the EEG's stamps step back %.3f s here",
                  std::abs(b.seconds));
    r.annotations.push_back({static_cast<std::int64_t>(b.sample), text, 0});
  }
  if (!eeg_clock.breaks.empty())
    r.notes.push_back(std::to_string(eeg_clock.breaks.size()) +
                      " break(s) in the EEG's stamps, each annotated where it falls");
  if (eeg_clock.outliers > 0) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "%zu EEG stamp(s) that no line through their neighbours explains (the furthest "
                  "%.3g s off) were left out of the stamps' fit: their samples keep the places "
                  "the line gives them, and no marker moved",
                  eeg_clock.outliers, eeg_clock.largest_outlier_s);
    r.notes.push_back(text);
  }

  // Markers: each at the EEG sample nearest its time (docs/eeg.md, "One marker rule"). The
  // EEG's fitted stamps are exact to a few microseconds, not to zero: a marker stamped on a
  // sample's time (as ARBCI's own outlets stamp them) falls a hair before or after it, and the
  // nearest sample is that one whichever side; one stamped in between lands within half a period.
  const double period = 1.0 / r.info.rate_hz;
  const double slack = period / 2.0;
  int before = 0, after = 0, marker_resets = 0;
  for (const xdf::Stream& s : file.streams) {
    if (s.numeric()) continue;
    for (const auto& [name, value] : s.parameters) r.parameters[name] = value;
    xdf::ClockReport clock;
    const std::vector<double> times = xdf::recorderStamps(s, clock);
    marker_resets += clock.resets;
    for (size_t k = 0; k < s.samples(); ++k) {
      const double at = times[k];
      if (at < stamps.front() - slack) {
        ++before;
        continue;
      }
      if (at > stamps.back() + slack) {
        ++after;
        continue;
      }
      auto found = std::lower_bound(stamps.begin(), stamps.end(), at);
      if (found == stamps.end() || (found != stamps.begin() && at - *(found - 1) <= *found - at))
        --found;
      const std::int64_t sample = found - stamps.begin();
      const std::vector<std::string>& texts = s.strings[k];
      StimulusEvent stimulus;
      stimulus.sample = sample;
      if (asStimulus(texts[0], stimulus))
        r.stimuli.push_back(stimulus);
      else
        r.annotations.push_back({sample, texts[0], 0});
      // A marker of several channels: the first is the event, the rest kept beside it.
      std::string rest;
      for (size_t c = 1; c < texts.size(); ++c) rest += (c > 1 ? " | " : "") + texts[c];
      if (texts.size() > 1) r.annotations.push_back({sample, "marker detail: " + rest, 0});
    }
  }
  if (marker_resets > 0)
    r.notes.push_back("the marker streams' clocks were reset " + std::to_string(marker_resets) +
                      " time(s); their stamps were re-anchored on the recorder's clock");
  if (before + after > 0)
    r.notes.push_back(std::to_string(before) + " marker(s) before the EEG's first sample and " +
                      std::to_string(after) + " after its last were left out");
  std::stable_sort(
      r.stimuli.begin(), r.stimuli.end(),
      [](const StimulusEvent& a, const StimulusEvent& b) { return a.sample < b.sample; });
  std::stable_sort(r.annotations.begin(), r.annotations.end(),
                   [](const Annotation& a, const Annotation& b) { return a.sample < b.sample; });
  return r;
}

}  // namespace arbci::bci
