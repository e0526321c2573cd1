#include "image/image_folder_scan.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "tessera/errors.h"
#include "tessera/io/exif.h"
#include "test_image_files.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using testing::TemporaryDir;

cv::Mat Pattern(int width, int height, int type = CV_8UC3) {
  cv::Mat image(height, width, type);
  cv::randu(image, 0, 255);
  return image;
}

void Write(const fs::path& path, const cv::Mat& image) {
  fs::create_directories(path.parent_path());
  ASSERT_TRUE(cv::imwrite(path.string(), image)) << path;
}

std::vector<std::string> Names(const ImageScan& scan) {
  std::vector<std::string> names;
  for (const auto& image : scan.images) names.push_back(image.name);
  return names;
}

// How many warnings quote `name`.
int CountWarningsNaming(const ImageScan& scan, const std::string& name) {
  return static_cast<int>(
      std::count_if(scan.warnings.begin(), scan.warnings.end(), [&](const std::string& warning) {
        return warning.find("'" + name + "'") != std::string::npos;
      }));
}

TEST(ScanImageFolder, NaturalOrderRecursiveSkipsHiddenAndOtherFiles) {
  TemporaryDir dir;
  for (const char* name : {"img10.png", "img2.png", "img1.png", "IMG3.png", "sub/img5.png",
                           ".hidden.png", ".cache/img0.png"}) {
    Write(dir.path() / name, Pattern(8, 6));
  }
  std::ofstream(dir.path() / "notes.txt") << "not an image";
  const ImageScan scan = ScanImageFolder(dir.path());
  const std::vector<std::string> expected = {"img1.png", "img2.png", "IMG3.png", "img10.png",
                                             "sub/img5.png"};
  EXPECT_EQ(Names(scan), expected);
  EXPECT_TRUE(scan.warnings.empty());
  EXPECT_EQ(scan.images[4].path, fs::absolute(dir.path()) / "sub" / "img5.png");
  // Passed over, but said in one line (issue 46: no log line at all).
  EXPECT_EQ(scan.skipped_folders,
            (std::vector<std::string>{
                "Skipped 1 folder and 1 image file whose names start with '.' ('.cache/', "
                "'.hidden.png'): hidden files and folders are never scanned for images; rename "
                "them to use them."}));
}

TEST(ScanImageFolder, HiddenFoldersDeepDownAreCountedAndTheFirstNamed) {
  TemporaryDir dir;
  Write(dir.path() / "a.png", Pattern(8, 6));
  for (const char* name : {"sub/.thumbs/t.png", ".b/x.png", ".a/y.png", ".c/z.png"}) {
    Write(dir.path() / name, Pattern(8, 6));
  }
  std::ofstream(dir.path() / ".DS_Store") << "not an image, not counted";
  const ImageScan scan = ScanImageFolder(dir.path());
  EXPECT_EQ(Names(scan), (std::vector<std::string>{"a.png"}));
  EXPECT_EQ(scan.skipped_folders,
            (std::vector<std::string>{
                "Skipped 4 folders whose names start with '.' ('.a/', '.b/', '.c/', ...): hidden "
                "files and folders are never scanned for images; rename them to use them."}));
}

