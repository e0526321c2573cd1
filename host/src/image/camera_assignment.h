#pragma once

// Initial intrinsics of the images: known calibration, EXIF focal length priors or a
// default, and the grouping of images into cameras.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "image/camera_settings.h"
#include "image/image_entry.h"
#include "tessera/camera.h"
#include "tessera/reconstruction.h"

namespace tessera {

// A focal length is believed only if it gives a field of view, across the longer
// image side, in this range (degrees). 1 degree is a 2000 mm lens on a full-frame
// sensor; 150 degrees covers action cameras and fisheye lenses, whose perspective
// focal length is meaningless anyway. A 35 mm equivalent of 1 mm (173 degrees), as
// some action cameras write, falls outside.
constexpr double kMinPlausibleFieldOfViewDeg = 1;
constexpr double kMaxPlausibleFieldOfViewDeg = 150;

// The field of view, in degrees, that `focal_px` gives across `longer_side_px`.
double FieldOfViewDeg(double focal_px, double longer_side_px);

// Whether `focal_px` gives a field of view across `longer_side_px` in
// [kMinPlausibleFieldOfViewDeg, kMaxPlausibleFieldOfViewDeg] (about 0.13 to 57 times the
// longer side): EXIF priors, and the focal lengths Tessera reads back from its own files
// (clusters.json), are believed only then.
bool IsPlausibleFocalLength(double focal_px, double longer_side_px);

// The folder of an image, relative to the image folder ("a/b" for "a/b/c.jpg"); empty
// for an image at the top level.
std::string ImageFolder(const std::string& image_name);

// A camera for messages: "camera 1 (SIMPLE_RADIAL 640x480, focal 768.0 px, default)".
std::string DescribeCamera(const Camera& camera);

struct FocalLengthPrior {
  double focal_px;
  CalibrationSource source;
};

// Focal length in pixels from EXIF, in this order of trust:
//  1. FocalLength (mm) / sensor width (mm) x longer side (px), with the sensor width
//     from the built-in database (sensor_database.h) by make and model;
//  2. FocalLength (mm) x FocalPlaneXResolution (px/mm), rescaled when the image is
//     smaller than the PixelXDimension/PixelYDimension the resolution refers to;
//  3. FocalLengthIn35mmFilm: the 35 mm frame's diagonal (43.27 mm) maps to the image's
//     diagonal, which is f35 / 36 x longer side for a 3:2 image and closer to the
//     truth than that for 4:3 compacts and phones.
// nullopt if none is usable. A value that is not positive, or that gives a field of
// view outside [kMinPlausibleFieldOfViewDeg, kMaxPlausibleFieldOfViewDeg], is ignored
// with a warning naming the image appended to `warnings` (may be null).
std::optional<FocalLengthPrior> EstimateFocalLengthPrior(const ImageEntry& image,
                                                         std::vector<std::string>* warnings);

struct CameraAssignment {
  std::vector<Camera> cameras;             // camera ids 1..N
  std::vector<camera_t> image_camera_ids;  // one per input image, in input order
  std::vector<std::string> warnings;
  // Suggestions for the log, never acted upon: a lens whose EXIF says it sees wider than
  // a non-fisheye model describes well (see FisheyeLensHint).
  std::vector<std::string> notes;
};

// EXIF 35 mm equivalent focal lengths below this (a diagonal field of view over 110
// degrees) suggest a fisheye or action-camera lens.
constexpr double kFisheyeHint35mm = 15.0;

// A log line when `settings.model` is not a fisheye model and an image's EXIF 35 mm
// equivalent focal length is below kFisheyeHint35mm, naming the first such image and
// suggesting camera.model OPENCV_FISHEYE; the model is never switched. Empty otherwise.
std::string FisheyeLensHint(const std::vector<ImageEntry>& images, const CameraSettings& settings);

// Makes cameras for the images per CameraSettings:
//  - known intrinsics (fx, fy, cx, cy) win: source kUser, has_prior_focal_length; models
//    with one focal length get (fx + fy) / 2. Throws InputError naming the source when
//    the principal point lies outside an image (a K for another resolution).
//  - else the EXIF prior (has_prior_focal_length);
//  - else default_focal_length_factor x longer side (kDefault, no prior).
// single_camera: one camera per distinct (width, height, make, model) and, with
// per_folder, per folder (ImageFolder), with the median
// of the group's priors (the default when no image of the group has one); otherwise one
// camera per image. Camera ids follow the first image of each camera. The model is
// settings.model; principal point at the image centre (unless known); distortion 0.
// Throws InputError for an unknown model name.
CameraAssignment AssignCameras(const std::vector<ImageEntry>& images,
                               const CameraSettings& settings);

// The folder (ImageFolder) of each camera of `assignment`, made for `images`.
std::map<camera_t, std::string> CameraFolders(const std::vector<ImageEntry>& images,
                                              const CameraAssignment& assignment);

// The folder of each camera of `images` (a workspace's); a camera whose images lie in
// more than one folder is left out.
std::map<camera_t, std::string> CameraFolders(const std::vector<Image>& images);

// The log line of camera.per_folder: "3 cameras by folder (camera.per_folder):
// camera 1 from 'left', camera 2 from 'right', camera 3 from the top level".
std::string DescribeCameraFolders(const std::map<camera_t, std::string>& folders);

}  // namespace tessera
