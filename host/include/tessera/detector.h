#pragma once

#include "tessera/features.h"
#include "tessera/image_view.h"
#include "tessera/plugin.h"

namespace tessera {

// Finds keypoints and computes their descriptors in one grey image.
//
// The contract in short (the full one: PREFIX/share/doc/tessera/plugins/detector.md):
// - Detect is called once per image without features in the workspace, from several
//   threads at once. `image` is the whole image, 8-bit grey, full resolution, EXIF
//   orientation applied; rows are `stride` bytes apart; valid during the call only.
// - The host applies the image's mask afterwards: it removes the keypoints (and their
//   rows) that fall on it. A detector never reads masks.
// - Return one descriptor row per keypoint, in the keypoints' order (else the image is
//   skipped), uint8 rows of the same width for every image, descriptors.metric ==
//   Metric().
// - A throw from Detect skips that image, not the run (a warning naming plugin and
//   image; the reason is recorded and the image skipped until its file changes). A
//   crash ends the run (exit code 4); an image that crashed the detector twice is
//   skipped from then on.
// - Options: OptionReader in the constructor, Finish(), effective_options_ =
//   reader.Effective(); the host records them with the features, and a change detects
//   the images again. An OptionError there is exit code 2, naming the key.
// - Log with log() (tessera/log.h), never to stdout or stderr; never call exit().
class TESSERA_API Detector : public Plugin {
 public:
  // Keypoints are in pixel coordinates of `image` as given (full resolution), even
  // when the detector works on a downscaled copy; the centre of the top-left pixel is
  // (0.5, 0.5), as in COLMAP (OpenCV's cv::KeyPoint: add 0.5). Must be safe to call
  // from several threads at once: the host detects images in parallel.
  virtual FeatureSet Detect(const ImageView& image) const = 0;

  // How this detector's descriptors are compared. Read once, when the host records what
  // produced the features; stored with them and given to pair selectors and matchers.
  virtual DescriptorMetric Metric() const = 0;
};

}  // namespace tessera
