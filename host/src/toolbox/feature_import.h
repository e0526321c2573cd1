#pragma once

// `tessera import --features`: keypoints and descriptors made by another program (a
// learned model in Python, COLMAP's feature_importer files) stored in a workspace as
// if a detector had made them, with the images ingested as `extract` ingests them.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "image/camera_settings.h"
#include "image/image_limits.h"
#include "pipeline/match_stage.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/stage_control.h"
#include "pipeline/workspace.h"

namespace tessera {

using DescriptorValues = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// One image's features as given: keypoints (x y, or x y scale orientation, in COLMAP's
// pixel convention: the centre of the top-left pixel is (0.5, 0.5)) and one row of
// descriptor values per keypoint.
struct ImportedFeatures {
  std::string name;    // the image's name, relative to the image folder
  std::string source;  // for messages: "DIR/a.jpg.txt" or "features['a.jpg']"
  // The line of the first keypoint in `source` (a text file: 2); 0 when rows are not
  // lines (arrays), so that messages say "row K".
  size_t first_line = 0;
  FeatureKeypoints keypoints;
  DescriptorValues descriptors;

  // "DIR/a.jpg.txt:7" or "features['a.jpg'] row 5", for keypoint `row`.
  std::string Where(size_t row) const;
};

// COLMAP's feature_importer text format: a first line `N D`, then N lines
// `x y scale orientation d1 ... dD`. Throws InputError naming the file and line for: a
// file that cannot be read, a bad header, a line with another number of values, a value
// that is no number, coordinates, scale or orientation that are not finite, a negative
// scale, a descriptor value that is not finite, fewer than N lines (truncated) or more.
ImportedFeatures ParseFeatureFile(const std::filesystem::path& file, const std::string& name);

// How imported descriptor values are stored in the workspace's uint8 rows, which the
// matchers compare by L2 distance:
//   kBytes      every value of the import is a whole number in [0, 255] (SIFT as COLMAP,
//               VLFeat or OpenCV write it): stored as it is, as COLMAP stores SIFT;
//   kUnitFloat  anything else (learned descriptors): each row is scaled to unit L2
//               length, then stored as round(128 + 256 v) clamped to [0, 255], so that
//               L2 distances are 256 times those of the unit vectors (components
//               beyond +-0.5, rare at 32 dimensions or more, are clipped).
enum class DescriptorEncoding { kBytes, kUnitFloat };
const char* DescriptorEncodingName(DescriptorEncoding encoding);
bool AllBytes(const DescriptorValues& values);
FeatureDescriptors EncodeDescriptors(const DescriptorValues& values, DescriptorEncoding encoding);

// Where the features come from: the images that have some, and each one's features on
// demand (called from several threads; throws InputError for bad input).
struct FeatureSource {
  std::string description;  // "DIR" or "the features given", for messages
  std::vector<std::string> names;
  std::function<ImportedFeatures(const std::string& name)> load;
};
// The files NAME.txt below `folder` (NAME the image's name, as COLMAP names them).
FeatureSource FeatureFolderSource(const std::filesystem::path& folder);
// Features already in memory (Python's numpy arrays).
FeatureSource FeatureMemorySource(std::vector<ImportedFeatures> features);

struct FeatureImportSettings {
  std::filesystem::path image_dir;  // required
  CameraSettings camera;            // the manifest's, with --camera-K
  int64_t max_image_pixels = kDefaultMaxImagePixels;
  // The manifest's matcher and pair selectors: they must take the descriptors' width.
  // Null: not checked.
  const MatchSettings* matching = nullptr;
  int num_threads = 1;
};

// The settings of a run's context: the manifest's camera settings (with --camera-K),
// image limit and threads; `matching` (the context's MakeMatchSettings, which must
// outlive the result) for the width check. `images`: the image folder, or empty for the
// one the workspace records (InputError when it records none). The folder must lie
// apart from the workspace (CheckImageFolderApart).
FeatureImportSettings MakeFeatureImportSettings(const PipelineContext& context,
                                                const MatchSettings& matching,
                                                const Workspace& workspace,
                                                const std::filesystem::path& images);

struct FeatureImportSummary {
  StageStatus status = StageStatus::kCompleted;
  size_t num_images = 0;    // images of the folder with features (given or held)
  size_t num_imported = 0;  // images whose features this call wrote
  size_t num_reused = 0;    // images that held the same features already
  size_t num_replaced = 0;  // of num_imported, images whose other features were replaced
  size_t num_without = 0;   // images of the folder left out: no features for them
  size_t num_features = 0;  // keypoints written by this call
  int dimension = 0;        // descriptor width
  std::string encoding;     // DescriptorEncodingName
  double seconds = 0;
  nlohmann::json ToJson() const;
};

// Ingests the images of settings.image_dir that `source` has features for (and those
// whose features the workspace holds from an earlier import), as `extract` ingests
// them, then stores the features, each image its own transaction; an image whose
// features changed loses its matches and geometries. Everything given is checked before
// anything is written: every image named must be in the folder, keypoints finite and
// inside their image, one descriptor width across images, the workspace's own width and
// encoding when it holds imported features, a width the matcher and pair selectors
// take. Throws InputError naming the file (and line) or the image. A workspace holding
// a detector's features is refused (import into a new one). Records the features'
// provenance ({"imported": ..., "metric": "l2", "descriptors": encoding}), so that
// `extract` refuses to replace them and `match` treats them as any features.
// `control`: progress ("import", images done, images to write) and cancellation between
// images; a cancelled call keeps the images written and the next resumes.
FeatureImportSummary ImportFeatures(const Workspace& workspace,
                                    const FeatureImportSettings& settings,
                                    const FeatureSource& source, const StageControl& control = {});

}  // namespace tessera
