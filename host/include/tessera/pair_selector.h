#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "tessera/camera.h"
#include "tessera/errors.h"
#include "tessera/feature_reader.h"
#include "tessera/features.h"
#include "tessera/ids.h"
#include "tessera/image_metadata.h"
#include "tessera/plugin.h"

namespace tessera {

// A candidate pair as indices into PairSelectionInput::images, first < second.
using ImageIndexPair = std::pair<size_t, size_t>;

// What a pair selector knows of one image before matching.
struct PairSelectionImage {
  image_t image_id = kInvalidImageId;
  std::string name;  // path relative to the image folder, '/' separated
  Camera camera;     // its camera (width and height are the image's, as detection saw it)
  ImageMetadata metadata;
};

struct PairSelectionInput {
  // In capture order (natural sort of the names).
  std::vector<PairSelectionImage> images;
  // The workspace's features; null where there are none (a selector that needs them
  // throws InputError then).
  const FeatureReader* features = nullptr;
  // Threads the selector may use.
  int num_threads = 1;
};

// Chooses which image pairs to match, from the images' names, cameras, metadata and,
// on demand, features.
//
// The contract in short (the full one: PREFIX/share/doc/tessera/plugins/pair_selector.md):
// - SelectPairs is called once per match stage, from one thread, with every image of
//   the workspace in capture order; it may use input.num_threads threads.
// - Return indices into input.images, each pair once, first < second, in a
//   deterministic order. An index out of range or a self pair ends the stage (exit
//   code 1). With several selectors the host matches the union, each pair once.
// - Read features on demand through input.features and drop them; never hold them all.
// - InputError (or OptionError) from SelectPairs or CheckDescriptors ends the stage with
//   exit code 2, naming the selector's slot; anything else exit code 1. A crash ends the
//   run (exit code 4); a selector that crashed twice on the same images is refused them.
// - Options: OptionReader in the constructor, Finish(), effective_options_ =
//   reader.Effective(); the host records them with the selected pairs.
// - Log with log() (tessera/log.h), never to stdout or stderr; never call exit().
class TESSERA_API PairSelector : public Plugin {
 public:
  // Returns each pair once, with first < second, in a deterministic order.
  virtual std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const = 0;

  // Throws OptionError when this selector cannot work with descriptors of this metric
  // and width (e.g. a retrieval selector given binary descriptors). Called before any
  // image is read, with the detector's metric; the default accepts everything.
  // `dimension` is 0 where the width is not known yet (before extraction: detectors do
  // not declare it); the host calls again with the workspace's width before matching.
  virtual void CheckDescriptors(DescriptorMetric /*metric*/, int /*dimension*/) const {}

  // Selectors that learn from images (a retrieval codebook) train on `input` and write
  // what they learned to `output`, a file their options can name in later runs
  // (`tessera vocab`). The default throws InputError: this selector does not train.
  virtual void Train(const PairSelectionInput& /*input*/,
                     const std::filesystem::path& /*output*/) const {
    throw InputError("this pair selector does not train");
  }
};

}  // namespace tessera
