#pragma once

// What part of a stage's work this process does. Empty (the default): all of it, into
// the workspace's own database. A shard of a Slurm array (distributed/) narrows it:
// the stages keep one loop each, and the shard code chooses only what it owns.

#include <functional>
#include <string>
#include <vector>

#include "database/database.h"
#include "tessera/pair_selector.h"

namespace tessera {

struct StageScope {
  // Named in log lines ("shard 2/4"); empty: the whole stage.
  std::string name;

  // Extract: whether this process detects the image at this index of the scan (natural
  // name order). Every image is ingested all the same. Empty: every image.
  std::function<bool(size_t image_index)> images;

  // Match: the pairs this process matches, given every chosen pair (indices into
  // `images`, capture order) with the workspace's images. Returns one flag per pair.
  // Empty: every pair.
  std::function<std::vector<bool>(const std::vector<ImageIndexPair>& pairs,
                                  const std::vector<Image>& images)>
      pairs;

  // Match: where images and features are read from and which pairs are done already,
  // when that is not the workspace's database (a shard reads database.db, read only,
  // and writes its own). nullptr: the workspace's database.
  const Database* source = nullptr;

  bool IsWhole() const { return !images && !pairs && source == nullptr; }
};

}  // namespace tessera
