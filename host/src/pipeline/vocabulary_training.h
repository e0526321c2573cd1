#pragma once

#include <cstddef>
#include <filesystem>

#include "manifest/manifest.h"
#include "pipeline/pipeline_context.h"

namespace tessera {

// Training a retrieval codebook (`tessera vocab`, the `retrieval` pair selector's
// `codebook` option): features are detected with the manifest's detector into a
// workspace, then the manifest's `retrieval` pair selector trains on them.

// `manifest` reduced to what training needs: its detector, and its `retrieval` slot (a
// new one when it has none) without its `codebook` (the file training writes), with
// `codebook_size` centres when above 0. No matcher, adjuster or exporter is loaded.
void PrepareManifestForVocabulary(Manifest* manifest, int codebook_size);

struct VocabularySettings {
  std::filesystem::path image_dir;      // the images to train on
  std::filesystem::path codebook_file;  // written by the selector
  // The workspace that keeps the features; empty: a temporary one, removed afterwards.
  std::filesystem::path workspace;
};

struct VocabularySummary {
  size_t num_images = 0;
  size_t num_features = 0;
  int codebook_size = 0;  // as the selector reports it
  double seconds = 0;
};

// Detects the features of `settings.image_dir` and trains the one pair selector of
// `context` (made from a manifest PrepareManifestForVocabulary reduced) on them. Bad
// input (no detector, descriptors the selector cannot use, too few features) is an
// InputError naming the folder or plugin.
VocabularySummary TrainVocabulary(const PipelineContext& context,
                                  const VocabularySettings& settings);

}  // namespace tessera
