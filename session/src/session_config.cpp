#include "arbci/session/session_config.h"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "arbci/assets.h"

namespace arbci::session {
namespace {

using Json = nlohmann::json;

// One object of the file with its dotted path, for messages. Reading the embedded defaults, every
// key must be there: the embedded file is the one place a default lives (a value in code would
// be a second one that could disagree).
class Section {
 public:
  Section(const Json& json, std::string path, std::string file, bool defaults = false)
      : json_(json), path_(std::move(path)), file_(std::move(file)), defaults_(defaults) {
    if (!json_.is_object()) fail("", "must be an object");
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw SessionConfigError(file_ + ": " + name(key) + " " + what);
  }
  std::string name(const std::string& key) const {
    return path_.empty() ? key : key.empty() ? path_ : path_ + "." + key;
  }
  bool has(const std::string& key) const { return json_.contains(key); }
  const Json& at(const std::string& key) const { return json_.at(key); }
  Section section(const std::string& key) const {
    static const Json empty = Json::object();
    if (!has(key)) missing(key);
    return Section(has(key) ? json_.at(key) : empty, name(key), file_, defaults_);
  }
  // A key the file leaves out keeps its value; the embedded defaults may leave none out.
  void missing(const std::string& key) const {
    if (defaults_)
      fail(key, "has no default: the embedded session file must set every key (add it there)");
  }
  void known(std::initializer_list<const char*> keys) const {
    std::set<std::string> allowed(keys.begin(), keys.end());
    for (const auto& [key, value] : json_.items()) {
      if (!allowed.count(key)) {
        std::string list;
        for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
        fail(key, "is not a known key (known here: " + list + ")");
      }
    }
  }
  double number(const std::string& key, double fallback, double low, double high) const {
    if (!has(key)) {
      missing(key);
      return fallback;
    }
    if (!at(key).is_number()) fail(key, "= " + at(key).dump() + " must be a number");
    const double v = at(key).get<double>();
    if (!(v >= low && v <= high))
      fail(key, "= " + at(key).dump() + " must lie in [" + fmt(low) + ", " + fmt(high) + "]");
    return v;
  }
  int integer(const std::string& key, int fallback, int low, int high) const {
    if (!has(key)) {
      missing(key);
      return fallback;
    }
    if (!at(key).is_number_integer()) fail(key, "= " + at(key).dump() + " must be an integer");
    const int v = at(key).get<int>();
    if (v < low || v > high)
      fail(key, "= " + std::to_string(v) + " must lie in [" + std::to_string(low) + ", " +
                    std::to_string(high) + "]");
    return v;
  }
  bool boolean(const std::string& key, bool fallback) const {
    if (!has(key)) {
      missing(key);
      return fallback;
    }
    if (!at(key).is_boolean()) fail(key, "= " + at(key).dump() + " must be true or false");
    return at(key).get<bool>();
  }
  std::string text(const std::string& key, const std::string& fallback,
                   std::initializer_list<const char*> allowed = {}) const {
    if (!has(key)) {
      missing(key);
      return fallback;
    }
    if (!at(key).is_string()) fail(key, "= " + at(key).dump() + " must be a string");
    const std::string v = at(key).get<std::string>();
    if (allowed.size() > 0) {
      std::string list;
      bool ok = false;
      for (const char* a : allowed) {
        ok |= v == a;
        list += (list.empty() ? "" : ", ") + std::string(a);
      }
      if (!ok) fail(key, "= \"" + v + "\" must be one of " + list);
    }
    return v;
  }
  std::vector<double> numbers(const std::string& key, const std::vector<double>& fallback,
                              size_t min_size, size_t max_size) const {
    if (!has(key)) {
      missing(key);
      return fallback;
    }
    const Json& j = at(key);
    if (!j.is_array() || j.size() < min_size || j.size() > max_size) {
      std::string count = std::to_string(min_size);
      if (max_size != min_size) count.append(1, '-').append(std::to_string(max_size));
      fail(key, "= " + j.dump() + " must be a list of " + count + " numbers");
    }
    std::vector<double> out;
    for (const Json& v : j) {
      if (!v.is_number()) fail(key, "= " + j.dump() + " must contain numbers only");
      out.push_back(v.get<double>());
    }
    return out;
  }
  cv::Vec3d vec3(const std::string& key, const cv::Vec3d& fallback) const {
    const auto v = numbers(key, {fallback[0], fallback[1], fallback[2]}, 3, 3);
    return {v[0], v[1], v[2]};
  }

