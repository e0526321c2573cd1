#include "image/camera_assignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "image/image_folder_scan.h"
#include "image/known_intrinsics.h"
#include "image/sensor_database.h"
#include "manifest/manifest.h"
#include "tessera/errors.h"
#include "test_image_files.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

ImageEntry Entry(const std::string& name, int width, int height) {
  ImageEntry entry;
  entry.name = name;
  entry.path = "/images/" + name;
  entry.width = width;
  entry.height = height;
  return entry;
}

ImageEntry With35mm(ImageEntry entry, double focal_35mm) {
  entry.exif.make = "Phone";
  entry.exif.model = "X";
  entry.exif.focal_length_35mm = focal_35mm;
  return entry;
}

TEST(SensorDatabase, FindsEveryEntryByItsOwnNameAndTheKodakZ612) {
  const auto& entries = SensorDatabase();
  EXPECT_GE(entries.size(), 50u);
  EXPECT_LE(entries.size(), 150u);
  for (const SensorEntry& entry : entries) {
    // A duplicate or a shadowing entry would return another entry's width.
    EXPECT_EQ(LookupSensorWidthMm(entry.make, entry.model), entry.width_mm)
        << entry.make << " " << entry.model;
  }
  EXPECT_EQ(LookupSensorWidthMm("EASTMAN KODAK COMPANY", "KODAK Z612 ZOOM DIGITAL CAMERA"), 5.75);
  EXPECT_EQ(LookupSensorWidthMm("NIKON CORPORATION", "NIKON D800"), 35.9);
  EXPECT_EQ(LookupSensorWidthMm(" Canon ", "Canon  EOS 5D Mark III "), 36.0);
  EXPECT_EQ(LookupSensorWidthMm("Canon", "Canon EOS 5D"), 35.8);
  EXPECT_EQ(LookupSensorWidthMm("OLYMPUS IMAGING CORP.", "E-M5"), 17.3);
  EXPECT_EQ(LookupSensorWidthMm("RICOH IMAGING COMPANY, LTD.", "PENTAX K-1"), 35.9);
  EXPECT_EQ(LookupSensorWidthMm("GoPro", "HERO4 Black"), 6.17);
  EXPECT_FALSE(LookupSensorWidthMm("Canon", "EOS 5D Mark").has_value());
  EXPECT_FALSE(LookupSensorWidthMm("SONY", "D800").has_value());
  EXPECT_FALSE(LookupSensorWidthMm("", "").has_value());
}

TEST(EstimateFocalLengthPrior, UsesTheSensorDatabaseInEitherOrientation) {
  for (const auto& [width, height] : {std::pair{2832, 2128}, std::pair{2128, 2832}}) {
    ImageEntry image = Entry("k.jpg", width, height);
    image.exif.make = "EASTMAN KODAK COMPANY";
    image.exif.model = "KODAK Z612 ZOOM DIGITAL CAMERA";
    image.exif.focal_length_mm = 5.8;
    image.exif.focal_length_35mm = 35;
    std::vector<std::string> warnings;
    const auto prior = EstimateFocalLengthPrior(image, &warnings);
    ASSERT_TRUE(prior.has_value());
    EXPECT_NEAR(prior->focal_px, 5.8 / 5.75 * 2832, 1e-9);
    EXPECT_EQ(prior->source, CalibrationSource::kExifFocalLength);
    EXPECT_TRUE(warnings.empty());
  }
}

TEST(EstimateFocalLengthPrior, UsesFocalPlaneResolutionScaledToTheImage) {
  ImageEntry image = Entry("fp.jpg", 2000, 1500);
  image.exif.make = "Unknown maker";
  image.exif.model = "Unknown model";
  image.exif.focal_length_mm = 10;
  image.exif.focal_plane_x_resolution = 200;  // px per mm at 4000 x 3000
  image.exif.pixel_x_dimension = 4000;
  image.exif.pixel_y_dimension = 3000;
  image.exif.focal_length_35mm = 50;  // less trusted: not used
  const auto prior = EstimateFocalLengthPrior(image, nullptr);
  ASSERT_TRUE(prior.has_value());
  EXPECT_NEAR(prior->focal_px, 10 * 200 * 0.5, 1e-9);
  EXPECT_EQ(prior->source, CalibrationSource::kExifFocalLength);
}

