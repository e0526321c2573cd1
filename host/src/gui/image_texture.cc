#include "gui/image_texture.h"

#include <imgui.h>

#include <algorithm>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "gui/gl.h"
#include "image/image_masks.h"

namespace tessera::gui {
namespace fs = std::filesystem;

ImageTexture::~ImageTexture() {
  if (id_ != 0) glDeleteTextures(1, &id_);
}

bool ImageTexture::Load(const fs::path& file, int max_width, const fs::path& mask_file) {
  std::error_code error;
  cv::Mat bgr =
      fs::is_regular_file(file, error) ? cv::imread(file.string(), cv::IMREAD_COLOR) : cv::Mat();
  masked_ = false;
  mask_problem_.clear();
  if (bgr.empty()) {
    width_ = 0;
    return false;
  }
  if (!mask_file.empty()) {
    // Masked-out pixels at 30 % of their brightness: the photograph stays readable.
    if (const auto mask = ReadMask(mask_file, bgr.cols, bgr.rows, &mask_problem_)) {
      const cv::Mat dark = bgr * 0.3;
      dark.copyTo(bgr, *mask == 0);
      masked_ = true;
    }
  }
  const double shrink = std::min(1.0, static_cast<double>(max_width) / bgr.cols);
  cv::Mat rgb;
  cv::resize(bgr, rgb, cv::Size(), shrink, shrink, cv::INTER_AREA);
  cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
  if (id_ == 0) glGenTextures(1, &id_);
  glBindTexture(GL_TEXTURE_2D, id_);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, rgb.cols, rgb.rows, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb.data);
  glBindTexture(GL_TEXTURE_2D, 0);
  width_ = rgb.cols;
  height_ = rgb.rows;
  source_width_ = bgr.cols;
  source_height_ = bgr.rows;
  scale_ = static_cast<float>(rgb.cols) / static_cast<float>(bgr.cols);
  return true;
}

void ImageTexture::Draw(float zoom) const {
  ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(id_)),
               ImVec2(static_cast<float>(width_) * zoom, static_cast<float>(height_) * zoom));
}

}  // namespace tessera::gui