 private:
  static std::string fmt(double v) {
    std::string s = std::to_string(v);
    while (s.find('.') != std::string::npos && (s.back() == '0' || s.back() == '.')) {
      const bool dot = s.back() == '.';
      s.pop_back();
      if (dot) break;
    }
    return s;
  }
  const Json& json_;
  std::string path_, file_;
  bool defaults_ = false;
};

void parseCameras(const Section& s, CameraSettings& c) {
  s.known({"source", "rate_hz", "width", "height", "focal_px", "distortion", "baseline_m",
           "head_position", "look_at", "head_motion_m", "head_motion_deg", "noise", "blur_px",
           "left", "right", "stereo_calibration"});
  c.source = s.text("source", c.source, {"simulated", "devices"});
  c.rate_hz = s.number("rate_hz", c.rate_hz, 1.0, 240.0);
  c.width = s.integer("width", c.width, 64, 4096);
  c.height = s.integer("height", c.height, 48, 4096);
  c.focal_px = s.number("focal_px", c.focal_px, 10.0, 1e5);
  c.distortion = s.numbers("distortion", c.distortion, 0, 8);
  c.baseline_m = s.number("baseline_m", c.baseline_m, 0.0, 0.5);
  c.head_position = s.vec3("head_position", c.head_position);
  c.look_at = s.vec3("look_at", c.look_at);
  c.head_motion_m = s.number("head_motion_m", c.head_motion_m, 0.0, 0.2);
  c.head_motion_deg = s.number("head_motion_deg", c.head_motion_deg, 0.0, 20.0);
  c.noise = s.number("noise", c.noise, 0.0, 50.0);
  c.blur_px = s.number("blur_px", c.blur_px, 0.0, 10.0);
  c.stereo_calibration = s.text("stereo_calibration", c.stereo_calibration);
  for (const char* side : {"left", "right"}) {
    if (!s.has(side)) continue;
    const Section cam = s.section(side);
    cam.known({"device", "video", "calibration"});
    CameraSource& source = std::string(side) == "left" ? c.left : c.right;
    source.device = cam.integer("device", -1, -1, 63);
    source.video = cam.text("video", "");
    source.calibration = cam.text("calibration", "");
    if (source.device < 0 && source.video.empty())
      cam.fail("", "needs a device number or a video file");
    if (source.calibration.empty())
      cam.fail("calibration", "is required: the camera's calibration file (arbci calibrate)");
  }
  if (c.source == "devices" && c.left.device < 0 && c.left.video.empty())
    s.fail("left", "is required when source is \"devices\"");
}

void parseWorld(const Section& s, const std::string& file, WorldSettings& w) {
  s.known({"table_z", "reference", "objects", "grid"});
  w.table_z = s.number("table_z", w.table_z, -2.0, 2.0);
  const Section ref = s.section("reference");
  ref.known({"id", "size_m", "position"});
  w.reference_id = ref.integer("id", w.reference_id, 0, 4095);
  w.reference_size_m = ref.number("size_m", w.reference_size_m, 0.005, 1.0);
  w.reference_position = ref.vec3("position", w.reference_position);
  if (s.has("objects")) {
    if (!s.at("objects").is_array() || s.at("objects").empty())
      s.fail("objects", "must be a non-empty list");
    w.objects.clear();
    for (size_t i = 0; i < s.at("objects").size(); ++i) {
      const Section o(s.at("objects")[i], s.name("objects") + "[" + std::to_string(i) + "]", file);
      o.known({"id", "position", "marker_m", "width_m", "height_m", "color"});
      WorldObjectSettings object;
      object.id = o.integer("id", -1, 0, 4095);
      if (object.id < 0) o.fail("id", "is required (the object's marker id)");
      if (object.id == w.reference_id)
        o.fail("id", "= " + std::to_string(object.id) + " is the reference marker's id");
      if (!o.has("position"))
        o.fail("position", "is required: [x, y, z] of the top centre in metres");
      object.position = o.vec3("position", {});
      object.marker_m = o.number("marker_m", object.marker_m, 0.005, 0.5);
      object.width_m = o.number("width_m", object.width_m, object.marker_m, 0.6);
      object.height_m = o.number("height_m", object.height_m, 0.005, 0.6);
      object.color = o.vec3("color", object.color);
      for (const auto& other : w.objects) {
        if (other.id == object.id)
          o.fail("id", "= " + std::to_string(object.id) + " is used twice");
      }
      w.objects.push_back(object);
    }
  }
  const Section g = s.section("grid");
  g.known({"rows", "columns", "cell_m", "centre"});
  w.grid.rows = g.integer("rows", w.grid.rows, 1, 12);
  w.grid.columns = g.integer("columns", w.grid.columns, 1, 12);
  if (w.grid.rows * w.grid.columns < 2) g.fail("", "needs at least 2 cells");
  w.grid.cell_m = g.number("cell_m", w.grid.cell_m, 0.01, 1.0);
  w.grid.centre = g.vec3("centre", w.grid.centre);
}

// `defaults`: this is the embedded session file, which must set every key.
void parse(const Json& json, const std::string& file, SessionConfig& c, bool defaults) {
  const Section root(json, "", file, defaults);
  root.known({"description", "display_hz", "hmd", "cameras", "tracker", "world", "eeg", "lsl",
              "paradigm", "classifier", "errp", "robot"});
  c.display_hz = root.number("display_hz", c.display_hz, 10.0, 500.0);
  const Section hmd = root.section("hmd");
  hmd.known({"width", "height", "undistort", "mirror_monitor"});
  c.hmd_width = hmd.integer("width", c.hmd_width, 64, 8192);
  c.hmd_height = hmd.integer("height", c.hmd_height, 48, 8192);
  c.undistort = hmd.boolean("undistort", c.undistort);
  c.mirror_monitor = hmd.integer("mirror_monitor", c.mirror_monitor, -1, 15);
  parseCameras(root.section("cameras"), c.cameras);
  const Section tracker = root.section("tracker");
  tracker.known({"kind", "border", "search_decimate", "max_pose_age_s"});
  c.tracker_kind = tracker.text("kind", c.tracker_kind, {"bch", "simple"});
  c.tracker_border = tracker.number("border", c.tracker_border, 0.05, 0.4);
  c.tracker_search_decimate = tracker.integer("search_decimate", c.tracker_search_decimate, 1, 2);
  c.max_pose_age_s = tracker.number("max_pose_age_s", c.max_pose_age_s, 0.05, 10.0);
  const Section world_section = root.section("world");
  parseWorld(world_section, file, c.world);
  if (c.world.objects.size() < 2) world_section.fail("objects", "must name at least 2 objects");

  const Section eeg = root.section("eeg");
  eeg.known({"source", "seed", "montage", "rate_hz", "block_size", "line_hz", "erp_scale",
             "errp_scale", "file", "photodiode_channel", "latency_ms", "lsl", "eegdev"});
  c.eeg.source = eeg.text("source", c.eeg.source, {"simulated", "file", "lsl", "eegdev"});
  c.eeg.seed =
      static_cast<std::uint64_t>(eeg.integer("seed", static_cast<int>(c.eeg.seed), 0, 1 << 30));
  if (eeg.has("montage")) {
    if (!eeg.at("montage").is_array() || eeg.at("montage").empty())
      eeg.fail("montage", "must be a list of channel names");
    c.eeg.montage = eeg.at("montage").get<std::vector<std::string>>();
  }
  c.eeg.rate_hz = eeg.number("rate_hz", c.eeg.rate_hz, 64.0, 4096.0);
  c.eeg.block_size = eeg.integer("block_size", c.eeg.block_size, 1, 4096);
  c.eeg.line_hz = eeg.number("line_hz", c.eeg.line_hz, 0.0, 70.0);
  c.eeg.erp_scale = eeg.number("erp_scale", c.eeg.erp_scale, 0.0, 10.0);
  c.eeg.errp_scale = eeg.number("errp_scale", c.eeg.errp_scale, 0.0, 10.0);
  c.eeg.file = eeg.text("file", c.eeg.file);
  c.eeg.photodiode_channel = eeg.text("photodiode_channel", c.eeg.photodiode_channel);
  c.eeg.latency_ms = eeg.number("latency_ms", c.eeg.latency_ms, 0.0, 1000.0);
  if (c.eeg.source == "file" && c.eeg.file.empty())
    eeg.fail("file", "is required when source is \"file\"");
  const Section eeg_lsl = eeg.section("lsl");
  eeg_lsl.known({"name", "type", "resolve_timeout_s"});
  c.eeg.lsl_name = eeg_lsl.text("name", c.eeg.lsl_name);
  c.eeg.lsl_type = eeg_lsl.text("type", c.eeg.lsl_type);
  c.eeg.lsl_resolve_timeout_s =
      eeg_lsl.number("resolve_timeout_s", c.eeg.lsl_resolve_timeout_s, 0.1, 600.0);
  if (c.eeg.source == "lsl" && c.eeg.lsl_name.empty() && c.eeg.lsl_type.empty())
    eeg_lsl.fail("name", "or type is required when eeg.source is \"lsl\"");

  const Section eeg_eegdev = eeg.section("eegdev");
  eeg_eegdev.known({"device"});
  c.eeg.eegdev_device = eeg_eegdev.text("device", c.eeg.eegdev_device);
  if (c.eeg.source == "eegdev" && c.eeg.eegdev_device.empty())
    eeg_eegdev.fail("device",
                    "is required when eeg.source is \"eegdev\" (e.g. \"biosemi\", "
                    "\"datafile|path|/data/s01.bdf\")");

  const Section lsl = root.section("lsl");
  lsl.known({"scope", "known_peers", "markers", "marker_stream"});
  c.lsl.scope = lsl.text("scope", c.lsl.scope, {"", "machine", "link", "site"});
  if (lsl.has("known_peers")) {
    if (!lsl.at("known_peers").is_array()) lsl.fail("known_peers", "must be a list of host names");
    c.lsl.known_peers = lsl.at("known_peers").get<std::vector<std::string>>();
  } else {
    lsl.missing("known_peers");
  }
  c.lsl.markers = lsl.boolean("markers", c.lsl.markers);
  c.lsl.marker_stream = lsl.text("marker_stream", c.lsl.marker_stream);
  if (c.lsl.markers && c.lsl.marker_stream.empty())
    lsl.fail("marker_stream", "must name the stream when markers is true");

  const Section p = root.section("paradigm");
  p.known({"flash_ms", "isi_ms", "sequences", "min_sequences", "certainty",
           "calibration_selections", "calibration_sequences", "trials", "intended", "cue_s",
           "result_s", "pause_s"});
  bci::ParadigmSettings& ps = c.paradigm;
  ps.display_hz = c.display_hz;
  ps.flash_ms = p.number("flash_ms", ps.flash_ms, 5.0, 2000.0);
  ps.isi_ms = p.number("isi_ms", ps.isi_ms, 0.0, 5000.0);
  ps.sequences = p.integer("sequences", ps.sequences, 1, 100);
  ps.min_sequences = p.integer("min_sequences", ps.min_sequences, 1, ps.sequences);
  ps.certainty = p.number("certainty", ps.certainty, 0.0, 1.0);
  ps.calibration_selections =
      p.integer("calibration_selections", ps.calibration_selections, 2, 200);
  ps.calibration_sequences = p.integer("calibration_sequences", ps.calibration_sequences, 1, 100);
  ps.trials = p.integer("trials", ps.trials, 1, 1000);
  ps.cue_s = p.number("cue_s", ps.cue_s, 0.0, 60.0);
  ps.result_s = p.number("result_s", ps.result_s, 0.0, 60.0);
  ps.pause_s = p.number("pause_s", ps.pause_s, 0.0, 60.0);
  if (p.has("intended")) {
    if (!p.at("intended").is_array())
      p.fail("intended", "must be a list of {\"object\": id, \"cell\": [row, column]}");
    c.intended.clear();
    for (size_t i = 0; i < p.at("intended").size(); ++i) {
      const Section t(p.at("intended")[i], p.name("intended") + "[" + std::to_string(i) + "]",
                      file);
      t.known({"object", "cell"});
      TrialIntent intent;
      intent.object = t.integer("object", -1, 0, 4095);
      bool known_object = false;
      for (const auto& o : c.world.objects) known_object |= o.id == intent.object;
      if (!known_object)
        t.fail("object", "= " + std::to_string(intent.object) + " is not one of world.objects");
      const auto cell = t.numbers("cell", {1, 1}, 2, 2);
      intent.row = static_cast<int>(cell[0]);
      intent.column = static_cast<int>(cell[1]);
      if (intent.row < 1 || intent.row > c.world.grid.rows || intent.column < 1 ||
          intent.column > c.world.grid.columns) {
        t.fail("cell", "lies outside the " + std::to_string(c.world.grid.rows) + "x" +
                           std::to_string(c.world.grid.columns) + " grid");
      }
      c.intended.push_back(intent);
    }
  }
  const Section cl = root.section("classifier");
  cl.known(
      {"method", "window_ms", "decimate_hz", "highpass_hz", "lowpass_hz", "notch_hz", "model"});
  c.classifier_method =
      cl.text("method", c.classifier_method, {"swlda", "slda", "xdawn", "riemann"});
  const auto window = cl.numbers(
      "window_ms", {c.pipeline.window.start_s * 1000.0, c.pipeline.window.end_s * 1000.0}, 2, 2);
  if (!(window[1] > window[0])) cl.fail("window_ms", "must end after it starts");
  c.pipeline.window = {window[0] / 1000.0, window[1] / 1000.0};
  c.pipeline.decimate_hz = cl.number("decimate_hz", c.pipeline.decimate_hz, 1.0, 500.0);
  c.pipeline.filter.highpass_hz =
      cl.number("highpass_hz", c.pipeline.filter.highpass_hz, 0.0, 100.0);
  c.pipeline.filter.lowpass_hz = cl.number("lowpass_hz", c.pipeline.filter.lowpass_hz, 0.0, 500.0);
  c.pipeline.filter.notch_hz = cl.number("notch_hz", c.pipeline.filter.notch_hz, 0.0, 500.0);
  c.model_file = cl.text("model", c.model_file);

  const Section e = root.section("errp");
  e.known({"enabled", "calibration_feedbacks", "wrong_feedback_rate", "threshold", "runner_up",
           "repeat_sequences", "max_corrections", "channels", "window_ms", "decimate_hz",
           "highpass_hz", "lowpass_hz", "method", "xdawn_filters"});
  ps.errp = e.boolean("enabled", ps.errp);
  ps.errp_calibration_feedbacks =
      e.integer("calibration_feedbacks", ps.errp_calibration_feedbacks, 4, 1000);
  ps.errp_wrong_rate = e.number("wrong_feedback_rate", ps.errp_wrong_rate, 0.05, 0.5);
  ps.errp_runner_up = e.number("runner_up", ps.errp_runner_up, 0.0, 1.0);
  ps.errp_repeat_sequences = e.integer("repeat_sequences", ps.errp_repeat_sequences, 0, 100);
  ps.errp_max_corrections = e.integer("max_corrections", ps.errp_max_corrections, 0, 10);
  c.errp.threshold = e.number("threshold", c.errp.threshold, 0.0, 1.0);
  if (e.has("channels")) {
    if (!e.at("channels").is_array())
      e.fail("channels", "must be a list of channel names ([]: all of the montage's)");
    c.errp.channels = e.at("channels").get<std::vector<std::string>>();
  }
  const auto errp_window =
      e.numbers("window_ms", {c.errp.window.start_s * 1000.0, c.errp.window.end_s * 1000.0}, 2, 2);
  if (!(errp_window[1] > errp_window[0]) || errp_window[0] < 0.0)
    e.fail("window_ms", "must start at or after the feedback and end after it starts");
  c.errp.window = {errp_window[0] / 1000.0, errp_window[1] / 1000.0};
  c.errp.decimate_hz = e.number("decimate_hz", c.errp.decimate_hz, 1.0, 500.0);
  c.errp.highpass_hz = e.number("highpass_hz", c.errp.highpass_hz, 0.0, 100.0);
  c.errp.lowpass_hz = e.number("lowpass_hz", c.errp.lowpass_hz, 0.0, 500.0);
  c.errp.method = e.text("method", c.errp.method, {"swlda", "slda", "xdawn", "riemann"});
  c.errp.xdawn_filters = e.integer("xdawn_filters", c.errp.xdawn_filters, 1, 64);
  if (ps.errp) (void)c.errp.pipeline(c.pipeline, c.eeg.montage);  // the montage has its channels

  const Section r = root.section("robot");
  r.known({"backend", "speed_factor", "host", "port", "key_file"});
  c.robot_backend = r.text("backend", c.robot_backend, {"simulated", "remote"});
  c.robot_speed_factor = r.number("speed_factor", c.robot_speed_factor, 0.1, 100.0);
  c.robot_host = r.text("host", c.robot_host);
  c.robot_port = r.integer("port", c.robot_port, 1, 65535);
  c.robot_key_file = r.text("key_file", c.robot_key_file);
  if (c.robot_backend == "remote" && c.robot_key_file.empty())
    r.fail("key_file", "is required for a remote robot");
}

}  // namespace

bci::PipelineSettings ErrpSettings::pipeline(const bci::PipelineSettings& p300,
                                             const std::vector<std::string>& montage) const {
  bci::PipelineSettings out = p300;
  out.window = window;
  out.decimate_hz = decimate_hz;
  out.filter.highpass_hz = highpass_hz;
  out.filter.lowpass_hz = lowpass_hz;
  out.channels.clear();
  if (channels.empty()) {
    out.channels = montage;  // the EEG channels only, never the photodiode
    return out;
  }
  for (const std::string& channel : channels) {
    if (std::find(montage.begin(), montage.end(), channel) != montage.end())
      out.channels.push_back(channel);
  }
  if (out.channels.empty()) {
    std::string wanted;
    for (const std::string& channel : channels) wanted += (wanted.empty() ? "" : ", ") + channel;
    throw SessionConfigError("errp.channels: the EEG montage has none of " + wanted +
                             " (the ErrP is fronto-central: name the montage's channels there)");
  }
  return out;
}

bci::TrainingSettings ErrpSettings::training() const {
  bci::TrainingSettings t;
  t.method = method;
  t.xdawn.filters = xdawn_filters;
  t.folds = 5;
  t.folds_by = "block";
  return t;
}

SessionConfig SessionConfig::defaults(const std::string& json_text, const std::string& name) {
  SessionConfig config;
  Json json;
  try {
    json = Json::parse(json_text);
  } catch (const Json::exception& error) {
    throw SessionConfigError(name + ": not JSON (" + std::string(error.what()) + ")");
  }
  parse(json, name, config, true);
  return config;
}

SessionConfig SessionConfig::load(const std::optional<std::filesystem::path>& path) {
  SessionConfig config = defaults(std::string(assets::embedded("sessions/simulated.json")),
                                  "embedded default session");
  if (!path) return config;
  std::ifstream in(*path);
  if (!in) throw SessionConfigError(path->string() + ": cannot open the session file");
  Json json;
  try {
    in >> json;
  } catch (const Json::exception& error) {
    throw SessionConfigError(path->string() + ": not JSON (" + std::string(error.what()) + ")");
  }
  config.source = path->string();
  parse(json, path->string(), config, false);
  return config;
}

bci::lsl::LslConfig LslSettings::config(const std::string& session_file) const {
  bci::lsl::LslConfig c;
  try {
    c = bci::lsl::LslConfig::load();
  } catch (const bci::lsl::LslError& e) {
    throw SessionConfigError(session_file + ": the LSL configuration: " + e.what());
  }
  if (!scope.empty()) c.resolve_scope = scope;
  c.known_peers.insert(c.known_peers.end(), known_peers.begin(), known_peers.end());
  return c;
}

}  // namespace arbci::session