TEST(EstimateFocalLengthPrior, Uses35mmEquivalentOverTheDiagonal) {
  // 3:2: the diagonal rule equals f35 / 36 x longer side.
  auto prior = EstimateFocalLengthPrior(With35mm(Entry("a.jpg", 3000, 2000), 28), nullptr);
  ASSERT_TRUE(prior.has_value());
  EXPECT_NEAR(prior->focal_px, 28.0 / 36 * 3000, 1e-9);
  EXPECT_EQ(prior->source, CalibrationSource::kExif35mmEquivalent);
  // 4:3: the longer side covers 34.6 mm of the 35 mm frame's diagonal-equivalent.
  prior = EstimateFocalLengthPrior(With35mm(Entry("b.jpg", 4000, 3000), 28), nullptr);
  ASSERT_TRUE(prior.has_value());
  EXPECT_NEAR(prior->focal_px, 28 * 5000 / std::hypot(36, 24), 1e-9);
}

TEST(EstimateFocalLengthPrior, IgnoresImplausibleValuesWithWarnings) {
  ImageEntry image = Entry("action.jpg", 4000, 3000);
  image.exif.focal_length_mm = 0;
  image.exif.focal_length_35mm = 1;
  std::vector<std::string> warnings;
  EXPECT_FALSE(EstimateFocalLengthPrior(image, &warnings).has_value());
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0], "Image 'action.jpg': EXIF FocalLength of 0 mm is not positive; ignored.");
  EXPECT_EQ(warnings[1],
            "Image 'action.jpg': the focal length from FocalLengthIn35mmFilm 1 mm (115.6 px) "
            "gives a field of view of 173.4 degrees, outside [1, 150]; ignored.");

  // A database focal length that is absurdly long falls through to the 35 mm value.
  ImageEntry tele = Entry("tele.jpg", 2832, 2128);
  tele.exif.make = "Kodak";
  tele.exif.model = "Z612";
  tele.exif.focal_length_mm = 5000;
  tele.exif.focal_length_35mm = 35;
  warnings.clear();
  const auto prior = EstimateFocalLengthPrior(tele, &warnings);
  ASSERT_TRUE(prior.has_value());
  EXPECT_EQ(prior->source, CalibrationSource::kExif35mmEquivalent);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("Image 'tele.jpg': "), std::string::npos);
  EXPECT_NE(warnings[0].find("outside [1, 150]"), std::string::npos);

  // No EXIF at all: nothing to warn about.
  warnings.clear();
  EXPECT_FALSE(EstimateFocalLengthPrior(Entry("plain.png", 100, 80), &warnings).has_value());
  EXPECT_TRUE(warnings.empty());
}

TEST(AssignCameras, ImplausibleExifInAFileFallsBackToTheDefault) {
  testing::TemporaryDir dir;
  testing::TestExif tags;
  tags.make = "Action";
  tags.model = "Cam";
  tags.focal_length_mm = 0;
  tags.focal_length_35mm = 1;
  const cv::Mat pixels(30, 40, CV_8UC3, cv::Scalar(10, 20, 30));
  testing::WriteBytes(dir.path() / "action.jpg", testing::EncodeJpegWithExif(pixels, tags));
  const ImageScan scan = ScanImageFolder(dir.path());
  ASSERT_EQ(scan.images.size(), 1u);
  ASSERT_EQ(scan.images[0].exif.focal_length_mm, 0.0);
  ASSERT_EQ(scan.images[0].exif.focal_length_35mm, 1.0);

  const CameraAssignment assignment = AssignCameras(scan.images, CameraSettings());
  ASSERT_EQ(assignment.cameras.size(), 1u);
  const Camera& camera = assignment.cameras[0];
  EXPECT_DOUBLE_EQ(camera.FocalLengthX(), 1.2 * 40);
  EXPECT_EQ(camera.calibration_source, CalibrationSource::kDefault);
  EXPECT_FALSE(camera.has_prior_focal_length);
  ASSERT_EQ(assignment.warnings.size(), 2u);
  for (const auto& warning : assignment.warnings) {
    EXPECT_EQ(warning.rfind("Image 'action.jpg': ", 0), 0u) << warning;
  }
}

