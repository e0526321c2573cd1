#pragma once

#include <filesystem>

#include "tessera/features.h"
#include "tessera/plugin.h"

namespace tessera {

// Finds putative correspondences between the descriptors of two images.
//
// The contract in short (the full one: PREFIX/share/doc/tessera/plugins/matcher.md):
// - Match is called once per selected pair not yet matched in the workspace, from
//   several threads at once, with the two images' descriptors as stored (one uint8 row
//   per keypoint, the workspace's metric and width; a set may be empty).
// - Return indices into the two sets: an index beyond them ends the stage (exit code
//   1). The host then verifies the matches geometrically; return putative ones.
// - A throw from Match ends the match stage (InputError: exit code 2, else 1); pairs
//   matched before stay in the workspace. A crash ends the run (exit code 4); a pair
//   that crashed the matcher twice is skipped from then on.
// - Options: OptionReader in the constructor, Finish(), effective_options_ =
//   reader.Effective(); the host records them with the matches, and a change matches
//   the pairs again. An OptionError there is exit code 2, naming the key.
// - Log with log() (tessera/log.h), never to stdout or stderr; never call exit().
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
