// Frames to process, from image files (any format OpenCV reads, or headerless raw files of a
// given size and pixel format), a video file or a camera. A frame that cannot be read carries its
// error instead of an image; opening a video or camera that fails throws FrameSourceError. The one
// camera and video reader: `arbci detect` reads it in order, a session through its capture thread.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/pixel_format.h"

namespace arbci::vision {

class FrameSourceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Frame {
  std::string name;   // file name, or the frame index of a video or camera
  cv::Mat image;      // grey, BGR or BGRA
  std::string error;  // why the frame could not be read (image empty)
};

struct RawFormat {
  int width = 0, height = 0;
  PixelFormat format = PixelFormat::Gray;
};

// "320x240" or "320x240:rgb565"; throws FrameSourceError.
RawFormat parseRawFormat(const std::string& text);

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::optional<Frame> next() = 0;
  // A video file's own frame rate (to play it in real time); 0 for a camera, which delivers at
  // its own pace, and for image files.
  virtual double fileRateHz() const { return 0.0; }
};

std::unique_ptr<FrameSource> imageFiles(std::vector<std::string> paths,
                                        std::optional<RawFormat> raw);
std::unique_ptr<FrameSource> videoFile(const std::string& path, int max_frames);
std::unique_ptr<FrameSource> camera(int device, int max_frames);

}  // namespace arbci::vision