TEST(AssignCameras, SingleCameraGroupsBySizeAndMakeWithTheMedianPrior) {
  const std::vector<ImageEntry> images = {
      With35mm(Entry("0.jpg", 3000, 2000), 36),  // 3000 px
      With35mm(Entry("1.jpg", 3000, 2000), 24),  // 2000 px
      Entry("2.jpg", 3000, 2000),                // no EXIF: another make and model
      With35mm(Entry("3.jpg", 2000, 3000), 30),  // portrait: another size
      With35mm(Entry("4.jpg", 3000, 2000), 30),  // 2500 px
      Entry("5.jpg", 3000, 2000),
  };
  CameraSettings settings;  // SIMPLE_RADIAL, single camera
  const CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.cameras.size(), 3u);
  const std::vector<camera_t> expected_ids = {1, 1, 2, 3, 1, 2};
  EXPECT_EQ(assignment.image_camera_ids, expected_ids);
  EXPECT_TRUE(assignment.warnings.empty());

  const Camera& phone = assignment.cameras[0];
  EXPECT_EQ(phone.camera_id, 1u);
  EXPECT_EQ(phone.ModelName(), "SIMPLE_RADIAL");
  const std::vector<double> expected_params = {2500, 1500, 1000, 0};
  EXPECT_EQ(phone.params, expected_params);
  EXPECT_TRUE(phone.has_prior_focal_length);
  EXPECT_EQ(phone.calibration_source, CalibrationSource::kExif35mmEquivalent);
  EXPECT_EQ(phone.width, 3000u);
  EXPECT_EQ(phone.height, 2000u);

  const Camera& plain = assignment.cameras[1];
  EXPECT_DOUBLE_EQ(plain.FocalLengthX(), 1.2 * 3000);
  EXPECT_FALSE(plain.has_prior_focal_length);
  EXPECT_EQ(plain.calibration_source, CalibrationSource::kDefault);

  const Camera& portrait = assignment.cameras[2];
  EXPECT_EQ(portrait.width, 2000u);
  EXPECT_EQ(portrait.height, 3000u);
  EXPECT_NEAR(portrait.FocalLengthX(), 30.0 / 36 * 3000, 1e-9);
  EXPECT_DOUBLE_EQ(portrait.PrincipalPointX(), 1000);
  EXPECT_DOUBLE_EQ(portrait.PrincipalPointY(), 1500);

  // An even count takes the mean of the two middle priors.
  const CameraAssignment two = AssignCameras(
      {With35mm(Entry("a.jpg", 3000, 2000), 24), With35mm(Entry("b.jpg", 3000, 2000), 36)},
      settings);
  ASSERT_EQ(two.cameras.size(), 1u);
  EXPECT_DOUBLE_EQ(two.cameras[0].FocalLengthX(), 2500);
}

TEST(AssignCameras, OneCameraPerImageWhenNotSingle) {
  CameraSettings settings;
  settings.single_camera = false;
  settings.model = "PINHOLE";
  settings.default_focal_length_factor = 0.8;
  const std::vector<ImageEntry> images = {With35mm(Entry("a.jpg", 3000, 2000), 36),
                                          With35mm(Entry("b.jpg", 3000, 2000), 36),
                                          Entry("c.png", 640, 480)};
  const CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.cameras.size(), 3u);
  const std::vector<camera_t> expected_ids = {1, 2, 3};
  EXPECT_EQ(assignment.image_camera_ids, expected_ids);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(assignment.cameras[i].camera_id, i + 1);
  const std::vector<double> expected_a = {3000, 3000, 1500, 1000};
  EXPECT_EQ(assignment.cameras[0].params, expected_a);
  const std::vector<double> expected_c = {0.8 * 640, 0.8 * 640, 320, 240};
  EXPECT_EQ(assignment.cameras[2].params, expected_c);
  EXPECT_FALSE(assignment.cameras[2].has_prior_focal_length);
}