TEST(ScanImageFolder, ListsGoodImagesWithSizesAndWarnsOncePerBadFile) {
  TemporaryDir dir;
  Write(dir.path() / "a.jpg", Pattern(64, 48));
  Write(dir.path() / "b.png", Pattern(30, 20));
  Write(dir.path() / "c16.png", Pattern(40, 10, CV_16UC3));
  Write(dir.path() / "d_gray.png", Pattern(12, 34, CV_8UC1));
  Write(dir.path() / "e.tif", Pattern(50, 60));
  Write(dir.path() / "F.JPG", Pattern(20, 30));
  std::vector<unsigned char> progressive;
  cv::imencode(".jpg", Pattern(24, 16), progressive, {cv::IMWRITE_JPEG_PROGRESSIVE, 1});
  testing::WriteBytes(dir.path() / "g_progressive.jpg", progressive);
  std::ofstream(dir.path() / "empty.jpg").close();
  std::ofstream(dir.path() / "text.jpg") << "this is a text file, not a JPEG";
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", Pattern(64, 64), jpeg);
  jpeg.resize(jpeg.size() / 2);
  testing::WriteBytes(dir.path() / "half.jpg", jpeg);
  std::vector<unsigned char> png;
  cv::imencode(".png", Pattern(64, 64), png);
  png.resize(png.size() - 20);
  testing::WriteBytes(dir.path() / "cut.png", png);

  const ImageScan scan = ScanImageFolder(dir.path());
  const std::vector<std::string> expected_names = {
      "a.jpg", "b.png", "c16.png", "d_gray.png", "e.tif", "F.JPG", "g_progressive.jpg"};
  ASSERT_EQ(Names(scan), expected_names);
  const std::vector<std::pair<int, int>> expected_sizes = {{64, 48}, {30, 20}, {40, 10}, {12, 34},
                                                           {50, 60}, {20, 30}, {24, 16}};
  for (size_t i = 0; i < expected_sizes.size(); ++i) {
    EXPECT_EQ(scan.images[i].width, expected_sizes[i].first) << scan.images[i].name;
    EXPECT_EQ(scan.images[i].height, expected_sizes[i].second) << scan.images[i].name;
    EXPECT_EQ(scan.images[i].exif.orientation, 1);
    // Detection gets the size the scan lists.
    const cv::Mat gray = ReadGrayImage(scan.images[i].path);
    EXPECT_EQ(gray.type(), CV_8UC1);
    EXPECT_EQ(gray.size(), cv::Size(scan.images[i].width, scan.images[i].height));
  }
  ASSERT_EQ(scan.warnings.size(), 4u);
  for (const char* bad : {"empty.jpg", "text.jpg", "half.jpg", "cut.png"}) {
    EXPECT_EQ(CountWarningsNaming(scan, bad), 1) << bad;
  }
  // Sorted by name: cut.png, empty.jpg, half.jpg, text.jpg.
  EXPECT_EQ(scan.warnings[0],
            "Skipped 'cut.png': truncated PNG data (the file ends before the IEND chunk).");
  EXPECT_EQ(scan.warnings[1], "Skipped 'empty.jpg': the file is empty.");
  EXPECT_EQ(scan.warnings[2],
            "Skipped 'half.jpg': truncated JPEG data (the file ends before the end-of-image "
            "marker).");
  EXPECT_EQ(scan.warnings[3],
            "Skipped 'text.jpg': not a JPEG, PNG or TIFF image (unrecognised file signature).");
}

TEST(ScanImageFolder, ThrowsNamingAMissingFolder) {
  TemporaryDir dir;
  const fs::path missing = dir.path() / "no-such-folder";
  try {
    ScanImageFolder(missing);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), missing.string() + ": the image folder does not exist");
  }
}

TEST(ReadGrayImage, ThrowsNamingTruncatedOrMissingFiles) {
  TemporaryDir dir;
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", Pattern(64, 64), jpeg);
  jpeg.resize(jpeg.size() / 2);
  const fs::path half = dir.path() / "half.jpg";
  testing::WriteBytes(half, jpeg);
  try {
    ReadGrayImage(half);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              half.string() +
                  ": cannot decode the image: truncated JPEG data (the file ends before the "
                  "end-of-image marker)");
  }
  const fs::path missing = dir.path() / "missing.png";
  try {
    ReadColorImage(missing);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), missing.string() + ": cannot read the image file");
  }
}

