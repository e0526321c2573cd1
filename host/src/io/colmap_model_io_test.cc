#include "tessera/io/colmap_model_io.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using testing::TemporaryDir;

std::string ReadBytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

fs::path AnchorDir(const std::string& dataset) {
  return testing::SharedDir() / "anchors" / "colmap-3.8" / dataset;
}

// Exact equality of everything the files hold; rotations up to the last bits, since the
// writer normalizes quaternions as COLMAP does.
void ExpectEqualReconstructions(const Reconstruction& a, const Reconstruction& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (const auto& [camera_id, camera] : a.cameras) {
    ASSERT_EQ(b.cameras.count(camera_id), 1u) << camera_id;
    const Camera& other = b.cameras.at(camera_id);
    EXPECT_EQ(camera.camera_id, other.camera_id);
    EXPECT_EQ(camera.model_id, other.model_id);
    EXPECT_EQ(camera.width, other.width);
    EXPECT_EQ(camera.height, other.height);
    EXPECT_EQ(camera.params, other.params);
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (const auto& [image_id, image] : a.images) {
    ASSERT_EQ(b.images.count(image_id), 1u) << image_id;
    const Image& other = b.images.at(image_id);
    EXPECT_EQ(image.image_id, other.image_id);
    EXPECT_EQ(image.camera_id, other.camera_id);
    EXPECT_EQ(image.name, other.name);
    EXPECT_EQ(image.registered, other.registered);
    EXPECT_LT(
        (image.cam_from_world.rotation.coeffs() - other.cam_from_world.rotation.coeffs()).norm(),
        1e-15);
    EXPECT_EQ(image.cam_from_world.translation, other.cam_from_world.translation);
    ASSERT_EQ(image.points2D.size(), other.points2D.size());
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      EXPECT_EQ(image.points2D[i].xy, other.points2D[i].xy);
      EXPECT_EQ(image.points2D[i].point3D_id, other.points2D[i].point3D_id);
    }
  }
  ASSERT_EQ(a.points3D.size(), b.points3D.size());
  for (const auto& [point3D_id, point3D] : a.points3D) {
    ASSERT_EQ(b.points3D.count(point3D_id), 1u) << point3D_id;
    const Point3D& other = b.points3D.at(point3D_id);
    EXPECT_EQ(point3D.xyz, other.xyz);
    EXPECT_EQ(point3D.color, other.color);
    EXPECT_EQ(point3D.error, other.error);
    ASSERT_EQ(point3D.track.size(), other.track.size());
    for (size_t i = 0; i < point3D.track.size(); ++i) {
      EXPECT_EQ(point3D.track[i].image_id, other.track[i].image_id);
      EXPECT_EQ(point3D.track[i].point2D_idx, other.track[i].point2D_idx);
    }
  }
}

// One camera of each model, images with and without 2D points, points with and without
// tracks, and one unregistered image (which COLMAP's writer leaves out).
Reconstruction SyntheticReconstruction() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  Reconstruction reconstruction;
  camera_t camera_id = 3;
  for (const CameraModelId model_id : AllCameraModelIds()) {
    Camera camera = Camera::Create(camera_id, model_id, 1000 + 17.25 * camera_id, 640, 480);
    for (const int idx : camera.ExtraParamsIdx()) camera.params[idx] = 0.01 * uniform(rng);
    camera.params[0] += 1.0 / 3.0;
    reconstruction.cameras[camera_id] = camera;
    camera_id += 2;
  }
  const std::vector<camera_t> camera_ids = {3, 5, 7, 9, 11};
  for (image_t image_id = 1; image_id <= 6; ++image_id) {
    Image image;
    image.image_id = image_id;
    image.camera_id = camera_ids[image_id % camera_ids.size()];
    image.name =
        image_id == 2 ? "sub dir/with space.png" : "img" + std::to_string(image_id) + ".jpg";
    image.registered = image_id != 6;
    image.cam_from_world.rotation =
        Eigen::Quaterniond(uniform(rng), uniform(rng), uniform(rng), uniform(rng)).normalized();
    image.cam_from_world.translation = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    const int num_points2D = image_id == 4 ? 0 : 5 + static_cast<int>(image_id);
    for (int i = 0; i < num_points2D; ++i) {
      Point2D point2D;
      point2D.xy = Eigen::Vector2d(320 + 300 * uniform(rng), 240 + 200 * uniform(rng));
      image.points2D.push_back(point2D);
    }
    reconstruction.images[image_id] = image;
  }
  // Points 10, 20, ... seen by two images each; point 1000 has no track.
  point3D_t point3D_id = 10;
  for (image_t image_id : {1u, 2u, 3u}) {
    for (point2D_t idx = 0; idx < 3; ++idx) {
      Point3D point3D;
      point3D.xyz = Eigen::Vector3d(uniform(rng), uniform(rng), 5 + uniform(rng));
      point3D.color = Eigen::Matrix<uint8_t, 3, 1>(static_cast<uint8_t>(point3D_id), 0, 255);
      point3D.error = 0.1 * point3D_id + 1e-9;
      // Image 4 has no 2D points; image 5 sees the points of images 2 and 3.
      const image_t other = image_id == 2 ? 5 : image_id + 2;
      const point2D_t other_idx = idx + (image_id == 3 ? 7 : 4);
      for (const auto& [track_image_id, track_idx] :
           {std::pair(image_id, idx + 1), std::pair(other, other_idx)}) {
        point3D.track.push_back({track_image_id, track_idx});
        reconstruction.images.at(track_image_id).points2D.at(track_idx).point3D_id = point3D_id;
      }
      reconstruction.points3D[point3D_id] = point3D;
      point3D_id += 10;
    }
  }
  Point3D lonely;
  lonely.xyz = Eigen::Vector3d(1e-300, -0.0, 12345678.9);
  reconstruction.points3D[1000] = lonely;
  return reconstruction;
}

