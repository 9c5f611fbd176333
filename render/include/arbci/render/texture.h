// A 2D GL texture owned RAII-style, filled from OpenCV images (grey, BGR, BGRA) or from a
// two-channel float map.
#pragma once

#include <opencv2/core/mat.hpp>

namespace arbci::render {

class Texture {
 public:
  Texture();  // needs a current GL context
  ~Texture();
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
  Texture(Texture&& other) noexcept;
  Texture& operator=(Texture&& other) noexcept;

  // 8-bit grey, BGR or BGRA; reallocates only when the size or format changes.
  // `smooth`: linear filtering with mipmaps (for markers seen small) instead of nearest.
  void upload(const cv::Mat& image, bool smooth = true);
  // CV_32FC2: per pixel a normalised source coordinate (a remap table).
  void uploadMap(const cv::Mat& map);
  unsigned int id() const { return id_; }
  cv::Size size() const { return size_; }
  bool grey() const { return grey_; }

 private:
  unsigned int id_ = 0;
  cv::Size size_;
  int format_ = 0;
  bool grey_ = false;
};

}  // namespace arbci::render