TEST(AssignCameras, PerFolderGivesEachFolderItsOwnCameraWithItsOwnPrior) {
  CameraSettings settings;
  settings.per_folder = true;
  // Two folders of same-size images of one make and model, interleaved; without
  // per_folder they would share one camera.
  const std::vector<ImageEntry> images = {
      With35mm(Entry("left/0.jpg", 3000, 2000), 36),   // 3000 px
      With35mm(Entry("right/0.jpg", 3000, 2000), 24),  // 2000 px
      With35mm(Entry("left/1.jpg", 3000, 2000), 36),
      With35mm(Entry("right/1.jpg", 3000, 2000), 24)};
  const CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.cameras.size(), 2u);
  const std::vector<camera_t> expected_ids = {1, 2, 1, 2};
  EXPECT_EQ(assignment.image_camera_ids, expected_ids);
  EXPECT_DOUBLE_EQ(assignment.cameras[0].FocalLengthX(), 3000);
  EXPECT_DOUBLE_EQ(assignment.cameras[1].FocalLengthX(), 2000);

  settings.per_folder = false;
  EXPECT_EQ(AssignCameras(images, settings).cameras.size(), 1u);
  // single_camera false: one camera per image, per_folder or not.
  settings.single_camera = false;
  settings.per_folder = true;
  EXPECT_EQ(AssignCameras(images, settings).cameras.size(), 4u);
}

TEST(AssignCameras, PerFolderKeepsTopLevelImagesApartAndGroupsBySizeWithinAFolder) {
  CameraSettings settings;
  settings.per_folder = true;
  const std::vector<ImageEntry> images = {
      Entry("top.jpg", 640, 480),      Entry("a/b/small.jpg", 320, 240),
      Entry("a/big.jpg", 640, 480),    Entry("a/b/big.jpg", 640, 480),
      Entry("a/b/big2.jpg", 640, 480), Entry("top2.jpg", 640, 480)};
  const CameraAssignment assignment = AssignCameras(images, settings);
  // The top level, "a/b" at two sizes, "a": a subfolder is a folder of its own.
  ASSERT_EQ(assignment.cameras.size(), 4u);
  const std::vector<camera_t> expected_ids = {1, 2, 3, 4, 4, 1};
  EXPECT_EQ(assignment.image_camera_ids, expected_ids);
  EXPECT_EQ(assignment.cameras[1].width, 320);
  EXPECT_EQ(assignment.cameras[3].width, 640);
  EXPECT_EQ(ImageFolder("a/b/c.jpg"), "a/b");
  EXPECT_EQ(ImageFolder("c.jpg"), "");
  EXPECT_EQ(DescribeCameraFolders(CameraFolders(images, assignment)),
            "4 cameras by folder (camera.per_folder): camera 1 from the top level, camera 2 "
            "from 'a/b', camera 3 from 'a', camera 4 from 'a/b'");
  // A workspace's camera shared by two folders is no folder's.
  std::vector<Image> workspace(3);
  workspace[0].name = "a/x.jpg";
  workspace[0].camera_id = 1;
  workspace[1].name = "b/x.jpg";
  workspace[1].camera_id = 1;
  workspace[2].name = "b/y.jpg";
  workspace[2].camera_id = 2;
  const std::map<camera_t, std::string> expected = {{2, "b"}};
  EXPECT_EQ(CameraFolders(workspace), expected);
}