Reconstruction RegisteredOnly(Reconstruction reconstruction) {
  for (auto it = reconstruction.images.begin(); it != reconstruction.images.end();) {
    it = it->second.registered ? std::next(it) : reconstruction.images.erase(it);
  }
  return reconstruction;
}

std::vector<std::string> FileNames(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(ColmapModelIo, SyntheticRoundTripInBothFormats) {
  const Reconstruction reconstruction = SyntheticReconstruction();
  for (const auto format : {ColmapModelFormat::kBinary, ColmapModelFormat::kText}) {
    TemporaryDir dir;
    WriteColmapModel(reconstruction, dir.path() / "model", format);
    const std::string extension = format == ColmapModelFormat::kBinary ? ".bin" : ".txt";
    // Only the three files: no temporary file is left behind.
    EXPECT_EQ(FileNames(dir.path() / "model"),
              (std::vector<std::string>{"cameras" + extension, "images" + extension,
                                        "points3D" + extension}));
    const Reconstruction read = ReadColmapModel(dir.path() / "model");
    EXPECT_EQ(read.images.size(), 5u);  // the unregistered image is not written
    EXPECT_EQ(read.NumRegisteredImages(), 5u);
    ExpectEqualReconstructions(RegisteredOnly(reconstruction), read);
    EXPECT_TRUE(read.images.at(4).points2D.empty());
    EXPECT_TRUE(read.points3D.at(1000).track.empty());
    EXPECT_EQ(read.images.at(2).name, "sub dir/with space.png");
    EXPECT_EQ(read.cameras.at(11).model_id, CameraModelId::kOpenCV);
  }
}

// COLMAP's ids: OPENCV_FISHEYE is 5, SIMPLE_RADIAL_FISHEYE 8, in both formats.
TEST(ColmapModelIo, FisheyeCamerasRoundTripWithColmapsIds) {
  Reconstruction reconstruction;
  reconstruction.cameras[1] = Camera::Create(1, CameraModelId::kOpenCVFisheye, 300, 640, 480);
  reconstruction.cameras[1].params = {300, 301, 320.5, 239.5, 0.05, -0.01, 0.002, -0.0003};
  reconstruction.cameras[2] = Camera::Create(2, CameraModelId::kSimpleRadialFisheye, 250, 64, 48);
  reconstruction.cameras[2].params[3] = 0.04;
  for (image_t id : {1, 2}) {
    Image image;
    image.image_id = id;
    image.camera_id = id;
    image.name = std::to_string(id) + ".jpg";
    image.registered = true;
    reconstruction.images[id] = image;
  }
  TemporaryDir dir;
  WriteColmapModel(reconstruction, dir.path() / "text", ColmapModelFormat::kText);
  EXPECT_NE(ReadFileContents(dir.path() / "text" / "cameras.txt")
                .find("\n1 OPENCV_FISHEYE 640 480 300 301 320.5 239.5 "),
            std::string::npos)
      << ReadFileContents(dir.path() / "text" / "cameras.txt");
  WriteColmapModel(reconstruction, dir.path() / "binary", ColmapModelFormat::kBinary);
  const std::string binary = ReadFileContents(dir.path() / "binary" / "cameras.bin");
  int32_t model_id = -1;
  std::memcpy(&model_id, binary.data() + 8 + 4, 4);  // after the count and camera id
  EXPECT_EQ(model_id, 5);
  for (const char* format : {"text", "binary"}) {
    const Reconstruction read = ReadColmapModel(dir.path() / format);
    EXPECT_EQ(read.cameras.at(1).model_id, CameraModelId::kOpenCVFisheye) << format;
    EXPECT_EQ(read.cameras.at(1).params, reconstruction.cameras[1].params) << format;
    EXPECT_EQ(read.cameras.at(2).model_id, CameraModelId::kSimpleRadialFisheye) << format;
    EXPECT_EQ(read.cameras.at(2).params, reconstruction.cameras[2].params) << format;
  }
}

TEST(ColmapModelIo, TextLayoutMatchesColmap) {
  Reconstruction reconstruction;
  reconstruction.cameras[1] =
      Camera::Create(1, CameraModelId::kSimpleRadial, 1.0 / 3.0, 3072, 2048);
  Image image;
  image.image_id = 1;
  image.camera_id = 1;
  image.name = "a.jpg";
  image.registered = true;
  image.points2D.resize(2);
  image.points2D[0].xy = Eigen::Vector2d(0.5, 1e-20);
  image.points2D[1].xy = Eigen::Vector2d(1536, 2.25);
  image.points2D[1].point3D_id = 7;
  reconstruction.images[1] = image;
  Image empty = image;
  empty.image_id = 2;
  empty.name = "b.jpg";
  empty.points2D.clear();
  reconstruction.images[2] = empty;
  Point3D point3D;
  point3D.xyz = Eigen::Vector3d(0.1, -2, 3);
  point3D.color = Eigen::Matrix<uint8_t, 3, 1>(1, 2, 255);
  point3D.error = 0.5;
  point3D.track = {{1, 1}};
  reconstruction.points3D[7] = point3D;
  point3D.track.clear();
  reconstruction.points3D[8] = point3D;

  TemporaryDir dir;
  WriteColmapModel(reconstruction, dir.path(), ColmapModelFormat::kText);
  EXPECT_EQ(ReadBytes(dir.path() / "cameras.txt"),
            "# Camera list with one line of data per camera:\n"
            "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
            "# Number of cameras: 1\n"
            "1 SIMPLE_RADIAL 3072 2048 0.33333333333333331 1536 1024 0\n");
  EXPECT_EQ(ReadBytes(dir.path() / "images.txt"),
            "# Image list with two lines of data per image:\n"
            "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
            "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
            "# Number of images: 2, mean observations per image: 0.5\n"
            "1 1 0 0 0 0 0 0 1 a.jpg\n"
            "0.5 9.9999999999999995e-21 -1 1536 2.25 7\n"
            "2 1 0 0 0 0 0 0 1 b.jpg\n"
            "\n");
  // COLMAP keeps the space after the error of a point without a track.
  EXPECT_EQ(ReadBytes(dir.path() / "points3D.txt"),
            "# 3D point list with one line of data per point:\n"
            "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
            "# Number of points: 2, mean track length: 0.5\n"
            "7 0.10000000000000001 -2 3 1 2 255 0.5 1 1\n"
            "8 0.10000000000000001 -2 3 1 2 255 0.5 \n");
  ExpectEqualReconstructions(reconstruction, ReadColmapModel(dir.path()));
}

TEST(ColmapModelIo, BinaryLayoutMatchesColmap) {
  Reconstruction reconstruction;
  reconstruction.cameras[2] = Camera::Create(2, CameraModelId::kPinhole, 100, 640, 480);
  TemporaryDir dir;
  WriteColmapModel(reconstruction, dir.path(), ColmapModelFormat::kBinary);
  // uint64 count, uint32 id, int32 model id, uint64 width, height, 4 doubles.
  std::string expected;
  const uint64_t count = 1, width = 640, height = 480;
  const uint32_t camera_id = 2;
  const int32_t model_id = 1;
  const double params[] = {100, 100, 320, 240};
  expected.append(reinterpret_cast<const char*>(&count), 8);
  expected.append(reinterpret_cast<const char*>(&camera_id), 4);
  expected.append(reinterpret_cast<const char*>(&model_id), 4);
  expected.append(reinterpret_cast<const char*>(&width), 8);
  expected.append(reinterpret_cast<const char*>(&height), 8);
  expected.append(reinterpret_cast<const char*>(params), sizeof(params));
  EXPECT_EQ(ReadBytes(dir.path() / "cameras.bin"), expected);
  EXPECT_EQ(ReadBytes(dir.path() / "images.bin"), std::string(8, '\0'));
  EXPECT_EQ(ReadBytes(dir.path() / "points3D.bin"), std::string(8, '\0'));
}

TEST(ColmapModelIo, BinaryPreferredOverText) {
  const Reconstruction reconstruction = RegisteredOnly(SyntheticReconstruction());
  Reconstruction other = reconstruction;
  other.cameras.at(3).params[0] = 42;
  TemporaryDir dir;
  WriteColmapModel(reconstruction, dir.path(), ColmapModelFormat::kBinary);
  WriteColmapModel(other, dir.path(), ColmapModelFormat::kText);
  EXPECT_EQ(ReadColmapModel(dir.path()).cameras.at(3).params[0],
            reconstruction.cameras.at(3).params[0]);
  fs::remove(dir.path() / "points3D.bin");
  EXPECT_EQ(ReadColmapModel(dir.path()).cameras.at(3).params[0], 42);
}

TEST(ColmapModelIo, MissingModelNamesTheFolder) {
  TemporaryDir dir;
  try {
    ReadColmapModel(dir.path() / "nowhere");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (dir.path() / "nowhere").string() +
                  " is not a COLMAP model: it lacks cameras, images and points3D as .bin or .txt "
                  "files.");
  }
}

