// The time to read a COLMAP model in C++ (ReadColmapModel), the reference of
// benchmarks/python_read_model.py, which reads the same model from Python.
//
//   colmap_model_read_benchmark MODEL_DIR [REPEATS]
// prints "read_seconds_median S points N images M" (the median of REPEATS reads, 5).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "tessera/io/colmap_model_io.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: colmap_model_read_benchmark MODEL_DIR [REPEATS]\n");
    return 2;
  }
  const int repeats = argc > 2 ? std::max(1, std::stoi(argv[2])) : 5;
  std::vector<double> seconds;
  size_t num_points = 0, num_images = 0;
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const tessera::Reconstruction model = tessera::ReadColmapModel(argv[1]);
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    num_points = model.points3D.size();
    num_images = model.images.size();
  }
  std::sort(seconds.begin(), seconds.end());
  std::printf("read_seconds_median %.6f points %zu images %zu\n", seconds[seconds.size() / 2],
              num_points, num_images);
  return 0;
}
