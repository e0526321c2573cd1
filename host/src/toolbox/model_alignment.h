#pragma once

// `align`: a model moved by a similarity onto another model (over the images they share
// by name), onto its images' GPS tags (east-north-up metres, as the mappers anchor
// models), or upright (the cameras' mean up direction on +Z, the ground plane at z = 0).
// Shared by the CLI verb and the Python module; each writes the moved model and
// alignment.json, which ReadAlignmentFile reads back (eval --alignment).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/similarity_transform.h"
#include "tessera/georeference.h"
#include "tessera/image_metadata.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/gps_anchoring.h"

namespace tessera {

// The file beside an aligned model that says how it was moved.
constexpr const char* kAlignmentFileName = "alignment.json";

struct Alignment {
  std::string method;         // "reference", "gps" or "upright"
  Similarity3d new_from_old;  // x_new = scale * rotation * x_model + translation
  // The correspondences the similarity rests on: image names (reference, gps) or, for
  // upright, the ground plane's points.
  size_t num_inliers = 0;
  std::vector<std::string> inlier_names;
  std::vector<point3D_t> inlier_point_ids;
  // The inliers' residuals after the move: camera centres' distances to their targets
  // (reference: in its units; gps: metres), or (upright) the angles of the cameras' up
  // directions from +Z, degrees.
  std::string residual_unit;
  double residual_mean = 0;
  double residual_max = 0;
  // What the method adds (the reference's shared images, the GPS origin and the tags
  // set aside, the ground plane), written into alignment.json as it is.
  nlohmann::json details = nlohmann::json::object();
  std::optional<Georeference> georeference;  // gps: the frame's origin

  nlohmann::json ToJson() const;
};

struct ReferenceAlignmentOptions {
  // An inlier's moved centre lies within this distance of the reference's, in the
  // reference's units; 0: 5% of the median distance of the reference's shared centres
  // from their median.
  double max_error = 0;
  uint64_t seed = 0;
};

// The similarity mapping `model` onto `reference` by LO-RANSAC on the camera centres of
// the registered images they share by name (geometry/similarity_estimator.h), refitted
// on its inliers. Throws InputError naming both (`model_name`, `reference_name`) when
// they share fewer than 3 images or the shared centres lie on a line.
Alignment AlignToReference(const Reconstruction& model, const Reconstruction& reference,
                           const std::string& model_name, const std::string& reference_name,
                           const ReferenceAlignmentOptions& options = {});

// The similarity into east-north-up metres about the median of the agreeing tags, with
// the mappers' outlier handling (tessera/sfm/gps_similarity.h). Throws InputError with
// the reason when the tags cannot anchor the model.
Alignment AlignToGps(const Reconstruction& model, const std::map<image_t, ImageMetadata>& metadata,
                     const std::string& model_name,
                     const GpsAnchoringOptions& options = GpsAnchoringOptions(), uint64_t seed = 0);

struct UprightOptions {
  // The ground plane's normal lies within this angle of the cameras' mean up direction.
  double max_plane_tilt_deg = 30;
  // A point within this distance of the plane supports it; 0: 1% of the median distance
  // of the points from their median.
  double plane_max_error = 0;
  // The plane needs this share of the points.
  double min_plane_inlier_ratio = 0.1;
  uint64_t seed = 0;
};

// The rotation putting the cameras' mean up direction (-y of each camera, in the world)
// on +Z, then, where a plane holds enough of the points with a normal near +Z, the
// rotation and translation putting it at z = 0 with +Z its normal. Throws InputError when
// the cameras' up directions cancel out.
Alignment AlignUpright(const Reconstruction& model, const std::string& model_name,
                       const UprightOptions& options = {});

// Reads alignment.json (as Alignment::ToJson writes it) into its similarity. Throws
// InputError naming the file and field.
Similarity3d ReadAlignmentFile(const std::filesystem::path& file);

struct AlignArguments {
  std::filesystem::path model;
  std::filesystem::path output;
  std::filesystem::path reference;  // --reference
  bool gps = false;                 // --gps
  std::filesystem::path images;     // with gps: the images' folder (empty: as recorded)
  // With gps: the tags' standard deviations, metres (the mappers' gps_horizontal_sigma
  // and gps_vertical_sigma); centres within 5 of them agree with the similarity.
  double gps_horizontal_sigma = GpsAnchoringOptions().horizontal_sigma_m;
  double gps_vertical_sigma = GpsAnchoringOptions().vertical_sigma_m;
  bool upright = false;  // --upright
};

struct AlignSummary {
  Alignment alignment;
  std::string format;  // "text" or "binary", as read and written
  size_t num_images = 0;
  size_t num_points3D = 0;
  double seconds = 0;

  nlohmann::json ToJson() const;
};

// Reads the model (and the reference, or the images' EXIF), aligns it and writes the
// moved model, alignment.json and (gps) georeference.json into `output` through the
// outputs transaction, holding the workspaces involved. Throws InputError naming the
// file or option.
AlignSummary AlignModel(const AlignArguments& arguments);

}  // namespace tessera