// A small binary model; every strict prefix of each of its files must be refused.
TEST(ColmapModelIo, EveryTruncationOfABinaryFileThrowsInputError) {
  const Reconstruction reconstruction = SyntheticReconstruction();
  TemporaryDir source;
  WriteColmapModel(reconstruction, source.path(), ColmapModelFormat::kBinary);
  int num_cases = 0;
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string bytes = ReadBytes(source.path() / name);
    TemporaryDir dir;
    fs::copy(source.path(), dir.path(), fs::copy_options::recursive);
    for (size_t length = 0; length < bytes.size(); ++length) {
      WriteBytes(dir.path() / name, bytes.substr(0, length));
      try {
        ReadColmapModel(dir.path());
        ADD_FAILURE() << name << " cut to " << length << " bytes was accepted";
      } catch (const InputError& error) {
        // The message names the file that was cut.
        EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
      }
      ++num_cases;
    }
    // And a byte too many.
    WriteBytes(dir.path() / name, bytes + "x");
    EXPECT_THROW(ReadColmapModel(dir.path()), InputError) << name << " with a byte appended";
  }
  EXPECT_GT(num_cases, 1000);
}

// Random bytes overwritten: the reader either reads a (different) model or throws
// InputError; it never crashes, hangs or throws anything else.
TEST(ColmapModelIo, RandomCorruptionNeverCrashes) {
  const Reconstruction reconstruction = SyntheticReconstruction();
  std::mt19937 rng(12345);
  int num_refused = 0, num_cases = 0;
  for (const auto format : {ColmapModelFormat::kBinary, ColmapModelFormat::kText}) {
    TemporaryDir dir;
    WriteColmapModel(reconstruction, dir.path(), format);
    const std::string extension = format == ColmapModelFormat::kBinary ? ".bin" : ".txt";
    for (const std::string name : {"cameras", "images", "points3D"}) {
      const fs::path path = dir.path() / (name + extension);
      const std::string bytes = ReadBytes(path);
      for (int trial = 0; trial < 60; ++trial) {
        std::string corrupt = bytes;
        const int num_changes = 1 + static_cast<int>(rng() % 4);
        for (int k = 0; k < num_changes; ++k) {
          corrupt[rng() % corrupt.size()] = static_cast<char>(rng() % 256);
        }
        WriteBytes(path, corrupt);
        ++num_cases;
        try {
          ReadColmapModel(dir.path());
        } catch (const InputError&) {
          ++num_refused;
        }
      }
      WriteBytes(path, bytes);
    }
  }
  EXPECT_EQ(num_cases, 360);
  // Most corruptions hit a count, an id or a number's syntax and are refused.
  EXPECT_GT(num_refused, 100);
}