TEST(AssignCameras, KnownIntrinsicsOverrideExif) {
  CameraSettings settings;
  settings.known_intrinsics = Eigen::Vector4d(2905.88, 2900, 1416, 1064);
  settings.known_intrinsics_source = "K.txt";
  ImageEntry bad_exif = Entry("a.jpg", 2832, 2128);
  bad_exif.exif.focal_length_mm = 0;
  const std::vector<ImageEntry> images = {bad_exif, With35mm(Entry("b.jpg", 2832, 2128), 50)};

  settings.model = "PINHOLE";
  CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.cameras.size(), 1u);  // one camera despite different EXIF makes
  const std::vector<double> expected_pinhole = {2905.88, 2900, 1416, 1064};
  EXPECT_EQ(assignment.cameras[0].params, expected_pinhole);
  EXPECT_EQ(assignment.cameras[0].calibration_source, CalibrationSource::kUser);
  EXPECT_TRUE(assignment.cameras[0].has_prior_focal_length);
  EXPECT_TRUE(assignment.warnings.empty());

  settings.model = "SIMPLE_RADIAL";
  settings.single_camera = false;
  assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.cameras.size(), 2u);
  const std::vector<double> expected_radial = {(2905.88 + 2900) / 2, 1416, 1064, 0};
  EXPECT_EQ(assignment.cameras[1].params, expected_radial);

  // A K for the full-resolution images does not fit a downscaled copy.
  try {
    AssignCameras({Entry("small.jpg", 708, 532)}, settings);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "K.txt: the principal point (1416, 1064) lies outside image 'small.jpg' (708x532); "
              "the intrinsics must be given for the images' resolution");
  }
}

// The sample's 1024 px K on 768 px copies: the principal point 128 px off centre.
TEST(AssignCameras, AKnownPrincipalPointFarFromTheCentreIsNamedInAWarning) {
  CameraSettings settings;
  settings.known_intrinsics = Eigen::Vector4d(919.8, 921.8, 507.1, 335.9);
  settings.known_intrinsics_source = "K.txt";
  CameraAssignment assignment = AssignCameras({Entry("a.jpg", 1024, 683)}, settings);
  EXPECT_TRUE(assignment.warnings.empty());
  assignment = AssignCameras({Entry("a.jpg", 768, 512), Entry("b.jpg", 768, 512)}, settings);
  ASSERT_EQ(assignment.warnings.size(), 1u);
  EXPECT_EQ(assignment.warnings[0],
            "K.txt: the principal point (507.1, 335.9) lies 147 px from the centre of the 2 "
            "images of 768x512 (the first 'a.jpg'), more than 10% of the image size: were the "
            "intrinsics given for another resolution?");
  EXPECT_EQ(assignment.cameras.at(0).calibration_source, CalibrationSource::kUser);
}

// Images of two sizes: K applies to those it fits; the others keep their own camera.
TEST(AssignCameras, AKnownKAppliesToTheImagesItFitsAndNamesTheOthers) {
  CameraSettings settings;
  settings.known_intrinsics = Eigen::Vector4d(919.8, 921.8, 507.1, 335.9);
  settings.known_intrinsics_source = "K.txt";
  const CameraAssignment assignment =
      AssignCameras({Entry("big.jpg", 1024, 683), Entry("small.jpg", 320, 240)}, settings);
  ASSERT_EQ(assignment.cameras.size(), 2u);
  EXPECT_EQ(assignment.cameras[0].calibration_source, CalibrationSource::kUser);
  EXPECT_EQ(assignment.cameras[1].calibration_source, CalibrationSource::kDefault);
  EXPECT_DOUBLE_EQ(assignment.cameras[1].params[1], 160.0);  // its own centre
  ASSERT_EQ(assignment.warnings.size(), 1u);
  EXPECT_EQ(assignment.warnings[0],
            "K.txt: the principal point (507.1, 335.9) lies outside the 320x240 image "
            "'small.jpg'; K is not used there: the EXIF or the default focal length gives "
            "the camera");
}

