#pragma once

#include <filesystem>

#include "tessera/features.h"
#include "tessera/plugin.h"

namespace tessera {

// Finds putative correspondences between the descriptors of two images.
class TESSERA_API Matcher : public Plugin {
 public:
  // Indices into descriptors1 and descriptors2. Both sets share one metric; a
  // matcher that cannot handle it throws tessera::InputError. Must be safe to call
  // from several threads at once: the host matches pairs in parallel.
  virtual FeatureMatches Match(const FeatureDescriptors& descriptors1,
                               const FeatureDescriptors& descriptors2) const = 0;

  // Optional: per-image work kept across processes. A matcher that builds something
  // from one image's descriptors alone (a search index) may keep it in `folder`, which
  // every process of the workspace sees (OUTPUT/cache/matcher/NAME), so that the matching
  // shards of a Slurm run, or a later run, read it instead of building it again. What is
  // kept there must be named by a hash of everything it was made from, and must never
  // change a match: Match returns the same with or without the folder. A file there may
  // be truncated or corrupt (a killed process, a full disk): check before use, and build
  // instead. The host calls this once, before any Prepare or Match, and not at all when
  // it has no workspace; the folder may not exist yet.
  virtual void SetCacheFolder(const std::filesystem::path& folder) { (void)folder; }

  // Optional: builds, and keeps in the cache folder, what Match would build for these
  // descriptors. The host calls it for each image as soon as its features are extracted,
  // from several threads at once, so that this work is done once per image and spread
  // with the images over the extraction shards, however the pairs are then split. A
  // failure here is reported as a warning, and Match must then still work.
  virtual void Prepare(const FeatureDescriptors& descriptors) const { (void)descriptors; }
};

}  // namespace tessera
