#include "arbci/session/settings_schema.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "arbci/bci/classifier.h"
#include "arbci/bci/errp_feedback.h"
#include "arbci/bci/settings.h"
#include "arbci/bci/signal_quality.h"
#include "arbci/robot/settings.h"
#include "arbci/session/eeg_sources.h"
#include "arbci/session/scene_source.h"
#include "arbci/session/trigger_output.h"
#include "arbci/vision/settings.h"

namespace arbci::session {
namespace {

using core::Key;
using core::Schema;
using core::Type;
using Json = nlohmann::json;
using Broken = std::optional<std::pair<std::string, std::string>>;

const Schema<HmdConfig>& hmdSchema() {
  static const Schema<HmdConfig> t = [] {
    Schema<HmdConfig> t("hmd", "The subject's head-mounted display (both eyes side by side)");
    t.integer("width", &HmdConfig::width, 1280, 64, 8192, "both eyes' width", "px")
        .integer("height", &HmdConfig::height, 480, 48, 8192, "the eyes' height", "px")
        .boolean("undistort", &HmdConfig::undistort, true,
                 "the camera images undistorted before the overlays")
        .integer("mirror_monitor", &HmdConfig::mirror_monitor, -1, -1, 15,
                 "the monitor (0-based) the HMD's view is shown on full screen (-1: none)")
        .text("output", &HmdConfig::output, "window",
              "where the subject's view goes: window (a window, or the monitor "
              "mirror_monitor names) or openxr (a headset through its OpenXR runtime: SteamVR, "
              "Monado, Varjo Base; flashes stamped at the runtime's predicted display time)",
              [] {
                return std::vector<std::string>{"window", "openxr"};
              })
        // PNG of the whole HMD frame, about 760 kB each at 1280x480 (camera images barely
        // compress): "phases" keeps 6 a trial, ~270 MB over a 60-trial day.
        .text("screenshots", &HmdConfig::screenshots, "phases",
              "the HMD frames kept as PNG (~760 kB each at 1280x480): phases (the calibration's, "
              "each trial phase's, the end's and a robot fault's), first_trial (the same for trial "
              "1 only), end (the end's and a robot fault's), none",
              [] {
                return std::vector<std::string>{"phases", "first_trial", "end", "none"};
              });
    return t;
  }();
  return t;
}

const Schema<CameraSource>& cameraSourceSchema() {
  static const Schema<CameraSource> t = [] {
    Schema<CameraSource> t("camera", "A camera device or a video file, with its calibration");
    t.integer("device", &CameraSource::device, -1, -1, 63, "the V4L2 device number (-1: none)")
        .text("video", &CameraSource::video, "", "a video file instead of a device")
        .text("calibration", &CameraSource::calibration, "",
              "its calibration file (arbci calibrate)");
    return t;
  }();
  return t;
}

std::string sideRule(const Json& side, const char* name, Broken& broken) {
  const bool used = side["device"].get<int>() >= 0 || !side["video"].get<std::string>().empty() ||
                    !side["calibration"].get<std::string>().empty();
  if (!used) return "";
  if (side["device"].get<int>() < 0 && side["video"].get<std::string>().empty())
    broken = std::pair{std::string(name), "needs a device number or a video file"};
  else if (side["calibration"].get<std::string>().empty())
    broken = std::pair{std::string(name) + ".calibration",
                       "is required: the camera's calibration file (arbci calibrate)"};
  return "";
}

const Schema<CameraSettings>& camerasSchema() {
  static const Schema<CameraSettings> t = [] {
    using C = CameraSettings;
    Schema<C> t("cameras", "The cameras at the subject's head: simulated, or devices and videos");
    t.text("source", &C::source, "simulated", "where the frames come from (camera sources)",
           [] { return sceneSources().names(); })
        .number("rate_hz", &C::rate_hz, 30.0, 1.0, 240.0, "camera frames a second", "Hz")
        .integer("width", &C::width, 640, 64, 4096, "simulated: the image width", "px")
        .integer("height", &C::height, 480, 48, 4096, "simulated: the image height", "px")
        .number("focal_px", &C::focal_px, 800.0, 10.0, 1e5, "simulated: the focal length", "px")
        .numbers("distortion", &C::distortion, {-0.08, 0.02, 0.0, 0.0, 0.0}, 0, 8,
                 "simulated: the lens's distortion coefficients (OpenCV's order)");
    t.number("baseline_m", &C::baseline_m, 0.064, 0.0, 0.5, "simulated: the stereo rig's baseline",
             "m");
    t.vector3("head_position", &C::head_position, {0.0, 1.20, 0.75},
              "simulated: the cameras' position (robot frame)", "m");
    t.vector3("look_at", &C::look_at, {0.0, 0.70, 0.0}, "simulated: where they look (robot frame)",
              "m");
    t.number("head_motion_m", &C::head_motion_m, 0.008, 0.0, 0.2,
             "simulated: the head's sway (amplitude)", "m")
        .number("head_motion_deg", &C::head_motion_deg, 0.6, 0.0, 20.0,
                "simulated: the head's turning (amplitude)", "deg")
        .number("noise", &C::noise, 2.0, 0.0, 50.0, "simulated: sensor noise (grey levels, sd)")
        .number("blur_px", &C::blur_px, 0.5, 0.0, 10.0, "simulated: optical blur (sd)", "px")
        .section("left", &C::left, cameraSourceSchema())
        .section("right", &C::right, cameraSourceSchema())
        .text("stereo_calibration", &C::stereo_calibration, "",
              "the right camera's pose in the left's frame (arbci calibrate --stereo)");
    t.rule([](const Json& c) -> Broken {
      Broken broken;
      sideRule(c["left"], "left", broken);
      if (!broken) sideRule(c["right"], "right", broken);
      if (!broken && c["source"] == "devices" && c["left"]["device"].get<int>() < 0 &&
          c["left"]["video"].get<std::string>().empty())
        broken = std::pair{"left", "is required when source is \"devices\""};
      return broken;
    });
    return t;
  }();
  return t;
}

const Schema<TrackerSettings>& trackerSchema() {
  static const Schema<TrackerSettings> t = [] {
    Schema<TrackerSettings> t("tracker", "The marker tracker and how old a pose may be");
    t.merge(vision::detectorSchema(), &TrackerSettings::detector)
        .number("max_pose_age_s", &TrackerSettings::max_pose_age_s, 0.5, 0.05, 10.0,
                "an older pose is stale: its object is not flashed, offered or grasped", "s");
    t.rule([](const Json& tracker) -> Broken {
      const auto* family = vision::markerFamilies().find(tracker["kind"].get<std::string>());
      if (family && family->make.in_sessions) return std::nullopt;
      std::string list;
      for (const auto& f : vision::markerFamilies().entries())
        if (f.make.in_sessions) list += (list.empty() ? "" : ", ") + f.name;
      return std::pair{"kind", "= " + tracker["kind"].dump() + " must be one of " + list +
                                   " (a session tracks objects by their ids alone)"};
    });
    return t;
  }();
  return t;
}

// Another module's key under this file's name for it (its unit in the name, as the others here).
Key renamed(Key key, std::string name) {
  key.name = std::move(name);
  return key;
}

const Schema<WorldObjectSettings>& objectSchema() {
  static const Schema<WorldObjectSettings> t = [] {
    using O = WorldObjectSettings;
    Schema<O> t("object", "An object on the table, carrying a marker on its top face");
    t.required(Key{"id", Type::Integer, nullptr, "the object's marker id", "", 0, 4095}, &O::id);
    t.vector3("position", &O::position, nullptr, "[x, y, z] of the top centre in metres", "m",
              true);
    t.number("marker_m", &O::marker_m, 0.05, 0.005, 0.5, "its marker's side", "m")
        .number("width_m", &O::width_m, 0.07, 0.005, 0.6, "its width (at least the marker's)", "m")
        .number("height_m", &O::height_m, 0.06, 0.005, 0.6, "its height", "m")
        .custom(
            renamed(robot::objectSchema().at("mass"), "mass_kg"),
            [](O& o, const Json& j) { o.mass_kg = j.get<double>(); },
            [](const O& o) { return Json(o.mass_kg); })
        .custom(
            robot::objectSchema().at("friction"),
            [](O& o, const Json& j) { o.friction = j.get<double>(); },
            [](const O& o) { return Json(o.friction); });
    t.vector3("color", &O::color, {0.8, 0.4, 0.3}, "its colour (red, green, blue, 0-1)", "");
    t.numbers("covered_s", &O::covered_s, {}, 0, 16,
              "simulated cameras: a hand lies over its marker from each first to each second "
              "session time, e.g. [20, 23] (a tracking loss to rehearse; empty: never)",
              "s");
    t.rule([](const Json& o) -> Broken {
      const Json& covered = o["covered_s"];
      bool ordered = covered.size() % 2 == 0;
      for (size_t i = 0; ordered && i + 1 < covered.size(); ++i)
        ordered = covered[i].get<double>() < covered[i + 1].get<double>();
      if (!ordered)
        return std::pair{"covered_s", "= " + covered.dump() +
                                          " must be pairs of session times [from, to, ...], "
                                          "each later than the one before"};
      if (o["width_m"].get<double>() < o["marker_m"].get<double>())
        return std::pair{"width_m", "= " + o["width_m"].dump() + " must lie in [" +
                                        o["marker_m"].dump() + ", 0.6] (at least the marker)"};
      return std::nullopt;
    });
    return t;
  }();
  return t;
}

const Schema<GridSettings>& gridSchema() {
  static const Schema<GridSettings> t = [] {
    using G = GridSettings;
    Schema<G> t("grid", "The grid of cells on the table where objects are put");
    t.integer("rows", &G::rows, 3, 1, 12, "rows of cells")
        .integer("columns", &G::columns, 3, 1, 12, "columns of cells")
        .number("cell_m", &G::cell_m, 0.09, 0.01, 1.0, "a cell's side", "m");
    t.vector3("centre", &G::centre, {0.0, 0.66, 0.0}, "its centre on the table (robot frame)", "m");
    t.rule([](const Json& g) -> Broken {
      if (g["rows"].get<int>() * g["columns"].get<int>() < 2)
        return std::pair{"", "needs at least 2 cells"};
      return std::nullopt;
    });
    return t;
  }();
  return t;
}

const Schema<WorldSettings>& referenceSchema() {
  static const Schema<WorldSettings> t = [] {
    using W = WorldSettings;
    Schema<W> t("reference", "The reference marker, at a known place in the robot's frame");
    t.integer("id", &W::reference_id, 0, 0, 4095, "its marker id")
        .number("size_m", &W::reference_size_m, 0.08, 0.005, 1.0, "its side", "m");
    t.vector3("position", &W::reference_position, {0.0, 0.90, 0.0},
              "its centre in the robot frame (lying flat, axes along the robot's)", "m");
    return t;
  }();
  return t;
}

Json defaultObjects() {
  auto object = [](int id, double x, Json color) {
    return Json{{"id", id},
                {"position", {x, 0.42, 0.06}},
                {"marker_m", 0.05},
                {"width_m", 0.07},
                {"height_m", 0.06},
                {"mass_kg", robot::SimulatedObject().mass},
                {"friction", robot::SimulatedObject().friction},
                {"color", std::move(color)},
                {"covered_s", Json::array()}};
  };
  return Json::array({object(10, -0.27, {0.85, 0.30, 0.25}), object(20, -0.09, {0.25, 0.55, 0.85}),
                      object(30, 0.09, {0.30, 0.75, 0.35}), object(40, 0.27, {0.90, 0.75, 0.20})});
}

const Schema<WorldSettings>& worldSchema() {
  static const Schema<WorldSettings> t = [] {
    using W = WorldSettings;
    Schema<W> t("world", "The table, the reference marker, the objects and the grid");
    t.number("table_z", &W::table_z, 0.0, -2.0, 2.0, "the table's height (robot frame)", "m")
        .sectionOf("reference", referenceSchema())
        .list("objects", &W::objects, objectSchema(), defaultObjects(), 2,
              "the objects the subject selects (at least 2)")
        .section("grid", &W::grid, gridSchema());
    t.rule([](const Json& w) -> Broken {
      const int reference = w["reference"]["id"].get<int>();
      std::set<int> seen;
      for (size_t i = 0; i < w["objects"].size(); ++i) {
        const int id = w["objects"][i]["id"].get<int>();
        const std::string key = "objects[" + std::to_string(i) + "].id";
        if (id == reference)
          return std::pair{key, "= " + std::to_string(id) + " is the reference marker's id"};
        if (!seen.insert(id).second)
          return std::pair{key, "= " + std::to_string(id) + " is used twice"};
      }
      return std::nullopt;
    });
    return t;
  }();
  return t;
}

const Schema<EegSettings>& eegSchema() {
  static const Schema<EegSettings> t = [] {
    using E = EegSettings;
    Schema<E> t("eeg", "The EEG source and the signal's shape");
    const auto& subject = bci::subjectSchema();
    t.text("source", &E::source, "simulated", "where the EEG comes from (EEG sources)",
           [] { return eegSources().names(); })
        .custom(
            subject.at("seed"), [](E& e, const Json& j) { e.seed = j.get<std::uint64_t>(); },
            [](const E& e) { return Json(e.seed); })
        .custom(
            subject.at("montage"),
            [](E& e, const Json& j) { e.montage = j.get<std::vector<std::string>>(); },
            [](const E& e) { return Json(e.montage); })
        .custom(
            subject.at("rate_hz"), [](E& e, const Json& j) { e.rate_hz = j.get<double>(); },
            [](const E& e) { return Json(e.rate_hz); })
        .custom(
            subject.at("block_size"), [](E& e, const Json& j) { e.block_size = j.get<int>(); },
            [](const E& e) { return Json(e.block_size); })
        .custom(
            subject.at("line_hz"), [](E& e, const Json& j) { e.line_hz = j.get<double>(); },
            [](const E& e) { return Json(e.line_hz); })
        .number("erp_scale", &E::erp_scale, 1.0, 0.0, 10.0,
                "simulated: the subject's P300 amplitude factor (weak subjects < 1)")
        .number("errp_scale", &E::errp_scale, 1.0, 0.0, 10.0,
                "simulated: its error-related potentials' amplitude factor (0: none)")
        .text("file", &E::file, "", "source \"file\": the recording to replay")
        .custom(
            subject.at("photodiode_channel"),
            [](E& e, const Json& j) { e.photodiode_channel = j.get<std::string>(); },
            [](const E& e) { return Json(e.photodiode_channel); })
        .text("photodiode_marker", &E::photodiode_marker, "",
              "a photodiode on a trigger input (an RDA marker): the marker as recorded, "
              "\"Stimulus/S  1\"; the timing check takes its onsets as the diode's edges")
        .number("latency_ms", &E::latency_ms, 0.0, 0.0, 1000.0,
                "the amplifier's delivery latency, as arbci timing-check measures it", "ms")
        .text("reference", &E::reference, "",
              "the electrodes' reference as the amplifier records it (\"linked mastoids\", "
              "\"FCz\"), for the recording and a BIDS export; \"\": not stated")
        .text("manufacturer", &E::manufacturer, "",
              "the amplifier's maker (\"Brain Products\"), for the recording and a BIDS "
              "export; \"\": not stated");
    // Each source's own section.
    for (const auto& source : eegSources().entries()) {
      if (!source.settings) continue;
      Key k{source.name, Type::Section, nullptr, source.settings->doc()};
      k.table = source.settings;
      const std::string name = source.name;
      t.custom(
          k, [name](E& e, const Json& j) { e.sources[name] = j; },
          [name](const E& e) {
            const auto found = e.sources.find(name);
            return found == e.sources.end() ? Json::object() : found->second;
          });
    }
    t.text("trigger_out", &E::trigger_out, "none",
           "a trigger byte to the amplifier at each flash's presentation: none, or serial "
           "(a trigger box on eeg.trigger.device)",
           [] { return triggerOutputs(); });
    {
      Key k{"trigger", Type::Section, nullptr, triggerSchema().doc()};
      k.table = &triggerSchema();
      t.custom(
          k, [](E& e, const Json& j) { e.trigger = j; }, [](const E& e) { return e.trigger; });
    }
    t.rule([](const Json& eeg) -> Broken {
      const Json trigger = eeg.value("trigger", Json::object());
      if (eeg.value("trigger_out", "none") == "serial" &&
          (!trigger.is_object() || trigger.value("device", "").empty()))
        return std::pair{"trigger.device",
                         "must name the trigger box's serial port when trigger_out is serial"};
      return std::nullopt;
    });
    t.rule([](const Json& eeg) -> Broken {
      const auto* source = eegSources().find(eeg["source"].get<std::string>());
      if (source && source->make.required) return source->make.required(eeg);
      return std::nullopt;
    });
    return t;
  }();
  return t;
}

const Schema<LslSettings>& lslSchema() {
  static const Schema<LslSettings> t = [] {
    using L = LslSettings;
    Schema<L> t("lsl",
                "The Lab Streaming Layer: where streams are looked for, what ARBCI "
                "publishes (scope and peers default to lsl_api.cfg's)");
    t.text("scope", &L::scope, "", "\"\" (lsl_api.cfg's), machine, link or site",
           [] {
             return std::vector<std::string>{"", "machine", "link", "site"};
           })
        .texts("known_peers", &L::known_peers, {}, 0,
               "host names added to lsl_api.cfg's KnownPeers")
        .boolean("markers", &L::markers, false,
                 "publish every stimulus and note of the recording as an LSL Markers stream")
        .text("marker_stream", &L::marker_stream, "ARBCI-Markers", "that stream's name");
    t.rule([](const Json& l) -> Broken {
      if (l["markers"].get<bool>() && l["marker_stream"].get<std::string>().empty())
        return std::pair{"marker_stream", "must name the stream when markers is true"};
      return std::nullopt;
    });
    return t;
  }();
  return t;
}

const Schema<TrialIntent>& intentSchema() {
  static const Schema<TrialIntent> t = [] {
    Schema<TrialIntent> t("intended", "What the simulated subject means in a trial");
    t.required(Key{"object", Type::Integer, nullptr, "the object's marker id", "", 0, 4095},
               &TrialIntent::object);
    Key cell{"cell", Type::Numbers, Json::array({1, 1}), "[row, column] of the cell, from 1"};
    cell.min_items = cell.max_items = 2;
    t.custom(
        cell,
        [](TrialIntent& i, const Json& j) {
          i.row = static_cast<int>(j[0].get<double>());
          i.column = static_cast<int>(j[1].get<double>());
        },
        [](const TrialIntent& i) {
          return Json::array({i.row, i.column});
        });
    return t;
  }();
  return t;
}

const Schema<SessionConfig>& paradigmSectionSchema() {
  static const Schema<SessionConfig> t = [] {
    Schema<SessionConfig> t("paradigm", bci::paradigmSchema().doc());
    for (const char* key :
         {"flash_ms", "isi_ms", "sequences", "min_sequences", "certainty", "act_certainty",
          "calibration_selections", "calibration_sequences", "trials", "cue_s", "result_s",
          "pause_s", "no_view_pause_s", "calibration", "learning_min_selections",
          "learning_min_consistency", "learning_sequences", "learning_max_sequences", "adapt"})
      t.adopt(bci::paradigmSchema(), key, &SessionConfig::paradigm);
    t.rulesOf(bci::paradigmSchema());
    t.list("intended", &SessionConfig::intended, intentSchema(),
           Json::array({{{"object", 20}, {"cell", {1, 3}}},
                        {{"object", 40}, {"cell", {3, 1}}},
                        {{"object", 10}, {"cell", {2, 2}}}}),
           0,
           "each trial's intention (the simulated subject's); trials beyond the list are drawn "
           "from the seed");
    return t;
  }();
  return t;
}

const Schema<ClassifierSettings>& classifierTable() {
  static const Schema<ClassifierSettings> t = [] {
    using C = ClassifierSettings;
    Schema<C> t("classifier", "The P300 classifier the calibration run trains");
    for (const char* key : {"method", "window_ms", "decimate_hz", "highpass_hz", "lowpass_hz",
                            "notch_hz", "notch_q", "filter_order", "common_average", "channels"}) {
      if (bci::trainingSchema().find(key))
        t.adopt(bci::trainingSchema(), key, &C::training);
      else
        t.adopt(bci::pipelineSchema(), key, &C::pipeline);
    }
    for (const char* key : {"p_enter", "p_remove", "max_features", "xdawn_filters", "shift_ms"})
      t.adopt(bci::trainingSchema(), key, &C::training);
    // The calibration run's cross-validation, not an offline analysis's (arbci train --folds):
    // fewer folds, so the first trial starts sooner.
    t.custom(
        Key{"folds", Type::Integer, 4,
            "the calibration run's cross-validation folds (by selection)", "", 2, 100},
        [](C& c, const Json& j) { c.training.folds = j.get<int>(); },
        [](const C& c) { return Json(c.training.folds); });
    t.text("model", &C::model_file, "", "a trained model (arbci train): no calibration run");
    t.rulesOf(bci::pipelineSchema()).rulesOf(bci::trainingSchema());
    return t;
  }();
  return t;
}

const Schema<ErrpSettings>& errpTable() {
  static const Schema<ErrpSettings> t = [] {
    using E = ErrpSettings;
    Schema<E> t("errp", "The ErrP classifier");
    t.number("threshold", &E::threshold, 0.5, 0.0, 1.0,
             "a selection whose posterior probability of an error exceeds it is rejected")
        .texts("channels", &E::channels, {}, 0,
               "its channels ([]: all of the montage's; those listed that the montage has)");
    // The P300 pipeline's and training's keys (their type, unit and range), at the ErrP's own
    // defaults: its features are slower and its band lower than the P300's.
    const auto& pipeline = bci::pipelineSchema();
    const auto& filter = bci::filterSchema();
    const auto& training = bci::trainingSchema();
    t.like(
         pipeline.at("window_ms"), Json::array({0, 800}), "its epoch after each feedback",
         [](E& e, const Json& j) {
           e.window = {j[0].get<double>() / 1000.0, j[1].get<double>() / 1000.0};
         },
         [](const E& e) {
           return Json::array({e.window.start_s * 1000.0, e.window.end_s * 1000.0});
         })
        .like(pipeline.at("decimate_hz"), &E::decimate_hz, 20.0,
              "its features' rate (0: its method's own)")
        .like(filter.at("highpass_hz"), &E::highpass_hz, 1.0, "its band's lower edge")
        .like(filter.at("lowpass_hz"), &E::lowpass_hz, 10.0, "its band's upper edge")
        .like(training.at("method"), &E::method, "shift-lda", "its classifier (classifiers)")
        .like(training.at("xdawn_filters"), &E::xdawn_filters, 1,
              "xDAWN filters kept (riemann: per class; 0: the method's own)")
        .like(training.at("folds"), &E::folds, 5,
              "its cross-validation: contiguous blocks of the feedbacks");
    t.rule([](const Json& e) -> Broken {
      const double start = e["window_ms"][0].get<double>(), end = e["window_ms"][1].get<double>();
      if (!(end > start) || start < 0.0)
        return std::pair{"window_ms",
                         "must start at or after the feedback and end after it starts"};
      return std::nullopt;
    });
    return t;
  }();
  return t;
}

const Schema<SessionConfig>& errpSectionSchema() {
  static const Schema<SessionConfig> t = [] {
    Schema<SessionConfig> t("errp",
                            "Error-related potentials: an ErrP classifier checks each "
                            "selection before the robot acts (docs/errp.md)");
    const auto& p = bci::paradigmSchema();
    t.adopt(p, "errp", &SessionConfig::paradigm, "enabled")
        .adopt(p, "errp_calibration_feedbacks", &SessionConfig::paradigm, "calibration_feedbacks")
        .adopt(p, "errp_wrong_rate", &SessionConfig::paradigm, "wrong_feedback_rate")
        .adopt(p, "errp_runner_up", &SessionConfig::paradigm, "runner_up")
        .adopt(p, "errp_repeat_sequences", &SessionConfig::paradigm, "repeat_sequences")
        .adopt(p, "errp_max_corrections", &SessionConfig::paradigm, "max_corrections")
        .merge(errpTable(), &SessionConfig::errp)
        .rulesOf(errpTable());
    return t;
  }();
  return t;
}

const Schema<RobotSettings>& robotSchema() {
  static const Schema<RobotSettings> t = [] {
    using R = RobotSettings;
    Schema<R> t("robot", "The robot backend the session commands");
    t.text("backend", &R::backend, "simulated",
           "simulated (arbci-robotd started here) or remote (host, port, key_file)",
           [] {
             return std::vector<std::string>{"simulated", "remote"};
           })
        .custom(
            robot::linkSchema().at("driver"),
            [](R& r, const Json& j) { r.driver = j.get<std::string>(); },
            [](const R& r) { return Json(r.driver); })
        .custom(
            robot::configSchema().at("model"),
            [](R& r, const Json& j) { r.model = j.get<std::string>(); },
            [](const R& r) { return Json(r.model); })
        .number("speed_factor", &R::speed_factor, 8.0, 0.1, 100.0,
                "simulated: the arm's seconds per second of the session")
        .custom(
            robot::linkSchema().at("host"),
            [](R& r, const Json& j) { r.host = j.get<std::string>(); },
            [](const R& r) { return Json(r.host); })
        .custom(
            robot::linkSchema().at("port"), [](R& r, const Json& j) { r.port = j.get<int>(); },
            [](const R& r) { return Json(r.port); })
        .custom(
            robot::linkSchema().at("watchdog_ms"),
            [](R& r, const Json& j) { r.watchdog_ms = j.get<int>(); },
            [](const R& r) { return Json(r.watchdog_ms); })
        .custom(
            robot::linkSchema().at("key_file"),
            [](R& r, const Json& j) { r.key_file = j.get<std::string>(); },
            [](const R& r) { return Json(r.key_file); });
    t.rule([](const Json& r) -> Broken {
      if (r["backend"] == "remote" && r["key_file"].get<std::string>().empty())
        return std::pair{"key_file", "is required for a remote robot"};
      return std::nullopt;
    });
    return t;
  }();
  return t;
}

// Rules between sections.
Broken crossRules(const Json& c) {
  std::set<int> objects;
  for (const Json& o : c["world"]["objects"]) objects.insert(o["id"].get<int>());
  const int rows = c["world"]["grid"]["rows"].get<int>();
  const int columns = c["world"]["grid"]["columns"].get<int>();
  const Json& intended = c["paradigm"]["intended"];
  for (size_t i = 0; i < intended.size(); ++i) {
    const std::string at = "paradigm.intended[" + std::to_string(i) + "]";
    const int object = intended[i]["object"].get<int>();
    if (!objects.count(object))
      return std::pair{at + ".object",
                       "= " + std::to_string(object) + " is not one of world.objects"};
    const int row = static_cast<int>(intended[i]["cell"][0].get<double>());
    const int column = static_cast<int>(intended[i]["cell"][1].get<double>());
    if (row < 1 || row > rows || column < 1 || column > columns)
      return std::pair{at + ".cell", "lies outside the " + std::to_string(rows) + "x" +
                                         std::to_string(columns) + " grid"};
  }
  if (const Json& errp = c["errp"]; errp["enabled"].get<bool>()) {
    // Too few calibration feedbacks leave a fold (or the whole block) without enough errors to
    // train on: refused now, not found out after the calibration run.
    const int given = errp["calibration_feedbacks"].get<int>(), folds = errp["folds"].get<int>();
    const double rate = errp["wrong_feedback_rate"].get<double>();
    const int least = bci::minimumCalibrationFeedbacks(rate, folds);
    if (given > 0 && given < least)
      return std::pair{"errp.calibration_feedbacks",
                       "= " + std::to_string(given) +
                           " is too few to train the ErrP classifier "
                           "with errp.folds = " +
                           std::to_string(folds) + " and a wrong share of " +
                           core::formatNumber(rate) + ": at least " + std::to_string(least) +
                           " (every fold keeps " + std::to_string(bci::kMinimumTargets) +
                           " errors to train on), or more folds (smaller held-out blocks)"};
  }
  if (c["errp"]["enabled"].get<bool>() && c["paradigm"]["calibration"] == "none")
    return std::pair{"errp.enabled",
                     "= true needs the calibration run's feedback block to train the ErrP "
                     "classifier, and paradigm.calibration is \"none\": set one of them "
                     "otherwise"};
  if (c["paradigm"]["calibration"] == "none") {
    // Learning from use trusts no model before learning_min_selections object selections are
    // fitted: a run of fewer trials ends without the arm ever moving.
    const int trials = c["paradigm"]["trials"].get<int>();
    const int needed = c["paradigm"]["learning_min_selections"].get<int>();
    if (trials < needed)
      return std::pair{"paradigm.trials",
                       "= " + std::to_string(trials) +
                           " with paradigm.calibration \"none\": the learner trusts no model "
                           "before " +
                           std::to_string(needed) +
                           " object selections (paradigm.learning_min_selections), so the arm "
                           "would never move; run at least " +
                           std::to_string(needed) + " trials (the docs' runs use 30)"};
  }
  if (c["errp"]["enabled"].get<bool>() && !c["errp"]["channels"].empty()) {
    const auto montage = c["eeg"]["montage"].get<std::vector<std::string>>();
    bool any = false;
    for (const Json& ch : c["errp"]["channels"])
      any |= std::find(montage.begin(), montage.end(), ch.get<std::string>()) != montage.end();
    if (!any)
      return std::pair{"errp.channels",
                       "= " + c["errp"]["channels"].dump() +
                           ": the EEG montage has none of them (the ErrP is fronto-central: "
                           "name the montage's channels there)"};
  }
  return std::nullopt;
}

}  // namespace

const core::Schema<ClassifierSettings>& classifierSchema() {
  return classifierTable();
}

const core::Schema<ErrpSettings>& errpOwnSchema() {
  return errpTable();
}

const Schema<GateSettings>& gateSchema() {
  static const Schema<GateSettings> t = [] {
    using G = GateSettings;
    Schema<G> t("gates",
                "What a run must pass: the EEG's quality at Start, the calibration's review "
                "before going online, the flashes' timing during the run");
    t.text("signal_quality", &G::signal_quality, "ask",
           "at Start, EEG channels graded bad over the last 2 s (flat, saturated, line noise at "
           "classifier.notch_hz, drift, RMS): ask the experimenter to start anyway or not (a run "
           "without one is refused), refuse, or off (logged only)",
           [] {
             return std::vector<std::string>{"ask", "refuse", "off"};
           })
        .integer("bad_channels_allowed", &G::bad_channels_allowed, 0, 0, 256,
                 "bad channels that pass the quality gate")
        .number("flat_sd_uv", &G::flat_sd_uv, bci::kFlatSdUv, 0.0, 100.0,
                "a channel whose standard deviation is below this is flat (bad)", "uV")
        .number("line_bad_uv", &G::line_bad_uv, bci::kLineBadUv, 0.1, 1e4,
                "line noise at the notch frequency above this amplitude is bad", "uV")
        .number("drift_bad_uv_s", &G::drift_bad_uv_s, bci::kDriftBadUvS, 0.1, 1e5,
                "a linear drift faster than this is bad", "uV/s")
        .number("rms_bad_uv", &G::rms_bad_uv, bci::kRmsBadUv, 1.0, 1e5,
                "an RMS about the trend above this is bad", "uV")
        .boolean("review", &G::review, true,
                 "windowed: after training, the calibration's ERP, AUC and accuracy wait for the "
                 "experimenter's Go online or Recalibrate")
        .number("min_auc", &G::min_auc, 0.0, 0.0, 1.0,
                "a calibration whose cross-validated AUC is below this does not go online "
                "unattended: the experimenter decides, and a run without one ends (0: none)")
        .integer("max_retakes", &G::max_retakes, 8, 1, 1000,
                 "calibration selections retaken (tracking lost) before the run pauses to ask the "
                 "experimenter (a run without one ends); a stall of the machine (every marker lost "
                 "at once) holds the flashes instead and is no retake")
        .text("timing", &G::timing, "pause",
              "flashes off the timing limits: each annotated in the recording, and past "
              "max_off_share or max_late_share the run pauses with the reason (pause), only "
              "annotated (annotate), or not checked (off); a run without an experimenter never "
              "pauses",
              [] {
                return std::vector<std::string>{"pause", "annotate", "off"};
              })
        .number("max_flash_ms", &G::max_flash_ms, 0.0, 0.0, 10000.0,
                "a flash shown longer is off limits (0: twice paradigm.flash_ms as the display "
                "shows it)",
                "ms")
        .number("min_gap_ms", &G::min_gap_ms, 0.0, 0.0, 10000.0,
                "a dark gap before a flash shorter than this is off limits (0: half the "
                "configured gap)",
                "ms")
        .number("min_soa_ms", &G::min_soa_ms, 0.0, 0.0, 10000.0,
                "an onset-to-onset interval shorter than this is off limits (0: the configured "
                "SOA less one display frame)",
                "ms")
        .number("max_off_share", &G::max_off_share, 0.1, 0.0, 1.0,
                "the share of a selection's flashes (after its first 12) off limits that pauses "
                "the run")
        .number("max_late_share", &G::max_late_share, 0.5, 0.0, 1.0,
                "the share of the last 120 presented frames presented late that pauses the run");
    return t;
  }();
  return t;
}

const Schema<SessionConfig>& sessionSchema() {
  static const Schema<SessionConfig> t = [] {
    Schema<SessionConfig> t("session", "A session file: every key, its default and what it means");
    t.text("description", &SessionConfig::description, "",
           "what this session file is for (free text)")
        .adopt(bci::paradigmSchema(), "display_hz", &SessionConfig::paradigm)
        .section("hmd", &SessionConfig::hmd, hmdSchema())
        .section("cameras", &SessionConfig::cameras, camerasSchema())
        .section("tracker", &SessionConfig::tracker, trackerSchema())
        .section("world", &SessionConfig::world, worldSchema())
        .section("eeg", &SessionConfig::eeg, eegSchema())
        .section("lsl", &SessionConfig::lsl, lslSchema())
        .sectionOf("paradigm", paradigmSectionSchema())
        .section("classifier", &SessionConfig::classifier, classifierTable())
        .sectionOf("errp", errpSectionSchema())
        .section("robot", &SessionConfig::robot, robotSchema())
        .section("gates", &SessionConfig::gates, gateSchema());
    t.rule(crossRules);
    return t;
  }();
  return t;
}

HmdConfig::HmdConfig() {
  hmdSchema().applyDefaults(*this);
}
CameraSource::CameraSource() {
  cameraSourceSchema().applyDefaults(*this);
}
CameraSettings::CameraSettings() {
  camerasSchema().applyDefaults(*this);
}
TrackerSettings::TrackerSettings() {
  trackerSchema().applyDefaults(*this);
}
WorldObjectSettings::WorldObjectSettings() : id(0), position(0.0, 0.0, 0.0) {
  objectSchema().applyDefaults(*this);
}
GridSettings::GridSettings() {
  gridSchema().applyDefaults(*this);
}
WorldSettings::WorldSettings() {
  worldSchema().applyDefaults(*this);
}
EegSettings::EegSettings() {
  eegSchema().applyDefaults(*this);
}
LslSettings::LslSettings() {
  lslSchema().applyDefaults(*this);
}
ErrpSettings::ErrpSettings() {
  errpTable().applyDefaults(*this);
}
TrialIntent::TrialIntent() : object(0) {
  intentSchema().applyDefaults(*this);
}
RobotSettings::RobotSettings() {
  robotSchema().applyDefaults(*this);
}
GateSettings::GateSettings() {
  gateSchema().applyDefaults(*this);
}
bci::QualityThresholds GateSettings::thresholds(double line_hz) const {
  bci::QualityThresholds t;
  t.flat_sd_uv = flat_sd_uv;
  t.line_bad_uv = line_bad_uv;
  t.drift_bad_uv_s = drift_bad_uv_s;
  t.rms_bad_uv = rms_bad_uv;
  // A poor grade stays below the bad one however the bad threshold is set.
  t.line_poor_uv = std::min(t.line_poor_uv, line_bad_uv);
  t.drift_poor_uv_s = std::min(t.drift_poor_uv_s, drift_bad_uv_s);
  t.rms_poor_uv = std::min(t.rms_poor_uv, rms_bad_uv);
  t.line_hz = line_hz;
  return t;
}
SessionConfig::SessionConfig() {
  sessionSchema().applyDefaults(*this);
}

SessionConfig SessionConfig::parse(const Json& json, const std::string& name) {
  SessionConfig config;
  Json resolved;
  try {
    resolved = sessionSchema().resolve(json, core::Place{name, ""});
  } catch (const core::SettingsError& error) {
    throw SessionConfigError(error.what());
  }
  sessionSchema().read(resolved, config);
  config.source = name;
  return config;
}

SessionConfig SessionConfig::load(const std::optional<std::filesystem::path>& path) {
  if (!path) return SessionConfig{};
  std::ifstream in(*path);
  if (!in) throw SessionConfigError(path->string() + ": cannot open the session file");
  Json json;
  try {
    in >> json;
  } catch (const Json::exception& error) {
    throw SessionConfigError(path->string() + ": not JSON (" + std::string(error.what()) + ")");
  }
  return parse(json, path->string());
}

Json SessionConfig::toJson() const {
  return sessionSchema().write(*this);
}

bci::PipelineSettings ErrpSettings::pipeline(const bci::PipelineSettings& p300,
                                             const std::vector<std::string>& montage) const {
  bci::PipelineSettings out = p300;
  out.window = window;
  out.decimate_hz = decimate_hz;
  out.filter.highpass_hz = highpass_hz;
  out.filter.lowpass_hz = lowpass_hz;
  out.channels.clear();
  // decimate_hz 0: the method's own rate, as the P300's.
  out = bci::withMethodRate(out, method);
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
  t.folds = folds;
  t.folds_by = "block";
  return t;
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

const core::Key& sessionKey(const std::string& path) {
  const core::Table* table = &sessionSchema();
  const core::Key* key = nullptr;
  std::istringstream parts(path);
  for (std::string part; std::getline(parts, part, '.');) {
    key = table ? table->find(part) : nullptr;
    if (!key) throw std::logic_error("the session file has no key " + path);
    table = key->table;
  }
  if (!key) throw std::logic_error("the session file has no key " + path);
  return *key;
}

std::string settingsMarkdown() {
  std::ostringstream out;
  out << core::markdown(sessionSchema(), "");
  auto registry = [&out](const std::string& title, const auto& r) {
    out << "## " << title << " (`" << r.key() << "`)\n\n| name | what it is |\n| --- | --- |\n";
    for (const auto& e : r.entries()) out << "| `" << e.name << "` | " << e.doc << " |\n";
    out << "\n";
  };
  registry("EEG sources", eegSources());
  registry("Classifiers", bci::classifiers());
  registry("Marker families", vision::markerFamilies());
  registry("Camera sources", sceneSources());
  registry("Robot drivers", robot::robotDrivers());
  return out.str();
}

}  // namespace arbci::session