// A recipe that holds the intrinsics (camera.require_calibration) refuses to guess them:
// no K at all, or an image K does not fit, is an error naming the manifest's field.
TEST(AssignCameras, ARecipeHoldingTheIntrinsicsRefusesImagesWithoutThem) {
  CameraSettings settings;
  settings.model = "PINHOLE";
  settings.calibration_required_by = "calibrated.json: camera.require_calibration";
  const std::vector<ImageEntry> images = {With35mm(Entry("a.jpg", 1024, 683), 50)};
  try {
    AssignCameras(images, settings);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "calibrated.json: camera.require_calibration: this recipe holds the intrinsics, "
              "and none were given: pass --camera-K FILE, or set camera.K, camera.K_file or "
              "camera.params");
  }
  settings.known_intrinsics = Eigen::Vector4d(919.8, 921.8, 507.1, 335.9);
  settings.known_intrinsics_source = "K.txt";
  const CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.cameras.size(), 1u);
  const std::vector<double> expected = {919.8, 921.8, 507.1, 335.9};
  EXPECT_EQ(assignment.cameras[0].params, expected);
  EXPECT_EQ(assignment.cameras[0].calibration_source, CalibrationSource::kUser);
  try {
    AssignCameras({Entry("big.jpg", 1024, 683), Entry("small.jpg", 320, 240)}, settings);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "calibrated.json: camera.require_calibration: this recipe holds the "
              "intrinsics, and those of K.txt do not fit the 320x240 image 'small.jpg' (the "
              "principal point (507.1, 335.9) lies outside): give them for the images' "
              "resolution");
  }
}

// A given K is checked as input (issue 60): what needs no image when it is set, the rest
// when the cameras are made; a recipe that holds the intrinsics refuses what is wrong,
// naming the file, the entry and the images, and any other run warns.
Eigen::Matrix3d MatrixK(double fx, double skew, double cx, double fy, double cy, double k20 = 0,
                        double k21 = 0) {
  Eigen::Matrix3d K;
  K << fx, skew, cx, 0, fy, cy, k20, k21, 1;
  return K;
}

