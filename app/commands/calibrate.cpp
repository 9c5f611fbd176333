// `arbci calibrate`: a camera (or a stereo pair) from chessboard or ChArUco images, written as an
// OpenCV calibration file. Progress and each view's verdict go to stderr; the result to stdout.
#include <cstdio>
#include <iostream>
#include <memory>

#include <opencv2/imgcodecs.hpp>

#include "arbci/vision/calibration.h"
#include "commands/commands.h"
#include "support/cli_error.h"
#include "support/output_path.h"

namespace arbci::app {
namespace {

struct CalibrateOptions {
  std::string board = "9x6";
  double square_mm = 25.0;
  bool charuco = false;
  double marker_mm = 0.0;
  std::string dictionary = "DICT_6X6_250";
  std::vector<std::string> images;
  std::vector<std::string> right;
  bool fix_aspect = false;
  bool zero_tangential = false;
  std::string out;
};

cv::Size parseBoard(const std::string& text) {
  int cols = 0, rows = 0;
  char x = 0;
  if (std::sscanf(text.c_str(), "%d%c%d", &cols, &x, &rows) != 3 || x != 'x' || cols < 3 ||
      rows < 3 || cols > 100 || rows > 100) {
    throw CliError("--board must be COLSxROWS (e.g. 9x6), got '" + text + "'");
  }
  return {cols, rows};
}

cv::Mat readImage(const std::string& path) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw CliError("cannot read image " + path);
  return image;
}

void printCamera(const vision::CameraModel& camera, double rms) {
  std::printf("image %dx%d  rms %.4f px\nfx %.3f  fy %.3f  cx %.3f  cy %.3f\ndistortion",
              camera.image_size.width, camera.image_size.height, rms, camera.fx(), camera.fy(),
              camera.cx(), camera.cy());
  for (double d : camera.distortion) std::printf(" %.6f", d);
  std::printf("\n");
}

int runCalibrate(const CalibrateOptions& options) {
  vision::CalibrationBoard board;
  if (options.charuco) {
    board.kind = vision::CalibrationBoard::Kind::Charuco;
    board.squares = parseBoard(options.board);
    board.marker_m =
        (options.marker_mm > 0.0 ? options.marker_mm : options.square_mm * 0.5) / 1000.0;
    board.dictionary = options.dictionary;
  } else {
    board.inner_corners = parseBoard(options.board);
  }
  board.square_m = options.square_mm / 1000.0;
  vision::CalibrationFlags flags;
  flags.fix_aspect_ratio = options.fix_aspect;
  flags.zero_tangential = options.zero_tangential;
  ensureWritable(options.out);
  try {
    if (!options.right.empty()) {
      if (options.right.size() != options.images.size()) {
        throw CliError("give as many --right images as left images (" +
                       std::to_string(options.images.size()) + ")");
      }
      std::vector<cv::Mat> left, right;
      for (size_t i = 0; i < options.images.size(); ++i) {
        std::fprintf(stderr, "[%zu/%zu] %s + %s\n", i + 1, options.images.size(),
                     options.images[i].c_str(), options.right[i].c_str());
        left.push_back(readImage(options.images[i]));
        right.push_back(readImage(options.right[i]));
      }
      const vision::StereoResult stereo = vision::calibrateStereo(board, left, right, flags);
      stereo.cameras.save(options.out);
      std::printf("stereo from %d pairs, rms %.4f px\nleft:  ", stereo.pairs, stereo.rms_px);
      printCamera(stereo.cameras.left, stereo.cameras.left.rms_px);
      std::printf("right: ");
      printCamera(stereo.cameras.right, stereo.cameras.right.rms_px);
      const cv::Vec3d t = stereo.cameras.translation * 1000.0;
      std::printf("baseline %.2f mm (%.2f, %.2f, %.2f)\nwrote %s\n", cv::norm(t), t[0], t[1], t[2],
                  options.out.c_str());
      return 0;
    }
    vision::IncrementalCalibrator calibrator(board);
    for (size_t i = 0; i < options.images.size(); ++i) {
      const vision::ViewResult view =
          calibrator.addView(readImage(options.images[i]), options.images[i]);
      std::fprintf(stderr, "[%zu/%zu] %s: %s%s%s\n", i + 1, options.images.size(),
                   options.images[i].c_str(), vision::toString(view.outcome).c_str(),
                   view.reason.empty() ? "" : ": ", view.reason.c_str());
    }
    const vision::CalibrationResult result = calibrator.calibrate(flags);
    vision::CameraModel camera = result.camera;
    camera.source = options.out;
    camera.save(options.out);
    std::printf("%zu views, coverage %.0f %% of the image\n", calibrator.viewCount(),
                100.0 * calibrator.coverageFraction());
    printCamera(camera, result.rms_px);
    for (size_t i = 0; i < result.per_view_rms_px.size(); ++i) {
      std::printf("  %-40s %.3f px\n", result.view_names[i].c_str(), result.per_view_rms_px[i]);
    }
    std::printf("wrote %s\n", options.out.c_str());
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  } catch (const vision::CalibrationFileError& error) {
    throw CliError(error.what());
  } catch (const std::runtime_error& error) {
    throw CliError(std::string("calibration failed: ") + error.what());
  }
  return 0;
}

}  // namespace

void addCalibrateCommand(CLI::App& root, int& exit_code) {
  auto options = std::make_shared<CalibrateOptions>();
  auto* command = root.add_subcommand(
      "calibrate",
      "Calibrate a camera (or a stereo pair with --right) from chessboard or ChArUco images");
  command
      ->add_option("images", options->images, "Images of the board (the left camera's for a pair)")
      ->required();
  command
      ->add_option("--board", options->board,
                   "Chessboard inner corners, or ChArUco squares, as COLSxROWS")
      ->capture_default_str();
  command->add_option("--square-mm", options->square_mm, "Square side in millimetres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_flag("--charuco", options->charuco,
                    "The board is a ChArUco board (--board counts squares)");
  command->add_option("--marker-mm", options->marker_mm,
                      "ChArUco marker side in millimetres (default half a square)");
  command->add_option("--dictionary", options->dictionary, "ChArUco dictionary")
      ->capture_default_str();
  command->add_option("--right", options->right,
                      "The right camera's images, paired in order, for stereo");
  command->add_flag("--fix-aspect", options->fix_aspect, "Keep fx = fy");
  command->add_flag("--zero-tangential", options->zero_tangential,
                    "Assume no tangential distortion");
  command->add_option("--out", options->out, "Calibration file to write (.yml or .xml)")
      ->required();
  command->callback([options, &exit_code] { exit_code = runCalibrate(*options); });
}

}  // namespace arbci::app
