#pragma once

// The mapper kind: from verified image pairs to models of cameras, poses and 3D points.
// The bundled mappers are `incremental` (after COLMAP's) and `global` (after GLOMAP);
// both are built from the building blocks of Tessera::sfm (tessera/sfm/), which a
// third party's mapper may use too.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/camera_rig.h"
#include "tessera/feature_reader.h"
#include "tessera/features.h"
#include "tessera/georeference.h"
#include "tessera/image_metadata.h"
#include "tessera/plugin.h"
#include "tessera/position_prior.h"
#include "tessera/reconstruction.h"
#include "tessera/two_view_geometry.h"

namespace tessera {

// What a mapper starts from: every camera, every image with its keypoints in points2D
// (poses unknown, `registered` false), what the images' EXIF says, the rigs, and the
// verified geometry of each image pair.
struct MapperInput {
  std::map<camera_t, Camera> cameras;
  std::map<image_t, Image> images;
  // EXIF of each image that had any: GPS, capture time, focal length.
  std::map<image_t, ImageMetadata> metadata;
  std::vector<CameraRig> rigs;
  struct Pair {
    image_t image_id1 = kInvalidImageId;
    image_t image_id2 = kInvalidImageId;
    TwoViewGeometry geometry;  // inlier_matches index image_id1's then image_id2's keypoints
  };
  std::vector<Pair> pairs;
};

// What the mapper found out about a camera's focal length before mapping.
struct FocalLengthReport {
  camera_t camera_id = kInvalidCameraId;
  double initial = 0;    // px, the default the camera came with
  double estimated = 0;  // px, what mapping started from
  // How: "view graph" (from the pairs' fundamental matrices), "first model" (refined by
  // bundle adjustment in a first mapping pass).
  std::string method;
  size_t num_pairs = 0;   // pairs that took part in the view-graph estimate
  size_t num_images = 0;  // images of the first model
};

// How a model agrees with the view graph: its verified pairs whose relative rotation is
// the model's within a tolerance, their share of the pairs' inliers, and the images
// most of whose pairs' inliers disagree (tessera/sfm/view_graph.h computes it).
struct ModelSelfCheck {
  size_t num_pairs = 0;
  size_t num_agreeing = 0;
  double agreement = 1;  // share of the pairs' inliers in agreeing pairs
  std::vector<image_t> disagreeing_images;
  // The model may be folded by symmetric structure.
  bool possibly_folded = false;
};

struct MapperResult {
  // Largest first (most registered images, then most points). Each holds only its
  // registered images, their cameras and its points (tracks and errors set, points2D
  // linked to them).
  std::vector<Reconstruction> models;
  // One per model, in the same order.
  std::vector<ModelSelfCheck> self_checks;
  // Empty, or one per model: the WGS84 origin of the local east-north-up frame (metres)
  // of a model anchored to its images' GPS; nullopt for a model in an arbitrary frame.
  std::vector<std::optional<Georeference>> georeferences;
  // Focal lengths estimated for cameras without a prior.
  std::vector<FocalLengthReport> focal_lengths;
  // Pairs dropped by view-graph filtering, of those verified.
  size_t num_pairs_dropped = 0;
  // Registrations refused because they disagreed with the view graph.
  size_t num_registrations_refused = 0;
  // One line per merge of two models, and per pair of models tried and not merged.
  std::vector<std::string> merges;
  // Why each image that is in no model was left out.
  std::map<image_t, std::string> unregistered_reasons;
  size_t num_tracks = 0;
  size_t num_refused_matches = 0;
  int num_global_ba = 0;
  int num_local_ba = 0;
  double seconds = 0;
  // Mapper-specific figures for the mapping summary (a JSON object).
  nlohmann::json details = nlohmann::json::object();
  // Stopped by MapperControl::should_stop: `models` and the reports are empty.
  bool cancelled = false;
};

// What the host watches and controls while a mapper runs. Every member may be empty;
// all are called on the thread that called Map.
struct MapperControl {
  // Polled often (before each registration, between steps, from solver iterations);
  // true: return soon, with `cancelled` set. The same command resumes the run.
  std::function<bool()> should_stop;
  // The model being built, whenever it changed visibly (an image registered, a
  // global step done), with its index among the models of this run.
  std::function<void(size_t model_index, const Reconstruction& model)> on_model_changed;
  // Progress of a step ("rotation averaging", "registration", ...): done of total.
  std::function<void(const std::string& step, size_t done, size_t total)> on_progress;
};

// Everything a mapper gets besides its input.
struct MapperContext {
  // The pipeline's bundle adjuster plugin; valid during Map.
  const BundleAdjuster* bundle_adjuster = nullptr;
  // The workspace's features (affine shapes, descriptors), index k being the k-th image
  // of MapperInput::images; valid during Map.
  const FeatureReader* features = nullptr;
  // Seeds every random choice: the same input and seed give the same models.
  uint64_t seed = 0;
  int num_threads = 1;
  MapperControl control;
};

// Builds models from verified pairs.
//
// The contract in short (the full one: PREFIX/share/doc/tessera/plugins/mapper.md):
// - Map is called once per map stage, on one thread. It returns every model it built,
//   largest first, and a reason for every image in none.
// - Refine through context.bundle_adjuster only; it throws when the adjuster crashed
//   twice on one problem: let it through.
// - Poll context.control.should_stop; when it says true, return a result with
//   `cancelled` set soon (within a second).
// - Bad options throw OptionError from the constructor, naming the option.
// - No edge in the view graph, or no pair of images that initialises: no model, with
//   the reasons; never throw for it.
// - Log with log(), never to stdout or stderr; never call exit().
class TESSERA_API Mapper : public Plugin {
 public:
  virtual MapperResult Map(const MapperInput& input, const MapperContext& context) const = 0;
};

}  // namespace tessera
