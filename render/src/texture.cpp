#include "arbci/render/texture.h"

#include <stdexcept>
#include <utility>

#include "gl.h"

namespace arbci::render {

Texture::Texture() {
  glGenTextures(1, &id_);
}

Texture::~Texture() {
  if (id_) glDeleteTextures(1, &id_);
}

Texture::Texture(Texture&& other) noexcept
    : id_(std::exchange(other.id_, 0)),
      size_(other.size_),
      format_(other.format_),
      grey_(other.grey_) {}

Texture& Texture::operator=(Texture&& other) noexcept {
  if (this != &other) {
    if (id_) glDeleteTextures(1, &id_);
    id_ = std::exchange(other.id_, 0);
    size_ = other.size_;
    format_ = other.format_;
    grey_ = other.grey_;
  }
  return *this;
}

void Texture::upload(const cv::Mat& image, bool smooth) {
  if (image.empty() || image.depth() != CV_8U)
    throw std::invalid_argument("texture: an 8-bit image is needed");
  GLenum format = GL_BGR;
  GLint internal = GL_RGB8;
  switch (image.channels()) {
    case 1:
      format = GL_RED;
      internal = GL_R8;
      break;
    case 3:
      break;
    case 4:
      format = GL_BGRA;
      internal = GL_RGBA8;
      break;
    default:
      throw std::invalid_argument("texture: 1, 3 or 4 channels are needed");
  }
  cv::Mat packed = image.isContinuous() ? image : image.clone();
  glBindTexture(GL_TEXTURE_2D, id_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (packed.size() != size_ || static_cast<int>(format) != format_) {
    glTexImage2D(GL_TEXTURE_2D, 0, internal, packed.cols, packed.rows, 0, format, GL_UNSIGNED_BYTE,
                 packed.data);
    size_ = packed.size();
    format_ = static_cast<int>(format);
  } else {
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, packed.cols, packed.rows, format, GL_UNSIGNED_BYTE,
                    packed.data);
  }
  grey_ = image.channels() == 1;
  if (smooth) {
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  } else {
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

void Texture::uploadMap(const cv::Mat& map) {
  if (map.type() != CV_32FC2) throw std::invalid_argument("texture: a remap table is CV_32FC2");
  cv::Mat packed = map.isContinuous() ? map : map.clone();
  glBindTexture(GL_TEXTURE_2D, id_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RG32F, packed.cols, packed.rows, 0, GL_RG, GL_FLOAT,
               packed.data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  size_ = packed.size();
  format_ = GL_RG;
}

}  // namespace arbci::render
