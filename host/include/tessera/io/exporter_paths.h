#pragma once

// Where exporters write, relative to the run's output folder.

#include <filesystem>
#include <string>

#include "tessera/exporter.h"

namespace tessera {

// OUTPUT/sparse/<model_index>: a model's folder, laid out as COLMAP's mapper does.
inline std::filesystem::path SparseModelDir(const ExportContext& context) {
  return context.output_dir / "sparse" / std::to_string(context.model_index);
}

// `name` (a file or folder, relative to the output folder and inside it: options read
// with OptionReader::GetRelativePath) for model 0,
// and name_<k> (before the extension) for model k, so that models never overwrite
// each other: transforms.json, transforms_1.json, ...
inline std::filesystem::path PerModelPath(const ExportContext& context,
                                          const std::filesystem::path& name) {
  std::filesystem::path path = context.output_dir / name;
  if (context.model_index == 0) return path;
  return path.parent_path() / (path.stem().string() + "_" + std::to_string(context.model_index) +
                               path.extension().string());
}

// Where `path` (below context.output_dir, the staging folder) lies once the host has
// placed the set: the same relative path below context.placed_output_dir. A path that a
// file holds to something outside the output folder is relative to the file's placed
// folder, since that is where its reader resolves it.
inline std::filesystem::path PlacedPath(const ExportContext& context,
                                        const std::filesystem::path& path) {
  if (context.placed_output_dir.empty()) return path;
  return (context.placed_output_dir / path.lexically_relative(context.output_dir))
      .lexically_normal();
}

}  // namespace tessera
