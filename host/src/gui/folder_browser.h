#pragma once

// A "..." button beside a path field that opens a popup listing the sub-folders of the
// field's folder (or of the working folder): ".." goes up, a folder goes in, "Choose this
// folder" writes the folder into the field.

#include <filesystem>
#include <string>

#include "gui/panel_widgets.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class FolderBrowser {
 public:
  // The button and its popup "browse <name>"; records "browse <name>", "choose folder"
  // and "folder <sub-folder>" in `widgets`.
  void Draw(const std::string& name, PathField* path, WidgetRects* widgets);

 private:
  // The popup's list; returns the sub-folder clicked (empty when none).
  std::filesystem::path DrawFolderList(WidgetRects* widgets);

  std::filesystem::path browse_dir_;  // the folder listed
};

}  // namespace tessera::gui
