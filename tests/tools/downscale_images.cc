// downscale_images SRC_DIR DST_DIR MAX_SIZE [QUALITY [CONTRAST]]
// Writes a copy of every image in SRC_DIR whose longer side is at most MAX_SIZE, for
// end-to-end tests on small copies of the shared datasets. Prints the scale factor.
// CONTRAST below 1 makes a dark, low-contrast copy (weak texture): each grey level v
// becomes CONTRAST * v + 16.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc < 4) {
    std::cerr << "usage: downscale_images SRC_DIR DST_DIR MAX_SIZE [QUALITY [CONTRAST]]\n";
    return 2;
  }
  const fs::path source(argv[1]), destination(argv[2]);
  const int max_size = std::stoi(argv[3]);
  const int quality = argc > 4 ? std::stoi(argv[4]) : 95;
  const double contrast = argc > 5 ? std::stod(argv[5]) : 1.0;
  fs::create_directories(destination);
  double scale = 1.0;
  for (const auto& entry : fs::directory_iterator(source)) {
    if (!entry.is_regular_file()) continue;
    const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_COLOR);
    if (image.empty()) continue;
    scale = std::min(1.0, static_cast<double>(max_size) / std::max(image.cols, image.rows));
    cv::Mat resized = image;
    if (scale < 1.0) cv::resize(image, resized, cv::Size(), scale, scale, cv::INTER_AREA);
    if (contrast != 1.0) resized.convertTo(resized, CV_8U, contrast, 16);
    const fs::path output = destination / entry.path().filename();
    if (!cv::imwrite(output.string(), resized, {cv::IMWRITE_JPEG_QUALITY, quality})) {
      std::cerr << "cannot write " << output << "\n";
      return 1;
    }
  }
  std::cout << scale << "\n";
  return 0;
}
