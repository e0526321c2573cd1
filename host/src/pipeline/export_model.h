#pragma once

// `export`: an existing COLMAP model written with an exporter plugin, without running
// the pipeline again. Shared by the CLI verb and the Python module.

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace tessera {

struct ExportArguments {
  std::filesystem::path model;   // COLMAP model folder (text or binary)
  std::string format;            // the exporter plugin's name
  std::filesystem::path output;  // the exporter writes below it
  std::filesystem::path images;  // the model's images, for exporters that read them
  std::filesystem::path masks;   // the images' masks, for exporters that write them
  nlohmann::json options = nlohmann::json::object();  // the exporter's options
  int model_index = 0;  // for exporters that write per model (sparse/N)
};

struct ExportSummary {
  std::string exporter;
  size_t num_images = 0;  // registered images written
  size_t num_points3D = 0;
  size_t num_observations = 0;
  double seconds = 0;
};

// Checks the plugin and its options, then reads the model and exports it as one set of
// outputs (placed whole or not at all), holding the workspaces of the model and of the
// output as a stage holds them. Throws InputError naming the file, option or plugin;
// PluginError when the exporter fails.
ExportSummary ExportModel(const ExportArguments& arguments);

}  // namespace tessera