TEST(ReadGrayImage, ScalesSixteenBitAndConvertsColour) {
  TemporaryDir dir;
  cv::Mat deep(2, 3, CV_16UC1);
  deep.setTo(0);
  deep.at<uint16_t>(0, 0) = 65535;
  deep.at<uint16_t>(0, 1) = 257 * 100;
  deep.at<uint16_t>(1, 2) = 257 * 7;
  Write(dir.path() / "deep.png", deep);
  const cv::Mat gray = ReadGrayImage(dir.path() / "deep.png");
  ASSERT_EQ(gray.type(), CV_8UC1);
  EXPECT_EQ(gray.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(gray.at<uint8_t>(0, 1), 100);
  EXPECT_EQ(gray.at<uint8_t>(1, 2), 7);
  EXPECT_EQ(gray.at<uint8_t>(1, 0), 0);

  cv::Mat color(1, 2, CV_8UC3, cv::Scalar(0, 0, 0));
  color.at<cv::Vec3b>(0, 0) = {255, 0, 0};  // pure blue: grey 0.114 * 255
  color.at<cv::Vec3b>(0, 1) = {0, 0, 255};  // pure red: grey 0.299 * 255
  Write(dir.path() / "color.png", color);
  const cv::Mat gray_from_color = ReadGrayImage(dir.path() / "color.png");
  EXPECT_EQ(gray_from_color.at<uint8_t>(0, 0), 29);
  EXPECT_EQ(gray_from_color.at<uint8_t>(0, 1), 76);

  cv::Mat single(2, 2, CV_8UC1, cv::Scalar(42));
  Write(dir.path() / "single.png", single);
  const cv::Mat as_color = ReadColorImage(dir.path() / "single.png");
  ASSERT_EQ(as_color.type(), CV_8UC3);
  EXPECT_EQ(as_color.at<cv::Vec3b>(1, 1), cv::Vec3b(42, 42, 42));
}

// Where each orientation puts the stored top-left and top-right corners.
TEST(ApplyExifOrientation, MatchesTheExifDefinitions) {
  // Stored 3 wide, 2 high: 1 at top-left, 2 at top-right, the rest 0.
  cv::Mat stored = cv::Mat::zeros(2, 3, CV_8UC1);
  stored.at<uint8_t>(0, 0) = 1;
  stored.at<uint8_t>(0, 2) = 2;
  struct Expected {
    cv::Point top_left, top_right;  // where the stored corners land (x, y)
  };
  // Displayed size is 3x2 for 1-4 and 2x3 for 5-8.
  const Expected expected[9] = {{},
                                {{0, 0}, {2, 0}},   // 1: as stored
                                {{2, 0}, {0, 0}},   // 2: mirrored left-right
                                {{2, 1}, {0, 1}},   // 3: rotated 180
                                {{0, 1}, {2, 1}},   // 4: mirrored top-bottom
                                {{0, 0}, {0, 2}},   // 5: transposed
                                {{1, 0}, {1, 2}},   // 6: rotated 90 clockwise
                                {{1, 2}, {1, 0}},   // 7: transverse
                                {{0, 2}, {0, 0}}};  // 8: rotated 90 counter-clockwise
  for (int orientation = 1; orientation <= 8; ++orientation) {
    const cv::Mat displayed = ApplyExifOrientation(stored, orientation);
    const bool swapped = OrientationSwapsAxes(orientation);
    ASSERT_EQ(displayed.cols, swapped ? 2 : 3) << orientation;
    EXPECT_EQ(displayed.at<uint8_t>(expected[orientation].top_left), 1) << orientation;
    EXPECT_EQ(displayed.at<uint8_t>(expected[orientation].top_right), 2) << orientation;
  }
}

TEST(ScanImageFolder, AppliesExifOrientationSixToSizeAndPixels) {
  TemporaryDir dir;
  // Stored 64 wide, 48 high, a white 16x16 marker at the stored top-left.
  cv::Mat stored(48, 64, CV_8UC3, cv::Scalar(0, 0, 0));
  stored(cv::Rect(0, 0, 16, 16)).setTo(cv::Scalar(255, 255, 255));
  testing::TestExif tags;
  tags.make = "Test";
  tags.orientation = 6;
  testing::WriteBytes(dir.path() / "rotated.jpg", testing::EncodeJpegWithExif(stored, tags));

  const ImageScan scan = ScanImageFolder(dir.path());
  ASSERT_EQ(scan.images.size(), 1u) << (scan.warnings.empty() ? "" : scan.warnings[0]);
  EXPECT_EQ(scan.images[0].exif.orientation, 6);
  EXPECT_EQ(scan.images[0].exif.make, "Test");
  EXPECT_EQ(scan.images[0].width, 48);
  EXPECT_EQ(scan.images[0].height, 64);

  // Rotated 90 degrees clockwise, the marker sits at the top-right.
  const cv::Mat gray = ReadGrayImage(scan.images[0].path);
  ASSERT_EQ(gray.cols, 48);
  ASSERT_EQ(gray.rows, 64);
  EXPECT_GT(cv::mean(gray(cv::Rect(34, 2, 12, 12)))[0], 230);
  EXPECT_LT(cv::mean(gray(cv::Rect(2, 2, 12, 12)))[0], 25);
  EXPECT_LT(cv::mean(gray(cv::Rect(34, 50, 12, 12)))[0], 25);
  const cv::Mat color = ReadColorImage(scan.images[0].path);
  EXPECT_EQ(color.size(), gray.size());
}

TEST(ScanImageFolder, ListsTiffAtTheSizeItDecodesTo) {
  TemporaryDir dir;
  cv::Mat stored = cv::Mat::zeros(6, 10, CV_8UC1);
  stored.at<uint8_t>(0, 0) = 200;  // stored top-left
  testing::WriteBytes(dir.path() / "turned.tif", testing::EncodeGrayTiff(stored, 8));
  const ImageScan scan = ScanImageFolder(dir.path());
  ASSERT_EQ(scan.images.size(), 1u) << (scan.warnings.empty() ? "" : scan.warnings[0]);
  EXPECT_EQ(scan.images[0].exif.orientation, 1);  // already applied by the decoder
  // libtiff turns the 8-bit image 90 degrees counter-clockwise for Orientation 8: the
  // stored top-left is the bottom-left.
  EXPECT_EQ(scan.images[0].width, 6);
  EXPECT_EQ(scan.images[0].height, 10);
  const cv::Mat gray = ReadGrayImage(scan.images[0].path);
  ASSERT_EQ(gray.size(), cv::Size(6, 10));
  EXPECT_EQ(gray.at<uint8_t>(9, 0), 200);
  EXPECT_EQ(cv::sum(gray)[0], 200);
}

TEST(ReadExifInfo, ReadsTagsWrittenByLibexif) {
  testing::TestExif tags;
  tags.make = "  EASTMAN KODAK COMPANY ";
  tags.model = "KODAK Z612 ZOOM DIGITAL CAMERA";
  tags.focal_length_mm = 5.8;
  tags.focal_length_35mm = 35;
  tags.orientation = 3;
  const std::vector<unsigned char> jpeg = testing::EncodeJpegWithExif(Pattern(16, 16), tags);
  const ExifInfo info = ReadExifInfo(jpeg.data(), jpeg.size());
  EXPECT_EQ(info.make, "EASTMAN KODAK COMPANY");
  EXPECT_EQ(info.model, "KODAK Z612 ZOOM DIGITAL CAMERA");
  EXPECT_DOUBLE_EQ(*info.focal_length_mm, 5.8);
  EXPECT_DOUBLE_EQ(*info.focal_length_35mm, 35);
  EXPECT_EQ(info.orientation, 3);
  EXPECT_FALSE(info.focal_plane_x_resolution.has_value());

  std::vector<unsigned char> plain;
  cv::imencode(".jpg", Pattern(16, 16), plain);
  const ExifInfo none = ReadExifInfo(plain.data(), plain.size());
  EXPECT_TRUE(none.make.empty());
  EXPECT_FALSE(none.focal_length_mm.has_value());
  EXPECT_EQ(none.orientation, 1);
}

TEST(ScanImageFolder, ReadsSceauxCastleHeaders) {
  const fs::path images = testing::SharedDir() / "datasets" / "sceaux-castle" / "images";
  if (!fs::is_directory(images)) TESSERA_SKIP_OR_FAIL_IN_CI(images << " is absent");
  const ImageScan scan = ScanImageFolder(images);
  EXPECT_TRUE(scan.warnings.empty());
  ASSERT_EQ(scan.images.size(), 11u);
  EXPECT_EQ(scan.images.front().name, "100_7100.JPG");
  for (const ImageEntry& image : scan.images) {
    EXPECT_EQ(image.width, 2832) << image.name;
    EXPECT_EQ(image.height, 2128) << image.name;
    EXPECT_EQ(image.exif.make, "EASTMAN KODAK COMPANY");
    EXPECT_EQ(image.exif.model, "KODAK Z612 ZOOM DIGITAL CAMERA");
    EXPECT_DOUBLE_EQ(image.exif.focal_length_mm.value_or(0), 5.85);  // 585/100
    EXPECT_DOUBLE_EQ(image.exif.focal_length_35mm.value_or(0), 35);
    EXPECT_EQ(image.exif.orientation, 1);
  }
}

TEST(ScanImageFolder, LeavesOutTheOutputFolderAndWorkspacesAndSaysSo) {
  TemporaryDir dir;
  Write(dir.path() / "a.png", Pattern(32, 24));
  Write(dir.path() / "out" / "gaussian_splatting" / "images" / "a.png", Pattern(32, 24));
  Write(dir.path() / "old" / "sparse" / "b.png", Pattern(32, 24));
  std::ofstream(dir.path() / "old" / "database.db") << "";
  Write(dir.path() / "sub" / "c.png", Pattern(32, 24));
  ImageScanOptions options;
  options.excluded_folders = {dir.path() / "out"};
  ImageScan scan = ScanImageFolder(dir.path(), options);
  EXPECT_EQ(Names(scan), (std::vector<std::string>{"a.png", "sub/c.png"}));
  std::sort(scan.skipped_folders.begin(), scan.skipped_folders.end());  // listing order
  EXPECT_EQ(scan.skipped_folders,
            (std::vector<std::string>{"Skipped the folder 'old': it is a Tessera workspace.",
                                      "Skipped the folder 'out': it is the output folder of this "
                                      "run."}));
  options.excluded_folders = {dir.path()};
  EXPECT_THROW(ScanImageFolder(dir.path(), options), InputError);
}

// Issue 60 item 3: an export put inside the image folder (export --output IMG/out) holds
// no lock and no database, only the outputs ledger: its undistorted copies were read as
// more photos by the next run.
TEST(ScanImageFolder, LeavesOutAFolderHoldingTesserasOutputsAndSaysSo) {
  TemporaryDir dir;
  Write(dir.path() / "a.png", Pattern(32, 24));
  Write(dir.path() / "out" / "gaussian_splatting" / "images" / "a.png", Pattern(32, 24));
  std::ofstream(dir.path() / "out" / ".tessera_outputs.json") << "{}";
  Write(dir.path() / "deep" / "er" / "b.png", Pattern(32, 24));
  std::ofstream(dir.path() / "deep" / "er" / ".tessera_outputs.json") << "{}";
  // Not a ledger: a link named like one, in a folder of photos.
  Write(dir.path() / "linked" / "c.png", Pattern(32, 24));
  std::filesystem::create_symlink(dir.path() / "out" / ".tessera_outputs.json",
                                  dir.path() / "linked" / ".tessera_outputs.json");
  ImageScan scan = ScanImageFolder(dir.path());
  EXPECT_EQ(Names(scan), (std::vector<std::string>{"a.png", "linked/c.png"}));
  std::sort(scan.skipped_folders.begin(), scan.skipped_folders.end());  // listing order
  EXPECT_EQ(scan.skipped_folders,
            (std::vector<std::string>{
                "Skipped the folder 'deep/er': it holds Tessera's outputs "
                "(.tessera_outputs.json), which are never read as input.",
                "Skipped the folder 'out': it holds Tessera's outputs (.tessera_outputs.json), "
                "which are never read as input."}));
}

TEST(ScanImageFolder, LeavesOutTheMaskFolder) {
  TemporaryDir dir;
  Write(dir.path() / "a.png", Pattern(32, 24));
  Write(dir.path() / "masks" / "a.png.png", Pattern(32, 24));
  ImageScanOptions options;
  options.mask_folder = dir.path() / "masks";
  const ImageScan scan = ScanImageFolder(dir.path(), options);
  EXPECT_EQ(Names(scan), (std::vector<std::string>{"a.png"}));
  EXPECT_EQ(scan.skipped_folders,
            (std::vector<std::string>{"Skipped the folder 'masks': it is the mask folder of "
                                      "this run."}));
  options.mask_folder = dir.path();
  EXPECT_THROW(ScanImageFolder(dir.path(), options), InputError);
}

TEST(ScanImageFolder, RecordsSizeAndContentHashAndRefusesOversizedOrLineBrokenNames) {
  TemporaryDir dir;
  Write(dir.path() / "a.png", Pattern(40, 30));
  fs::copy_file(dir.path() / "a.png", dir.path() / "b.png");
  Write(dir.path() / "c.png", Pattern(40, 30));
  fs::copy_file(dir.path() / "a.png", dir.path() / "line\nbreak.png");
  // Any control character: the model and database readers refuse such names.
  fs::copy_file(dir.path() / "a.png", dir.path() / "escape\x1b.png");
  Write(dir.path() / "big.png", Pattern(50, 30));
  ImageScanOptions options;
  options.max_image_pixels = 1200;  // 40x30 passes, 50x30 does not
  const ImageScan scan = ScanImageFolder(dir.path(), options);
  ASSERT_EQ(Names(scan), (std::vector<std::string>{"a.png", "b.png", "c.png"}));
  EXPECT_EQ(scan.images[0].file_size, fs::file_size(dir.path() / "a.png"));
  EXPECT_EQ(scan.images[0].content_hash.size(), 32u);
  EXPECT_EQ(scan.images[0].content_hash, scan.images[1].content_hash);  // same bytes
  EXPECT_NE(scan.images[0].content_hash, scan.images[2].content_hash);
  ASSERT_EQ(scan.warnings.size(), 3u);
  EXPECT_EQ(scan.warnings[0],
            "Skipped 'big.png': 50x30 pixels is over the limit of 1200 (max_image_pixels).");
  EXPECT_EQ(scan.warnings[1],
            "Skipped 'escape\\x1b.png': the name contains the control character \\x1b.");
  EXPECT_EQ(scan.warnings[2],
            "Skipped 'line\\nbreak.png': the name contains a line break, which a COLMAP text "
            "model cannot hold.");
}

// Every entry named like an image that the scan does not use is named with why, in name
// order, and counted; the FIFOs and the device are never opened, so the scan returns
// (a scan that opened pipe.jpg would wait for a writer until the CTest TIMEOUT).
TEST(ScanImageFolder, NamesEveryEntryItDoesNotUseAndOpensNoFifoOrDevice) {
  TemporaryDir dir, outside;
  Write(dir.path() / "good.png", Pattern(8, 6));
  Write(dir.path() / "folder.jpg" / "inner.png", Pattern(8, 6));
  fs::create_symlink("missing.jpg", dir.path() / "dangling.jpg");
  ASSERT_EQ(mkfifo((dir.path() / "pipe.jpg").c_str(), 0644), 0) << std::strerror(errno);
  fs::create_symlink("/dev/null", dir.path() / "null.jpg");
  ASSERT_EQ(mkfifo((outside.path() / "fifo").c_str(), 0644), 0) << std::strerror(errno);
  fs::create_symlink(outside.path() / "fifo", dir.path() / "outside_pipe.png");
  Write(outside.path() / "more" / "photo.png", Pattern(8, 6));
  fs::create_symlink(outside.path() / "more", dir.path() / "linked_folder");
  fs::create_symlink(outside.path() / "more" / "photo.png", dir.path() / "linked_photo.png");
  const fs::path socket_path = dir.path() / "sock.tif";
  const int socket_fd = socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(socket_fd, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  ASSERT_LT(socket_path.string().size(), sizeof(address.sun_path));
  std::strncpy(address.sun_path, socket_path.c_str(), sizeof(address.sun_path) - 1);
  ASSERT_EQ(bind(socket_fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0)
      << std::strerror(errno);

  const ImageScan scan = ScanImageFolder(dir.path());
  close(socket_fd);
  EXPECT_EQ(Names(scan),
            (std::vector<std::string>{"folder.jpg/inner.png", "good.png", "linked_photo.png"}));
  const std::string fifo = (outside.path() / "fifo").string();
  const std::string more = (outside.path() / "more").string();
  EXPECT_EQ(scan.warnings,
            (std::vector<std::string>{
                "Skipped 'dangling.jpg': it is a symbolic link to 'missing.jpg', which does not "
                "exist.",
                "Skipped 'folder.jpg': it is a folder, not an image file (its contents are "
                "scanned as a sub-folder).",
                "Skipped 'linked_folder': it is a symbolic link to '" + more +
                    "', a folder; the scan does not follow links to folders.",
                "Skipped 'null.jpg': it is a symbolic link to '/dev/null', which is a device, not "
                "an image file; it was not opened.",
                "Skipped 'outside_pipe.png': it is a symbolic link to '" + fifo +
                    "', which is a named pipe (FIFO), not an image file; it was not opened.",
                "Skipped 'pipe.jpg': it is a named pipe (FIFO), not an image file; it was not "
                "opened.",
                "Skipped 'sock.tif': it is a socket, not an image file; it was not opened."}));
  EXPECT_TRUE(scan.skipped_folders.empty());
}

// Whether this process may run a child as the user nobody (root reads every file, so an
// unreadable file can be tested as root only from a child without root's rights).
bool ChildCanBecomeNobody() {
  const pid_t pid = fork();
  if (pid == 0) _exit(setgid(65534) == 0 && setuid(65534) == 0 ? 0 : 1);
  int status = 0;
  return pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) &&
         WEXITSTATUS(status) == 0;
}

// A file and a folder the scan cannot open are named with the system's reason. As root
// the scan runs in a child process as the user nobody, for whom they are unreadable.
TEST(ScanImageFolder, NamesAFileItCannotReadAndAFolderItCannotList) {
  const bool root = geteuid() == 0;
  if (root && !ChildCanBecomeNobody()) {
    GTEST_SKIP() << "running as root and a child cannot become the user nobody: no user here "
                    "is refused a file";
  }
  TemporaryDir dir;
  fs::permissions(dir.path(), fs::perms::all);  // nobody lists it
  Write(dir.path() / "a.png", Pattern(8, 6));
  Write(dir.path() / "locked.png", Pattern(8, 6));
  Write(dir.path() / "closed" / "b.png", Pattern(8, 6));
  fs::permissions(dir.path() / "locked.png", fs::perms::none);
  fs::permissions(dir.path() / "closed", fs::perms::none);
  EXPECT_EXIT(
      {
        if (root && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(3);
        const ImageScan scan = ScanImageFolder(dir.path());
        for (const std::string& warning : scan.warnings)
          std::fprintf(stderr, "%s\n", warning.c_str());
        _exit(Names(scan) == std::vector<std::string>{"a.png"} ? 0 : 1);
      },
      ::testing::ExitedWithCode(0),
      "^Skipped 'closed': it is a folder that cannot be listed \\(Permission denied\\)\\.\n"
      "Skipped 'locked.png': the file cannot be read \\(Permission denied\\)\\.\n$");
  fs::permissions(dir.path() / "closed", fs::perms::owner_all);  // for the clean-up
}

}  // namespace
}  // namespace tessera
