#pragma once

// `eval`: a model folder scored against ground truth, shared by the CLI verb and the
// Python module.

#include <filesystem>
#include <optional>

#include "eval/evaluation.h"
#include "geometry/similarity_transform.h"
#include "tessera/errors.h"
#include "tessera/georeference.h"

namespace tessera {

// Reads the COLMAP model in `model_dir` (holding its workspace, so that no run rewrites
// it meanwhile) and the ground truth (*.camera files, a transforms.json or a model
// folder) and scores the model's poses. Throws InputError naming the file on bad input;
// a result that could not be aligned is returned with `aligned` false.
//
// `no_align`: no similarity is estimated; the model must be anchored to GPS
// (MODEL/georeference.json) and the ground truth's frame known: east-north-up metres about
// `gt_origin`, or a georeferenced model folder. Its poses are moved into the model's frame
// and scored there. Throws InputError saying which is missing.
//
// `model_moved_by` (an alignment.json of `tessera align`): the model is moved by it first;
// with `no_align` it is then scored in the ground truth's frame as it is (no
// georeference.json needed: the alignment put it there).
EvaluationResult EvaluateModelFolder(
    const std::filesystem::path& model_dir, const std::filesystem::path& ground_truth,
    bool no_align = false, const std::optional<Georeference>& gt_origin = std::nullopt,
    const std::optional<Similarity3d>& model_moved_by = std::nullopt);

// Why a result could not be scored (result.aligned false), naming both inputs: the
// user's to fix (wrong ground truth, names that do not match), so bad input.
InputError UnscoredError(const EvaluationResult& result, const std::filesystem::path& model_dir,
                         const std::filesystem::path& ground_truth);

}  // namespace tessera
