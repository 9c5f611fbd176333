#include "arbci/ui/image_view.h"

#include <imgui.h>

#include <opencv2/imgproc.hpp>

namespace arbci::ui {

void ImageView::draw(const cv::Mat& image, float width) {
  if (image.empty()) {
    ImGui::TextDisabled("(no image)");
    return;
  }
  if (!texture_) texture_ = std::make_unique<render::Texture>();
  // ImGui shows a one-channel texture in red: grey images go up as colour.
  cv::Mat colour = image;
  if (image.channels() == 1) cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
  texture_->upload(colour, false);
  const float height = width * static_cast<float>(image.rows) / static_cast<float>(image.cols);
  ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture_->id())),
               ImVec2(width, height));
}

void ImageView::drawTexture(unsigned int texture, float width, float height, bool flip_vertically) {
  ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture)), ImVec2(width, height),
               flip_vertically ? ImVec2(0, 1) : ImVec2(0, 0),
               flip_vertically ? ImVec2(1, 0) : ImVec2(1, 1));
}

}  // namespace arbci::ui
