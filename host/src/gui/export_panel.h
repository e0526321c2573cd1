#pragma once

// "Export the model": the model shown (as written: a model folder) written with an
// exporter plugin to an output folder, as `tessera export` writes it (ExportModel: the
// same plugins, the same checks, the same outputs ledger). The exporters are those on
// the plugin path; a run's model not yet written cannot be exported, and says so.

#include <filesystem>
#include <string>
#include <vector>

#include "gui/panel_widgets.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class ExportPanel {
 public:
  // Exports `model` (a COLMAP model folder; empty: none written) with the exporter
  // `format` to `output`, the photographs read from `images`; false with the message
  // in Message() (also logged).
  bool Export(const std::filesystem::path& model, const std::string& format,
              const std::filesystem::path& output, const std::filesystem::path& images,
              int model_index);
  // The section: the exporter (a dropdown recorded as "exporter", its entries as
  // "exporter NAME"), the output folder ("export output") and Export ("export").
  void Draw(const std::filesystem::path& model, int model_index,
            const std::filesystem::path& images, WidgetRects* widgets);
  // Forgets the last export's message (a run replaces the model it was about).
  void ForgetResult() {
    message_.clear();
    failed_ = false;
  }
  const std::string& Message() const { return message_; }
  bool failed() const { return failed_; }
  const std::string& format() const { return format_; }

 private:
  void FindExporters();

  std::vector<std::string> exporters_;
  bool searched_ = false;
  std::string format_;
  PathField output_{};
  std::string message_;
  bool failed_ = false;
  std::filesystem::path message_model_;  // the model message_ is about
};

}  // namespace tessera::gui