TEST(ColmapModelIo, HugeCountsThrowQuickly) {
  const Reconstruction reconstruction = SyntheticReconstruction();
  TemporaryDir source;
  WriteColmapModel(reconstruction, source.path(), ColmapModelFormat::kBinary);
  const uint64_t huge = uint64_t{1} << 60;
  // Header counts of each file, and the 2D point count of the first image (after the
  // fixed part and the NUL-terminated name).
  const std::string images = ReadBytes(source.path() / "images.bin");
  const size_t name_end = images.find('\0', 8 + 64);
  const std::vector<std::pair<std::string, size_t>> cases = {
      {"cameras.bin", 0}, {"images.bin", 0}, {"points3D.bin", 0}, {"images.bin", name_end + 1}};
  for (const auto& [name, offset] : cases) {
    TemporaryDir dir;
    fs::copy(source.path(), dir.path(), fs::copy_options::recursive);
    std::string bytes = ReadBytes(dir.path() / name);
    std::memcpy(&bytes[offset], &huge, 8);
    WriteBytes(dir.path() / name, bytes);
    try {
      ReadColmapModel(dir.path());
      FAIL() << "expected InputError for " << name << " at " << offset;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("claims 1152921504606846976"), std::string::npos)
          << error.what();
      EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
    }
  }
}

