#pragma once

#include <filesystem>
#include <optional>

#include "tessera/georeference.h"
#include "tessera/plugin.h"
#include "tessera/reconstruction.h"

namespace tessera {

struct ExportContext {
  // The folder to write into: a staging folder of the run's output folder, whose files
  // the host moves to placed_output_dir when the whole set succeeded.
  std::filesystem::path output_dir;
  std::filesystem::path image_dir;  // where the images named in the model live
  int model_index = 0;              // 0 is the largest model
  // The run's mask folder (camera.mask_path or --masks): the mask of image NAME is
  // MASK_DIR/NAME.png, else MASK_DIR/NAME with the image's extension replaced by .png;
  // white keeps, black masks out. Empty: the run has no masks.
  std::filesystem::path mask_dir;
  // The model's frame: a local east-north-up frame in metres anchored at this WGS84
  // position when the mapper anchored it to GPS; absent: an arbitrary frame and scale.
  // Exporters that can say which frame they write say so.
  std::optional<Georeference> georeference;
  // The run's output folder as the user named it (relative to the working folder, or
  // absolute), where the files of output_dir end up (PlacedPath of
  // tessera/io/exporter_paths.h). A path that a written file holds to something outside
  // it (transforms.json's file_path) is computed from there, never from output_dir.
  // Empty: output_dir itself (a caller that does not stage).
  std::filesystem::path placed_output_dir;
};

// Writes a reconstruction to files. `reconstruction` may hold images that are not
// registered (Image::registered false: after `map`, every image of the run is there);
// an exporter writes the registered ones only. It writes below context.output_dir only
// (the host runs each exporter in a staging folder and places its files when the whole
// set succeeded).
//
// The contract in short (the full one: PREFIX/share/doc/tessera/plugins/exporter.md):
// - Export is called one call at a time: by map and run once per model and exporter
//   (models from 0, the largest; points coloured first when the image folder is known),
//   by `tessera export` once. context.output_dir is the same staging folder for every
//   model of a run: name per-model files with PerModelPath or SparseModelDir
//   (tessera/io/exporter_paths.h), and path options with OptionReader::GetRelativePath.
// - context.image_dir may be empty (not known); context.mask_dir is empty without masks.
//   Never write into either: the host places nothing there.
// - A throw stops the set: later exporters are not run, earlier outputs stay whole, and
//   what this run wrote stays in the staging folder until the next run (InputError:
//   exit code 2, else 1). A crash ends the run (exit code 4); a model that crashed the
//   exporter twice is skipped by it from then on, with a warning.
// - Options: OptionReader in the constructor, Finish(), effective_options_ =
//   reader.Effective(). An OptionError there is exit code 2, naming the key.
// - Log with log() (tessera/log.h), never to stdout or stderr; never call exit().
class TESSERA_API Exporter : public Plugin {
 public:
  virtual void Export(const Reconstruction& reconstruction, const ExportContext& context) const = 0;
};

}  // namespace tessera
