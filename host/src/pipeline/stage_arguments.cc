#include "pipeline/stage_arguments.h"

#include "manifest/manifest.h"
#include "util/paths.h"

namespace tessera {
namespace {

PipelineContext CreateContext(const StageArguments& arguments) {
  if (arguments.manifest_json) {
    return PipelineContext::Create(
        Manifest::FromJson(*arguments.manifest_json, std::filesystem::current_path(), "manifest"));
  }
  std::filesystem::path file = arguments.manifest;
  // Video: ordered frames that may come back to where they started.
  if (file.empty() && !arguments.videos.empty()) {
    file = DefaultManifestFile().parent_path() / "ordered_loop.json";
  }
  return PipelineContext::Create(file);
}

}  // namespace

PipelineContext LoadPipelineContext(const StageArguments& arguments) {
  PipelineContext context = CreateContext(arguments);
  if (arguments.threads > 0) context.manifest.num_threads = arguments.threads;
  if (!arguments.camera_K.empty()) {
    ReadKnownIntrinsicsFile(arguments.camera_K, &context.manifest.camera);
  }
  if (!arguments.masks.empty()) context.manifest.camera.mask_path = arguments.masks;
  if (arguments.camera_per_folder) context.manifest.camera.per_folder = true;
  // Each camera of a rig is the camera of one subfolder.
  if (!arguments.rig.empty()) {
    context.rig = RigFile::Read(arguments.rig);
    context.manifest.camera.per_folder = true;
  }
  context.LimitLibraryThreads();
  return context;
}

}  // namespace tessera