TEST(ColmapModelIo, MalformedTextNamesFileLineAndField) {
  const Reconstruction reconstruction = SyntheticReconstruction();
  TemporaryDir dir;
  WriteColmapModel(reconstruction, dir.path(), ColmapModelFormat::kText);
  const auto expect_message = [&](const std::string& file, const std::string& contents,
                                  const std::string& message) {
    const std::string original = ReadBytes(dir.path() / file);
    WriteBytes(dir.path() / file, contents);
    try {
      ReadColmapModel(dir.path());
      ADD_FAILURE() << "expected InputError: " << message;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()), (dir.path() / file).string() + message);
    }
    WriteBytes(dir.path() / file, original);
  };
  expect_message("cameras.txt", "# comment\n1 FISHEYE 10 10 1 2 3\n",
                 " line 2: unknown camera model 'FISHEYE'.");
  expect_message("cameras.txt", "1 PINHOLE 10 10 1 2 3\n",
                 " line 1: PINHOLE takes 4 parameters, found 3.");
  expect_message("cameras.txt", "1 PINHOLE 10 1O 1 2 3 4\n",
                 " line 1: '1O' is not a valid height.");
  expect_message("images.txt", "1 1 0 0 0 0 0 0 3 a.jpg\n",
                 " ends after line 1: the 2D points line of image 1 is missing.");
  expect_message("images.txt", "1 1 0 0 0 0 0 0 3 a.jpg\n1 2\n",
                 " line 2: the 2D points of image 1 are not triplets X Y POINT3D_ID.");
  expect_message("images.txt", "1 1 0 0 0 0 0 0 4 a.jpg\n\n",
                 ": image 1 (a.jpg) refers to camera 4, which the cameras file does not hold.");
  expect_message("points3D.txt", "5 1 2 3 0 0 300 0.5\n",
                 " line 1: the colour channel 300 is over 255.");
  expect_message("points3D.txt", "5 1 2 3 0 0 0 0.5 1 99\n",
                 ": the track of 3D point 5 refers to 2D point 99 of image 1, which has only 6.");
}

// NaN and infinity used to be read, and the transforms_json exporter then wrote them as
// null; a quaternion of length 0 was read as the identity.
TEST(ColmapModelIo, NonFiniteNumbersAndZeroRotationsAreRefusedNamingFileLineAndField) {
  TemporaryDir dir;
  WriteColmapModel(SyntheticReconstruction(), dir.path(), ColmapModelFormat::kText);
  const auto expect_message = [&](const std::string& file, const std::string& contents,
                                  const std::string& message) {
    const std::string original = ReadBytes(dir.path() / file);
    WriteBytes(dir.path() / file, contents);
    try {
      ReadColmapModel(dir.path());
      ADD_FAILURE() << "expected InputError: " << message;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()), (dir.path() / file).string() + message);
    }
    WriteBytes(dir.path() / file, original);
  };
  expect_message("cameras.txt", "1 PINHOLE 10 10 1 nan 3 4\n",
                 " line 1: 'nan' is not a finite camera parameter.");
  expect_message("images.txt", "1 1 0 0 0 0 inf 0 3 a.jpg\n\n",
                 " line 1: 'inf' is not a finite translation component.");
  expect_message("images.txt", "1 1 0 0 0 0 0 0 3 a.jpg\n1 -NaN -1\n",
                 " line 2: '-NaN' is not a finite 2D point y.");
  expect_message("images.txt", "7 0 0 0 0 0 0 0 3 a.jpg\n\n",
                 " line 1: the rotation of image 7 has length 0.");
  expect_message("points3D.txt", "5 1 nan 3 0 0 0 0.5\n",
                 " line 1: 'nan' is not a finite coordinate.");
  expect_message("points3D.txt", "5 1 2 3 0 0 0 INFINITY\n",
                 " line 1: 'INFINITY' is not a finite error.");
}

