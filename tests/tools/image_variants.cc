// image_variants SRC_DIR DST_DIR MAX_SIZE PREFIX
// For benchmarks that need more real images than the shared datasets hold: writes, for
// every image of SRC_DIR, three JPEGs into DST_DIR: PREFIX<stem>_full.jpg (the image,
// longer side at most MAX_SIZE), PREFIX<stem>_crop.jpg (its central 70%, same
// resolution) and PREFIX<stem>_small.jpg (the full view at 60% of that size). Each is a
// distinct image to a detector, showing the same scene. Prints how many it wrote.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc != 5) {
    std::cerr << "usage: image_variants SRC_DIR DST_DIR MAX_SIZE PREFIX\n";
    return 2;
  }
  const fs::path source(argv[1]), destination(argv[2]);
  const int max_size = std::stoi(argv[3]);
  const std::string prefix = argv[4];
  fs::create_directories(destination);
  int written = 0;
  const auto write = [&](const std::string& name, const cv::Mat& image) {
    if (!cv::imwrite((destination / name).string(), image, {cv::IMWRITE_JPEG_QUALITY, 92})) {
      std::cerr << "image_variants: cannot write " << (destination / name) << "\n";
      std::exit(1);
    }
    ++written;
  };
  for (const auto& entry : fs::directory_iterator(source)) {
    if (!entry.is_regular_file()) continue;
    const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_COLOR);
    if (image.empty()) continue;
    const double scale =
        std::min(1.0, static_cast<double>(max_size) / std::max(image.cols, image.rows));
    cv::Mat full = image;
    if (scale < 1.0) cv::resize(image, full, cv::Size(), scale, scale, cv::INTER_AREA);
    const std::string stem = prefix + entry.path().stem().string();
    write(stem + "_full.jpg", full);
    const cv::Rect centre(image.cols * 15 / 100, image.rows * 15 / 100, image.cols * 70 / 100,
                          image.rows * 70 / 100);
    cv::Mat crop;
    cv::resize(image(centre), crop, full.size(), 0, 0, cv::INTER_AREA);
    write(stem + "_crop.jpg", crop);
    cv::Mat small;
    cv::resize(full, small, cv::Size(), 0.6, 0.6, cv::INTER_AREA);
    write(stem + "_small.jpg", small);
  }
  std::cout << written << "\n";
  return written > 0 ? 0 : 1;
}