std::string ErrorOfAssign(const std::vector<ImageEntry>& images, const CameraSettings& settings) {
  try {
    AssignCameras(images, settings);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

TEST(KnownIntrinsics, ASkewOrAnAspectRatioOutOfRangeWarnsAndIsRefusedWhenHeld) {
  const std::vector<ImageEntry> images = {Entry("a.jpg", 1024, 683), Entry("b.jpg", 1024, 683)};
  CameraSettings settings;
  SetKnownIntrinsics(MatrixK(919.8, 150, 507.1, 921.8, 335.9), "K.txt", &settings);
  CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.warnings.size(), 1u);
  EXPECT_EQ(assignment.warnings[0],
            "K.txt: K[0][1] (the skew) is 150, not 0: Tessera's camera models have no skew, and "
            "it would be dropped");
  settings.calibration_required_by = "calibrated.json: camera.require_calibration";
  EXPECT_EQ(ErrorOfAssign(images, settings),
            "calibrated.json: camera.require_calibration: this recipe holds the intrinsics, and "
            "those given for the camera of the 2 images of 1024x683 (the first 'a.jpg') are "
            "wrong: K.txt: K[0][1] (the skew) is 150, not 0: Tessera's camera models have no "
            "skew, and it would be dropped");

  CameraSettings tenth;
  SetKnownIntrinsics(MatrixK(2000, 0, 507.1, 200, 335.9), "K.txt", &tenth);
  assignment = AssignCameras(images, tenth);
  ASSERT_EQ(assignment.warnings.size(), 1u);
  EXPECT_EQ(assignment.warnings[0],
            "K.txt: the aspect ratio fy / fx (K[1][1] (fy) / K[0][0] (fx)) is 0.1, outside [0.5, "
            "2]: is one of them mistyped?");
  tenth.calibration_required_by = "calibrated.json: camera.require_calibration";
  EXPECT_NE(ErrorOfAssign(images, tenth).find("are wrong: K.txt: the aspect ratio fy / fx"),
            std::string::npos);
  CameraSettings json_k;
  SetKnownIntrinsics(Eigen::Vector4d(919.8, 3000, 507.1, 335.9), "camera.K", &json_k);
  ASSERT_EQ(json_k.known_intrinsics_problems.size(), 1u);
  EXPECT_EQ(json_k.known_intrinsics_problems[0],
            "camera.K: the aspect ratio fy / fx (fy / fx) is 3.26158, outside [0.5, 2]: is one of "
            "them mistyped?");
}

TEST(KnownIntrinsics, NotACalibrationMatrixIsRefused) {
  CameraSettings settings;
  const auto error_of = [&](const Eigen::Matrix3d& K) {
    try {
      SetKnownIntrinsics(K, "K.txt", &settings);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of(MatrixK(919.8, 0, 507.1, 921.8, 335.9, 5, 7)),
            "K.txt: the bottom row K[2] is '5 7 1', not '0 0 1': not a calibration matrix");
  EXPECT_EQ(error_of(MatrixK(919.8, 0, 0, 921.8, 0, 507.1, 335.9)),
            "K.txt: the bottom row K[2] is '507.1 335.9 1', not '0 0 1': not a calibration "
            "matrix (it looks transposed: cx and cy belong in the last column)");
  EXPECT_EQ(error_of(MatrixK(-919.8, 0, 507.1, 921.8, 335.9)),
            "K.txt: K[0][0] (fx) is -919.8: focal lengths must be positive finite numbers of "
            "pixels");
  EXPECT_EQ(error_of(MatrixK(919.8, 0, 507.1, 921.8, 335.9)), "no error");
  EXPECT_FALSE(settings.known_intrinsics_problems.size());
}

// fx = 1e-9 or 1e12 ran into "no pair of images initialised a model" (exit 3).
TEST(KnownIntrinsics, AFocalLengthNoLensGivesIsRefusedNamingTheCamera) {
  const std::vector<ImageEntry> images = {Entry("a.jpg", 1024, 683)};
  for (const double focal : {1e-9, 1e12}) {
    CameraSettings settings;
    SetKnownIntrinsics(MatrixK(focal, 0, 507.1, focal, 335.9), "K.txt", &settings);
    const std::string error = ErrorOfAssign(images, settings);
    EXPECT_EQ(error.rfind("K.txt: fx = ", 0), 0u) << error;
    EXPECT_NE(error.find(" px is implausible for the camera of the 1024x683 image 'a.jpg': a "
                         "field of view of "),
              std::string::npos)
        << error;
  }
}

// A 1024 px K on 640 px photos: held with only a warning by a recipe that holds it.
TEST(KnownIntrinsics, AKForAnotherResolutionIsRefusedWhenHeld) {
  const std::vector<ImageEntry> images = {Entry("a.jpg", 640, 427), Entry("b.jpg", 640, 427)};
  CameraSettings settings;
  SetKnownIntrinsics(MatrixK(919.8, 0, 507.1, 921.8, 335.9), "K.txt", &settings);
  const CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.warnings.size(), 1u);
  EXPECT_NE(assignment.warnings[0].find("lies 224 px from the centre"), std::string::npos);
  settings.calibration_required_by = "calibrated.json: camera.require_calibration";
  EXPECT_EQ(ErrorOfAssign(images, settings),
            "calibrated.json: camera.require_calibration: this recipe holds the intrinsics, and "
            "those of K.txt do not fit the 2 images of 640x427 (the first 'a.jpg') (the "
            "principal point (507.1, 335.9) lies 224 px from their centre, more than 10% of the "
            "image size): give them for the images' resolution");
}

// Mixed sizes: the 640 px K went to the 1024 px camera too (its point inside the image).
TEST(KnownIntrinsics, OnMixedSizesAKIsGivenOnlyToTheSizeItFits) {
  const std::vector<ImageEntry> images = {Entry("small.jpg", 640, 427),
                                          Entry("big.jpg", 1024, 683)};
  CameraSettings settings;
  SetKnownIntrinsics(MatrixK(574.9, 0, 316.9, 576.1, 209.9), "K640.txt", &settings);
  const CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.cameras.size(), 2u);
  EXPECT_EQ(assignment.cameras[0].calibration_source, CalibrationSource::kUser);
  EXPECT_EQ(assignment.cameras[1].calibration_source, CalibrationSource::kDefault);
  EXPECT_DOUBLE_EQ(assignment.cameras[1].params[1], 512.0);  // its own centre
  ASSERT_EQ(assignment.warnings.size(), 1u);
  EXPECT_EQ(assignment.warnings[0],
            "K640.txt: the principal point (316.9, 209.9) lies 235 px from the centre of the "
            "1024x683 image 'big.jpg', more than 10% of the image size, while K fits images of "
            "another size; K is not used there: the EXIF or the default focal length gives the "
            "camera");
  settings.calibration_required_by = "calibrated.json: camera.require_calibration";
  EXPECT_EQ(ErrorOfAssign(images, settings),
            "calibrated.json: camera.require_calibration: this recipe holds the intrinsics, and "
            "those of K640.txt do not fit the 1024x683 image 'big.jpg' (the principal point "
            "(316.9, 209.9) lies 235 px from their centre, more than 10% of the image size): "
            "give them for the images' resolution");
}

