#pragma once

// `register`: new photos placed into an existing model without moving it (COLMAP's
// image_registrator). Shared by the CLI verb and the Python module.
//
//   1. the images of the folder that the workspace does not hold yet are extracted
//      (pipeline/extract_stage.h, which resumes);
//   2. the manifest's pair selection, restricted to pairs with an image in no model of
//      the workspace (a "new" image), is matched (pipeline/match_stage.h, which resumes);
//   3. each new image is registered into model N by the incremental mapper's own steps
//      (IncrementalMapper::StartFrom, RegisterImages: PnP LO-RANSAC checked against the
//      view graph, triangulation, local adjustment) with every camera, pose and point of
//      the model held, unless refine_existing (then a global refinement follows);
//   4. OUTPUT/sparse/N and OUTPUT/register_summary.json are placed as one set
//      (outputs/output_transaction.h), replacing that model folder only.
// Nothing of the model is written before step 4: an interrupt loses only step 3.

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/stage_arguments.h"
#include "pipeline/stage_control.h"

namespace tessera {

struct RegisterArguments {
  std::filesystem::path output;  // the workspace
  std::filesystem::path images;  // empty: the folder extract recorded
  int model_index = 0;           // OUTPUT/sparse/N
  bool refine_existing = false;  // a global refinement after registration, moving everything
  StageArguments stage;          // --manifest, --threads, --camera-K, --masks
};

struct RegisterSummary {
  StageStatus status = StageStatus::kCompleted;
  int model_index = 0;
  std::string model_folder;
  bool refine_existing = false;
  size_t num_images_before = 0;  // in the model
  size_t num_images_after = 0;
  size_t num_points_before = 0;
  size_t num_points_after = 0;
  size_t num_extracted = 0;      // images detected by this call's extraction
  size_t num_pairs_matched = 0;  // pairs matched by this call
  struct NewImage {
    std::string name;
    bool registered = false;
    std::string reason;  // why not; empty when registered
  };
  std::vector<NewImage> images;  // every new image, by name
  double extract_seconds = 0;
  double match_seconds = 0;
  double register_seconds = 0;
  double seconds = 0;

  size_t NumRegistered() const;
  nlohmann::json ToJson() const;
};

// The steps above. Throws InputError (one line naming the option, file or image) on bad
// input: a workspace without a database, no model N, an image folder that lacks or
// changed an image of the workspace, no image outside every model; PluginError as the
// stages do. Cancelled by `control` (Ctrl-C): status kCancelled, and what extraction
// and matching finished is kept; the model is not written.
RegisterSummary RegisterIntoModel(const RegisterArguments& arguments,
                                  const StageControl& control = {});

// The summary's lines for a person: one per new image, then the totals.
std::vector<std::string> DescribeRegistration(const RegisterSummary& summary);

}  // namespace tessera
