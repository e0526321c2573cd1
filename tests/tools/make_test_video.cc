// Writes a test video from an ordered folder of images (tests of video input): each
// image resized to WIDTH pixels wide, every third one followed by a blurred copy
// (Gaussian blur, sigma 3 px at 480 px), and the camera held still (the same image
// repeated STILL times) after the images a quarter and three quarters of the way. FOURCC
// avc1 is H.264 in MP4.
// Prints one line per video frame: "INDEX SOURCE KIND" with KIND sharp, blurred or still
// (0-based frame index, 0-based source image index).
// usage: tessera_test_video IMAGE_DIR OUT.mp4 WIDTH [FOURCC avc1] [FPS 10] [STILL 8]
//        [MAX_IMAGES 0: all]

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s IMAGE_DIR OUT.mp4 WIDTH [FOURCC] [FPS] [STILL] [MAX_IMAGES]\n",
                 argv[0]);
    return 2;
  }
  const int width = std::stoi(argv[3]);
  const std::string fourcc = argc > 4 ? argv[4] : "avc1";
  const double fps = argc > 5 ? std::stod(argv[5]) : 10;
  const int still = argc > 6 ? std::stoi(argv[6]) : 8;
  const size_t max_images = argc > 7 ? std::stoul(argv[7]) : 0;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(argv[1])) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".jpg" || ext == ".png") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (max_images > 0 && files.size() > max_images) files.resize(max_images);
  if (files.empty()) {
    std::fprintf(stderr, "%s: no images\n", argv[1]);
    return 1;
  }
  cv::VideoWriter writer;
  int index = 0;
  for (size_t i = 0; i < files.size(); ++i) {
    const cv::Mat image = cv::imread(files[i].string(), cv::IMREAD_COLOR);
    cv::Mat frame;
    const int height = (image.rows * width / image.cols) / 2 * 2;  // even, for H.264
    cv::resize(image, frame, cv::Size(width, height), 0, 0, cv::INTER_AREA);
    if (!writer.isOpened()) {
      writer.open(argv[2], cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), fps,
                  frame.size());
      if (!writer.isOpened()) {
        std::fprintf(stderr, "%s: cannot write a %s video\n", argv[2], fourcc.c_str());
        return 1;
      }
    }
    writer << frame;
    std::printf("%d %zu sharp\n", index++, i);
    if (i % 3 == 1) {
      cv::Mat blurred;
      cv::GaussianBlur(frame, blurred, cv::Size(), 3.0 * width / 480);
      writer << blurred;
      std::printf("%d %zu blurred\n", index++, i);
    }
    if (i == files.size() / 4 || i == files.size() * 3 / 4) {
      for (int k = 0; k < still; ++k) {
        writer << frame;
        std::printf("%d %zu still\n", index++, i);
      }
    }
  }
  writer.release();
  return 0;
}
