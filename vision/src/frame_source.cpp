#include "arbci/vision/frame_source.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

namespace arbci::vision {
namespace {

Frame readRaw(const std::string& path, const RawFormat& raw) {
  Frame frame{path, {}, {}};
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  if (error) {
    frame.error = "cannot read " + path + ": " + error.message();
    return frame;
  }
  const auto expected =
      static_cast<std::uintmax_t>(raw.width) * raw.height * vision::bytesPerPixel(raw.format);
  if (size != expected) {
    frame.error = path + ": a " + std::to_string(raw.width) + "x" + std::to_string(raw.height) +
                  " " + vision::toString(raw.format) + " raw image has " +
                  std::to_string(expected) + " bytes, the file has " + std::to_string(size);
    return frame;
  }
  std::vector<std::uint8_t> bytes(static_cast<size_t>(size));
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
  if (!in) {
    frame.error = "cannot read " + path;
    return frame;
  }
  const vision::ImageView view{bytes.data(), raw.width, raw.height,
                               static_cast<size_t>(raw.width) * vision::bytesPerPixel(raw.format),
                               raw.format};
  vision::toLuminance(view, frame.image);
  return frame;
}

class ImageFiles final : public FrameSource {
 public:
  ImageFiles(std::vector<std::string> paths, std::optional<RawFormat> raw)
      : paths_(std::move(paths)), raw_(raw) {}
  std::optional<Frame> next() override {
    if (index_ >= paths_.size()) return std::nullopt;
    const std::string& path = paths_[index_++];
    if (raw_) return readRaw(path, *raw_);
    Frame frame{path, {}, {}};
    if (!std::filesystem::is_regular_file(path)) {
      frame.error = "cannot read " + path + ": no such file";
      return frame;
    }
    try {
      frame.image = cv::imread(path, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception& e) {
      frame.error = "cannot decode " + path + ": " + e.err;
      return frame;
    }
    if (frame.image.empty()) {
      frame.error = "cannot decode " + path + " as an image";
    } else if (frame.image.depth() != CV_8U) {
      frame.image.convertTo(frame.image, CV_8U, frame.image.depth() == CV_16U ? 1.0 / 257.0 : 1.0);
    }
    if (frame.image.channels() == 2) frame.image = cv::Mat();  // grey + alpha is rare: reject
    if (frame.error.empty() && frame.image.empty())
      frame.error = path + ": unsupported channel layout";
    return frame;
  }

 private:
  std::vector<std::string> paths_;
  std::optional<RawFormat> raw_;
  size_t index_ = 0;
};

class Capture final : public FrameSource {
 public:
  Capture(cv::VideoCapture capture, int max_frames, bool file)
      : capture_(std::move(capture)), max_frames_(max_frames), file_(file) {}
  double fileRateHz() const override {
    return file_ ? std::max(0.0, capture_.get(cv::CAP_PROP_FPS)) : 0.0;
  }
  std::optional<Frame> next() override {
    if (max_frames_ > 0 && index_ >= max_frames_) return std::nullopt;
    Frame frame{std::to_string(index_), {}, {}};
    if (!capture_.read(frame.image) || frame.image.empty()) return std::nullopt;
    ++index_;
    return frame;
  }

 private:
  cv::VideoCapture capture_;
  int max_frames_;
  bool file_;
  int index_ = 0;
};

}  // namespace

RawFormat parseRawFormat(const std::string& text) {
  RawFormat raw;
  char separator = 0;
  std::istringstream in(text);
  if (!(in >> raw.width >> separator >> raw.height) || separator != 'x' || raw.width <= 0 ||
      raw.height <= 0 || raw.width > 32768 || raw.height > 32768) {
    throw FrameSourceError("--raw must be WIDTHxHEIGHT[:FORMAT], got '" + text + "'");
  }
  std::string rest;
  std::getline(in, rest);
  if (!rest.empty()) {
    if (rest[0] != ':')
      throw FrameSourceError("--raw must be WIDTHxHEIGHT[:FORMAT], got '" + text + "'");
    try {
      raw.format = vision::pixelFormatFromString(rest.substr(1));
    } catch (const std::invalid_argument& error) {
      throw FrameSourceError(error.what());
    }
  }
  return raw;
}

std::unique_ptr<FrameSource> imageFiles(std::vector<std::string> paths,
                                        std::optional<RawFormat> raw) {
  return std::make_unique<ImageFiles>(std::move(paths), raw);
}

std::unique_ptr<FrameSource> videoFile(const std::string& path, int max_frames) {
  if (!std::filesystem::is_regular_file(path))
    throw FrameSourceError("cannot open video " + path + ": no such file");
  cv::VideoCapture capture(path);
  if (!capture.isOpened())
    throw FrameSourceError("cannot open video " + path + " (unknown format or codec)");
  return std::make_unique<Capture>(std::move(capture), max_frames, true);
}

std::unique_ptr<FrameSource> camera(int device, int max_frames) {
  cv::VideoCapture capture(device, cv::CAP_V4L2);
  if (!capture.isOpened())
    throw FrameSourceError("cannot open camera /dev/video" + std::to_string(device));
  return std::make_unique<Capture>(std::move(capture), max_frames, false);
}

}  // namespace arbci::vision
