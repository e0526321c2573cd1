#include "pipeline/evaluate_model.h"

#include "eval/ground_truth.h"
#include "pipeline/workspace.h"
#include "tessera/io/colmap_model_io.h"

namespace tessera {

EvaluationResult EvaluateModelFolder(const std::filesystem::path& model_dir,
                                     const std::filesystem::path& ground_truth) {
  // A model of a workspace is read while no run can rewrite it.
  const auto workspaces = HoldEnclosingWorkspaces({model_dir});
  const Reconstruction model = ReadColmapModel(model_dir);
  const auto poses = ReadGroundTruth(ground_truth);
  return EvaluateReconstruction(model, poses, model_dir);
}

InputError UnscoredError(const EvaluationResult& result, const std::filesystem::path& model_dir,
                         const std::filesystem::path& ground_truth) {
  return InputError("Cannot score " + model_dir.string() + " against " + ground_truth.string() +
                    ": " + result.error + ".");
}

}  // namespace tessera