TEST(ColmapModelIo, NonFiniteNumbersAndZeroRotationsAreRefusedNamingBinaryRecordAndField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto expect_message = [](const Reconstruction& reconstruction, const std::string& file,
                                 const std::string& message) {
    TemporaryDir dir;
    WriteColmapModel(reconstruction, dir.path(), ColmapModelFormat::kBinary);
    try {
      ReadColmapModel(dir.path());
      ADD_FAILURE() << "expected InputError: " << message;
    } catch (const InputError& error) {
      const std::string text = error.what();
      EXPECT_EQ(text.rfind((dir.path() / file).string() + " is truncated or malformed at byte ", 0),
                0u)
          << text;
      EXPECT_NE(text.find(message), std::string::npos) << text;
    }
  };
  Reconstruction camera = SyntheticReconstruction();
  camera.cameras.at(5).params[1] = nan;
  expect_message(camera, "cameras.bin",
                 ": the parameters of camera 5: nan is not a finite number.");
  Reconstruction translation = SyntheticReconstruction();
  translation.images.at(2).cam_from_world.translation.y() = -inf;
  expect_message(translation, "images.bin",
                 ": the translation of image 2: -inf is not a finite number.");
  Reconstruction point2D = SyntheticReconstruction();
  point2D.images.at(3).points2D.at(1).xy.x() = nan;
  expect_message(point2D, "images.bin", ": a 2D point of image 3: nan is not a finite number.");
  // The writer normalizes a zero quaternion to the identity, so the bytes are changed:
  // the first record's rotation follows the count (8 bytes) and the image id (4).
  TemporaryDir zero;
  WriteColmapModel(SyntheticReconstruction(), zero.path(), ColmapModelFormat::kBinary);
  std::string images = ReadBytes(zero.path() / "images.bin");
  std::fill(images.begin() + 12, images.begin() + 12 + 4 * 8, '\0');
  WriteBytes(zero.path() / "images.bin", images);
  try {
    ReadColmapModel(zero.path());
    ADD_FAILURE() << "a zero quaternion was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (zero.path() / "images.bin").string() +
                  " is truncated or malformed at byte 44: the rotation of image 1 has length 0.");
  }
  Reconstruction point3D = SyntheticReconstruction();
  point3D.points3D.at(20).xyz.z() = inf;
  expect_message(point3D, "points3D.bin",
                 ": the position of 3D point 20: inf is not a finite number.");
  Reconstruction error = SyntheticReconstruction();
  error.points3D.at(1000).error = nan;
  expect_message(error, "points3D.bin",
                 ": the error of 3D point 1000: nan is not a finite number.");
}

