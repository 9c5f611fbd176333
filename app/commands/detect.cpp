// `arbci detect`: markers in image files, a video file or a camera; one JSON object per frame on
// one line (stdout); errors for unreadable inputs on stderr, the rest still processed.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/frame_source.h"
#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_poses.h"
#include "arbci/vision/marker_set.h"
#include "arbci/vision/marker_tracker.h"
#include "arbci/vision/settings.h"
#include "commands/commands.h"
#include "support/cli_error.h"
#include "support/detection_json.h"
#include "support/png.h"
#include "support/schema_option.h"

namespace arbci::app {
namespace {

struct DetectOptions {
  std::vector<std::string> inputs;
  std::string video;
  int device = -1;
  int frames = 0;
  std::string raw;
  std::string kind;
  double border = 0.0;  // 0: the kind's usual border
  std::string threshold = "adaptive";
  std::string vignetting;
  std::string dictionary;
  std::vector<std::string> patterns;
  bool track = false;
  bool smooth = false;
  double min_cutoff_hz = vision::TrackerOptions{}.min_cutoff_hz;
  double beta = vision::TrackerOptions{}.beta;
  int repeat = 1;
  int decimate = 0;  // tracker.search_decimate
  std::string annotate;
  std::string camera;
  double marker_size_mm = 50.0;
  std::string undistort = "lut";
  std::string pose = "rpp";
  std::string marker_set;
};

// What --camera adds: the lens for the frame size in use, and pose estimation.
struct Geometry {
  vision::CameraModel camera;  // at the frames' size
  std::shared_ptr<const vision::Undistorter> lens;
  vision::PoseOptions pose;
  double marker_size_m = 0.05;
  std::optional<vision::MarkerSet> set;
  std::optional<vision::MarkerPoses> poses;  // remembers each marker's last pose (no flips)
};

nlohmann::json poseJson(const vision::PoseEstimate& estimate) {
  const cv::Vec3d t = estimate.pose.translation, r = estimate.pose.rotationVector();
  auto round6 = [](double v) { return std::round(v * 1e6) / 1e6; };
  nlohmann::json out{
      {"t_m", {round6(t[0]), round6(t[1]), round6(t[2])}},
      {"rvec", {round6(r[0]), round6(r[1]), round6(r[2])}},
      {"reprojection_rms_px", std::round(estimate.reprojection_rms_px * 1000.0) / 1000.0}};
  return out;
}

vision::ThresholdSettings parseThreshold(const DetectOptions& options) {
  vision::ThresholdSettings settings;
  try {
    size_t used = 0;
    const int value = std::stoi(options.threshold, &used);
    if (used != options.threshold.size() || value < 0 || value > 255)
      throw std::invalid_argument("");
    settings.mode = vision::ThresholdMode::Constant;
    settings.value = value;
  } catch (const std::exception&) {
    try {
      settings.mode = vision::thresholdModeFromString(options.threshold);
    } catch (const std::invalid_argument&) {
      throw CliError("--threshold must be 0..255, adaptive, auto-median or auto-midrange, got '" +
                     options.threshold + "'");
    }
  }
  if (!options.vignetting.empty()) {
    vision::Vignetting v;
    char c1 = 0, c2 = 0;
    std::istringstream in(options.vignetting);
    if (!(in >> v.corners >> c1 >> v.left_right >> c2 >> v.top_bottom) || c1 != ',' || c2 != ',') {
      throw CliError("--vignetting must be CORNERS,LEFTRIGHT,TOPBOTTOM offsets, got '" +
                     options.vignetting + "'");
    }
    if (settings.mode == vision::ThresholdMode::Adaptive) {
      throw CliError("--vignetting applies to constant and automatic thresholds, not adaptive");
    }
    settings.vignetting = v;
  }
  return settings;
}

vision::DetectorConfig makeConfig(const DetectOptions& options) {
  vision::DetectorConfig config;
  try {
    config.kind = vision::markerKindFromString(options.kind);
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
  // The family's usual border unless given.
  config.border =
      options.border > 0.0 ? options.border : vision::markerFamilies().at(options.kind).make.border;
  config.threshold = parseThreshold(options);
  config.search_decimate = options.decimate;
  config.dictionary = options.dictionary;
  for (size_t i = 0; i < options.patterns.size(); ++i) {
    // ID=FILE or FILE (ids count from 0 in the order given).
    const std::string& spec = options.patterns[i];
    const size_t equals = spec.find('=');
    int id = static_cast<int>(i);
    std::string file = spec;
    if (equals != std::string::npos) {
      try {
        id = std::stoi(spec.substr(0, equals));
      } catch (const std::exception&) {
        throw CliError("--pattern must be FILE or ID=FILE, got '" + spec + "'");
      }
      file = spec.substr(equals + 1);
    }
    try {
      config.templates.push_back(vision::TemplatePattern::load(file, id));
    } catch (const std::runtime_error& error) {
      throw CliError(error.what());
    }
  }
  return config;
}

void annotate(const std::filesystem::path& folder, const vision::Frame& frame,
              const std::vector<vision::MarkerDetection>& markers) {
  cv::Mat canvas;
  if (frame.image.channels() == 1) {
    cv::cvtColor(frame.image, canvas, cv::COLOR_GRAY2BGR);
  } else if (frame.image.channels() == 4) {
    cv::cvtColor(frame.image, canvas, cv::COLOR_BGRA2BGR);
  } else {
    canvas = frame.image.clone();
  }
  const int thickness = std::max(1, canvas.cols / 640);
  for (const vision::MarkerDetection& m : markers) {
    std::vector<cv::Point> outline;
    for (const cv::Point2f& p : m.corners) outline.emplace_back(cvRound(p.x), cvRound(p.y));
    cv::polylines(canvas, outline, true,
                  m.from_history ? cv::Scalar(0, 200, 255) : cv::Scalar(0, 220, 0), thickness,
                  cv::LINE_AA);
    cv::circle(canvas, outline[0], 3 * thickness, cv::Scalar(0, 0, 255), cv::FILLED);  // top-left
    cv::putText(canvas, std::to_string(m.id), outline[0] + cv::Point(4, -4),
                cv::FONT_HERSHEY_SIMPLEX, 0.5 * thickness, cv::Scalar(255, 0, 0), thickness,
                cv::LINE_AA);
  }
  const std::string stem = std::filesystem::path(frame.name).stem().string();
  writePng(folder / (stem.empty() ? frame.name : stem + ".png"), canvas);
}

Geometry makeGeometry(const DetectOptions& options, cv::Size frame_size) {
  Geometry geometry;
  try {
    const vision::CameraModel camera = vision::CameraModel::load(options.camera);
    camera.checkImageSize(frame_size);
    geometry.camera = camera.scaledTo(frame_size);
    geometry.lens = std::make_shared<vision::Undistorter>(
        geometry.camera, vision::undistortModeFromString(options.undistort));
    geometry.pose.method = vision::poseMethodFromString(options.pose);
    if (!options.marker_set.empty())
      geometry.set = vision::MarkerSet::loadArToolKitConfig(options.marker_set);
  } catch (const vision::CalibrationFileError& error) {
    throw CliError(error.what());
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
  geometry.marker_size_m = options.marker_size_mm / 1000.0;
  geometry.poses.emplace(geometry.camera.camera_matrix, geometry.pose);
  return geometry;
}

int runDetect(const DetectOptions& options) {
  const int sources = (!options.inputs.empty()) + (!options.video.empty()) + (options.device >= 0);
  if (sources != 1)
    throw CliError("give image files, or --video FILE, or --device N (exactly one)");
  if (!options.marker_set.empty() && options.camera.empty()) {
    throw CliError(
        "--marker-set needs --camera: a set's pose needs the camera's intrinsics "
        "(see arbci detect --help)");
  }
  vision::MarkerDetector detector = [&] {
    try {
      return vision::MarkerDetector(makeConfig(options));
    } catch (const std::invalid_argument& error) {
      throw CliError(error.what());
    }
  }();
  std::unique_ptr<vision::FrameSource> source;
  try {
    if (!options.inputs.empty()) {
      std::optional<vision::RawFormat> raw;
      if (!options.raw.empty()) raw = vision::parseRawFormat(options.raw);
      source = vision::imageFiles(options.inputs, raw);
    } else if (!options.video.empty()) {
      source = vision::videoFile(options.video, options.frames);
    } else {
      source = vision::camera(options.device, options.frames);
    }
  } catch (const vision::FrameSourceError& error) {
    throw CliError(error.what());
  }
  if (!options.annotate.empty()) {
    std::error_code error;
    std::filesystem::create_directories(options.annotate, error);
    if (error) throw CliError("cannot create " + options.annotate + ": " + error.message());
  }
  vision::TrackerOptions tracking;
  tracking.smooth_corners = options.smooth;
  tracking.min_cutoff_hz = options.min_cutoff_hz;
  tracking.beta = options.beta;
  vision::MarkerTracker tracker(tracking);
  std::optional<Geometry> geometry;
  int failures = 0, index = 0;
  while (auto frame = source->next()) {
    if (!frame->error.empty()) {
      std::cerr << "arbci: " << frame->error << "\n";
      ++failures;
      continue;
    }
    if (!options.camera.empty() &&
        (!geometry || geometry->camera.image_size != frame->image.size())) {
      // The lens and intrinsics for this frame size (built once per size).
      geometry = makeGeometry(options, frame->image.size());
      vision::DetectorConfig config = detector.config();
      config.lens = geometry->lens;
      detector = vision::MarkerDetector(config);
    }
    vision::DetectionResult result;
    std::vector<vision::StageTimes> times;
    for (int r = 0; r < options.repeat; ++r) {
      result = detector.detect(frame->image);
      times.push_back(result.timing);
    }
    // The run with the median total, whole: its stages add up to its total.
    result.timing = vision::medianRun(times);
    std::vector<vision::MarkerDetection> markers = result.markers;
    if (options.track || options.smooth)
      markers = tracker.update(markers, detector.lastSquares(), index / 30.0,
                               &detector.lastIdealSquares());
    nlohmann::json line{{"frame", frame->name},
                        {"width", frame->image.cols},
                        {"height", frame->image.rows},
                        {"threshold", result.threshold},
                        {"threshold_mode", result.threshold_mode},
                        {"markers", nlohmann::json::array()}};
    std::map<int, vision::PoseEstimate> poses;
    if (geometry) {
      poses = geometry->poses->estimate(markers, [&](int) { return geometry->marker_size_m; });
    }
    for (const auto& m : markers) {
      nlohmann::json marker = markerJson(m);
      if (geometry) {
        nlohmann::json ideal = nlohmann::json::array();
        for (const cv::Point2f& p : m.ideal_corners)
          ideal.push_back({std::round(p.x * 1000.0) / 1000.0, std::round(p.y * 1000.0) / 1000.0});
        marker["ideal_corners"] = ideal;
        if (const auto pose = poses.find(m.id); pose != poses.end())
          marker["pose"] = poseJson(pose->second);
      }
      line["markers"].push_back(marker);
    }
    if (geometry && geometry->set) {
      if (const auto set_pose = vision::estimateSetPose(
              *geometry->set, markers, geometry->camera.camera_matrix, geometry->pose)) {
        line["set_pose"] = poseJson(set_pose->estimate);
        line["set_pose"]["markers"] = set_pose->used_ids;
      }
    }
    line["timing_us"] = stageTimesJson(result.timing);
    std::cout << line.dump() << "\n" << std::flush;
    if (!options.annotate.empty()) annotate(options.annotate, *frame, markers);
    ++index;
  }
  return failures > 0 ? 1 : 0;
}

}  // namespace

void addDetectCommand(CLI::App& root, int& exit_code) {
  auto options = std::make_shared<DetectOptions>();
  auto* command = root.add_subcommand(
      "detect", "Find markers in images, a video or a camera; one JSON line per frame");
  command->add_option("images", options->inputs, "Image files (PNG, JPEG, ...; or raw with --raw)");
  command->add_option("--video", options->video, "A video file");
  command->add_option("--device", options->device, "A camera (V4L2 device number)");
  command->add_option("--frames", options->frames, "At most this many frames of a video or camera")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--raw", options->raw,
                      "Inputs are headerless: WIDTHxHEIGHT[:gray|rgb|bgr|rgba|bgra|abgr|rgb565]");
  const auto& detector = vision::detectorSchema();
  schemaOption(*command, "--kind", options->kind, detector.at("kind"));
  schemaOptionOwnDefault(*command, "--border", options->border, detector.at("border"), 0.0,
                         "the family's own (0.125 for bch, 0.25 for simple)");
  command
      ->add_option("--threshold", options->threshold,
                   "adaptive, auto-median, auto-midrange, or a constant 0..255")
      ->capture_default_str();
  command->add_option(
      "--vignetting", options->vignetting,
      "Threshold offsets CORNERS,LEFTRIGHT,TOPBOTTOM (constant and automatic modes)");
  command->add_option("--dictionary", options->dictionary,
                      "aruco: an OpenCV dictionary (default DICT_6X6_250); apriltag: a libapriltag "
                      "family (default tag36h11; tagStandard41h12, tag25h9, ...)");
  // One pattern per --pattern (repeat it for more): a list would swallow the image names after.
  command
      ->add_option("--pattern", options->patterns,
                   "A template pattern for --kind template: FILE.patt or ID=FILE.patt (one per "
                   "--pattern; repeat it for more)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  command->add_flag("--track", options->track,
                    "Keep identities over frames (video, camera, image sequences)");
  command->add_flag(
      "--smooth", options->smooth,
      "With --track (implied): One-Euro smoothing of the corners, frames taken as "
      "1/30 s apart. docs/bench/tracker-log.md measures it: still markers lose their jitter, "
      "moving ones gain latency (about 5 ms at the defaults, 1 ms at 3 Hz, beta 1)");
  command
      ->add_option("--min-cutoff-hz", options->min_cutoff_hz,
                   "--smooth: the One-Euro cutoff at rest (lower: steadier, laggier)")
      ->check(CLI::Range(0.01, 100.0))
      ->capture_default_str();
  command
      ->add_option("--beta", options->beta,
                   "--smooth: how fast the cutoff rises with corner speed, per px/s")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  command
      ->add_option(
          "--repeat", options->repeat,
          "Detect each frame N times; report the stage times of the run with the median total")
      ->check(CLI::Range(1, 100000));
  schemaOption(*command, "--decimate", options->decimate, detector.at("search_decimate"));
  command->add_option("--annotate", options->annotate,
                      "Write each frame with its markers drawn into this folder");
  command->add_option("--camera", options->camera,
                      "Camera calibration (OpenCV .yml/.xml or ARToolKitPlus .cal): adds "
                      "undistorted corners and poses");
  command
      ->add_option("--marker-size-mm", options->marker_size_mm,
                   "Side of the markers' black square, for poses")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--undistort", options->undistort, "none, algorithmic or lut")
      ->check(CLI::IsMember({"none", "algorithmic", "lut"}))
      ->capture_default_str();
  command->add_option("--pose", options->pose, "rpp, ippe or iterative")
      ->check(CLI::IsMember({"rpp", "ippe", "iterative"}))
      ->capture_default_str();
  command->add_option("--marker-set", options->marker_set,
                      "ARToolKit multi-marker .cfg (mm): adds the set's pose");
  command->callback([options, &exit_code] { exit_code = runDetect(*options); });
}

}  // namespace arbci::app