TEST(AssignCameras, RejectsAnUnknownModel) {
  CameraSettings settings;
  settings.model = "FISHEYE";
  try {
    AssignCameras({Entry("a.jpg", 10, 10)}, settings);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "camera.model: unknown camera model 'FISHEYE' (known models: SIMPLE_PINHOLE, "
              "PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE)");
  }
}

TEST(EstimateFocalLengthPrior, SceauxCastleMatchesItsCalibration) {
  const fs::path root = testing::SharedDir() / "datasets" / "sceaux-castle";
  if (!fs::is_directory(root / "images")) TESSERA_SKIP_OR_FAIL_IN_CI(root << " is absent");
  const double focal_truth = ReadCalibrationMatrixFile(root / "K.txt")(0, 0);
  const ImageScan scan = ScanImageFolder(root / "images");
  ASSERT_EQ(scan.images.size(), 11u);
  for (const ImageEntry& image : scan.images) {
    std::vector<std::string> warnings;
    const auto prior = EstimateFocalLengthPrior(image, &warnings);
    ASSERT_TRUE(prior.has_value()) << image.name;
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(prior->source, CalibrationSource::kExifFocalLength);
    EXPECT_LT(std::abs(prior->focal_px / focal_truth - 1), 0.06) << image.name;
  }
  const CameraAssignment assignment = AssignCameras(scan.images, CameraSettings());
  ASSERT_EQ(assignment.cameras.size(), 1u);
  const double focal = assignment.cameras[0].FocalLengthX();
  std::printf("sceaux-castle: EXIF prior %.2f px (sensor database), K.txt %.2f px, %+.2f%%\n",
              focal, focal_truth, 100 * (focal / focal_truth - 1));
  EXPECT_LT(std::abs(focal / focal_truth - 1), 0.06);
}

TEST(AssignCameras, AVeryWideLensSuggestsFisheyeButNeverSwitches) {
  CameraSettings settings;  // SIMPLE_RADIAL
  const std::vector<ImageEntry> images = {With35mm(Entry("a.jpg", 4000, 3000), 26),
                                          With35mm(Entry("b.jpg", 4000, 3000), 12),
                                          With35mm(Entry("c.jpg", 4000, 3000), 14)};
  const CameraAssignment assignment = AssignCameras(images, settings);
  ASSERT_EQ(assignment.notes.size(), 1u);
  EXPECT_EQ(assignment.notes[0],
            "'b.jpg' and 1 other image(s): EXIF FocalLengthIn35mmFilm 12 mm suggests a fisheye "
            "or action-camera lens; camera.model OPENCV_FISHEYE models one (keeping "
            "SIMPLE_RADIAL)");
  for (const Camera& camera : assignment.cameras) {
    EXPECT_EQ(camera.model_id, CameraModelId::kSimpleRadial);
  }
  settings.model = "OPENCV_FISHEYE";
  EXPECT_TRUE(AssignCameras(images, settings).notes.empty());
  EXPECT_EQ(AssignCameras(images, settings).cameras[0].model_id, CameraModelId::kOpenCVFisheye);
  EXPECT_TRUE(FisheyeLensHint({images[0]}, CameraSettings()).empty());
}

}  // namespace
}  // namespace tessera