// Image names become paths below the image and output folders (the gaussian_splatting
// exporter writes images/<name>): absolute names, '..' and control characters are
// refused, naming the file, the image and the name with its control characters escaped.
TEST(ColmapModelIo, UnsafeImageNamesAreRefusedInBothFormats) {
  const std::pair<std::string, std::string> cases[] = {
      {"/tmp/overwritten.jpg",
       "'/tmp/overwritten.jpg' is an absolute path; image names are relative to the image "
       "folder."},
      {"../../outside.jpg",
       "'../../outside.jpg' has a '..' component, which leads out of the image folder."},
      {"sub/../../outside.jpg",
       "'sub/../../outside.jpg' has a '..' component, which leads out of the image folder."},
      {"bell\x07.jpg", "'bell\\x07.jpg' contains the control character \\x07."},
      {"line\nbreak.jpg",
       "'line\\nbreak.jpg' contains a line break, which a COLMAP text model cannot hold."},
  };
  for (const auto& [name, message] : cases) {
    Reconstruction reconstruction = RegisteredOnly(SyntheticReconstruction());
    reconstruction.images.at(2).name = name;
    for (const ColmapModelFormat format : {ColmapModelFormat::kBinary, ColmapModelFormat::kText}) {
      // A line break cannot be written into a text model: the name ends its line there.
      if (format == ColmapModelFormat::kText && name.find('\n') != std::string::npos) continue;
      TemporaryDir dir;
      WriteColmapModel(reconstruction, dir.path(), format);
      const bool binary = format == ColmapModelFormat::kBinary;
      // The text model writes image 1 on lines 5 and 6, image 2 on line 7.
      const std::string where = binary ? (dir.path() / "images.bin").string() + ": image 2"
                                       : (dir.path() / "images.txt").string() + " line 7: image 2";
      try {
        ReadColmapModel(dir.path());
        ADD_FAILURE() << "expected InputError for " << name;
      } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.what()), where + ": the image name " + message);
      }
    }
  }
}

// --- COLMAP's own files -----------------------------------------------------------

class ColmapAnchorTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (!fs::is_directory(AnchorDir(GetParam()))) {
      TESSERA_SKIP_OR_FAIL_IN_CI("COLMAP anchor models not found at "
                                 << AnchorDir(GetParam()) << " (set TESSERA_SHARED_DIR)");
    }
  }
};

TEST_P(ColmapAnchorTest, BinaryRoundTripIsByteExact) {
  const fs::path model_dir = AnchorDir(GetParam()) / "sparse" / "0";
  ColmapModelFileOrder order;
  const Reconstruction reconstruction = ReadColmapModel(model_dir, &order);
  EXPECT_EQ(reconstruction.NumRegisteredImages(), reconstruction.images.size());
  TemporaryDir dir;
  WriteColmapModel(reconstruction, dir.path(), ColmapModelFormat::kBinary, &order);
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string expected = ReadBytes(model_dir / name);
    const std::string written = ReadBytes(dir.path() / name);
    EXPECT_EQ(written.size(), expected.size()) << name;
    EXPECT_TRUE(written == expected) << name << " differs from COLMAP's";
  }
  // Without the file order, records come by ascending id and read back the same.
  TemporaryDir sorted;
  WriteColmapModel(reconstruction, sorted.path(), ColmapModelFormat::kBinary);
  EXPECT_EQ(fs::file_size(sorted.path() / "points3D.bin"),
            fs::file_size(model_dir / "points3D.bin"));
  ExpectEqualReconstructions(reconstruction, ReadColmapModel(sorted.path()));
}

TEST_P(ColmapAnchorTest, TextRoundTripIsByteExact) {
  const fs::path text_dir = AnchorDir(GetParam()) / "sparse-txt";
  ColmapModelFileOrder order;
  const Reconstruction reconstruction = ReadColmapModel(text_dir, &order);
  TemporaryDir dir;
  WriteColmapModel(reconstruction, dir.path(), ColmapModelFormat::kText, &order);
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_TRUE(ReadBytes(dir.path() / name) == ReadBytes(text_dir / name))
        << name << " differs from COLMAP's";
  }
}

// COLMAP's model_converter made sparse-txt from sparse/0: our text writer, given the
// binary model and the text files' record order, must write the very same bytes,
// header statistics included.
TEST_P(ColmapAnchorTest, BinaryToTextMatchesModelConverter) {
  const fs::path text_dir = AnchorDir(GetParam()) / "sparse-txt";
  ColmapModelFileOrder text_order;
  const Reconstruction from_text = ReadColmapModel(text_dir, &text_order);
  const Reconstruction from_binary = ReadColmapModel(AnchorDir(GetParam()) / "sparse" / "0");
  ExpectEqualReconstructions(from_binary, from_text);
  TemporaryDir dir;
  WriteColmapModel(from_binary, dir.path(), ColmapModelFormat::kText, &text_order);
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_TRUE(ReadBytes(dir.path() / name) == ReadBytes(text_dir / name))
        << name << " differs from COLMAP's";
  }
}

INSTANTIATE_TEST_SUITE_P(Anchors, ColmapAnchorTest,
                         ::testing::Values("fountain-P11", "Herz-Jesus-P8"), [](const auto& info) {
                           std::string name = info.param;
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name;
                         });

}  // namespace
}  // namespace tessera
