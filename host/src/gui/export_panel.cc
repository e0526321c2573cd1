#include "gui/export_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "gui/checked_read.h"
#include "pipeline/export_model.h"
#include "plugin/plugin_registry.h"
#include "util/paths.h"

namespace tessera::gui {
namespace fs = std::filesystem;

void ExportPanel::FindExporters() {
  searched_ = true;
  std::string error;
  CheckedRead(
      {},
      [&] { exporters_ = PluginRegistry::Discover(PluginSearchPath({})).NamesOfKind("exporter"); },
      &error);
  if (!error.empty()) message_ = error;
  // The COLMAP binary model first when there is one: what the pipeline writes by default.
  const auto colmap = std::find(exporters_.begin(), exporters_.end(), "colmap_binary");
  format_ = colmap != exporters_.end() ? *colmap : exporters_.empty() ? "" : exporters_.front();
}

bool ExportPanel::Export(const fs::path& model, const std::string& format, const fs::path& output,
                         const fs::path& images, int model_index) {
  failed_ = true;
  message_model_ = model;
  if (model.empty()) {
    message_ =
        "export: the model shown is not written yet (a run's model): export it once "
        "the run has written it";
  } else if (format.empty()) {
    message_ = "export: choose an exporter";
  } else if (output.empty()) {
    message_ = "export: choose an output folder";
  } else {
    ExportArguments arguments;
    arguments.model = model;
    arguments.format = format;
    arguments.output = output;
    arguments.images = images;
    arguments.model_index = model_index;
    ExportSummary summary;
    if (CheckedRead(
            model, [&] { summary = ExportModel(arguments); }, &message_)) {
      failed_ = false;
      message_ = "exported " + std::to_string(summary.num_images) + " images, " +
                 std::to_string(summary.num_points3D) + " points with '" + summary.exporter +
                 "' to " + output.string();
      spdlog::info("gui: {}", message_);
      return true;
    }
  }
  spdlog::error("{}", message_);
  return false;
}

void ExportPanel::Draw(const fs::path& model, int model_index, const fs::path& images,
                       WidgetRects* widgets) {
  // A message is about the model exported: another model shown, and it goes.
  if (!message_.empty() && model != message_model_) {
    ForgetResult();
  }
  const bool open = ImGui::CollapsingHeader("Export the model");
  widgets->RecordLastItem("export section");
  if (!open) return;
  if (!searched_) {
    FindExporters();
    message_model_ = model;
  }
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 10);
  if (ImGui::BeginCombo("##exporter", format_.empty() ? "(no exporter found)" : format_.c_str())) {
    for (const std::string& name : exporters_) {
      if (ImGui::Selectable(name.c_str(), name == format_)) format_ = name;
      widgets->RecordLastItem("exporter " + name);
    }
    ImGui::EndCombo();
  }
  widgets->RecordLastItem("exporter");
  ImGui::SameLine();
  const ImGuiStyle& style = ImGui::GetStyle();
  ImGui::SetNextItemWidth(
      -(ImGui::CalcTextSize("Export").x + 2 * style.FramePadding.x + style.ItemSpacing.x));
  ImGui::InputTextWithHint("##export output", "output folder", output_.data(), output_.size());
  widgets->RecordLastItem("export output");
  ImGui::SameLine();
  ImGui::BeginDisabled(model.empty());
  if (ImGui::Button("Export"))
    Export(model, format_, fs::path(output_.data()), images, model_index);
  ImGui::EndDisabled();
  widgets->RecordLastItem("export");
  if (model.empty()) HintText("a run's model is exported once written (its workspace's sparse/N)");
  if (failed_) {
    ErrorText(message_, widgets);
  } else {
    HintText(message_);
  }
}

}  // namespace tessera::gui
