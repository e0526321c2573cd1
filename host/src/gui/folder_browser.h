#pragma once

// A "..." button beside a path field that opens a popup listing the sub-folders of the
// field's folder (or of the working folder): ".." goes up, a folder goes in, "Choose this
// folder" writes the folder into the field. Given a file extension (the manifest field's
// ".json"), it lists the files with it too, and a file clicked is written into the field
// instead of a folder. "New folder" makes a sub-folder of the folder listed and goes in.

#include <filesystem>
#include <string>

#include "gui/panel_widgets.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class FolderBrowser {
 public:
  // The button and its popup "browse <name>"; records "browse <name>", "choose folder"
  // (without `file_extension`), "new folder name", "create folder", "folder
  // <sub-folder>" and "file <file>" in `widgets`.
  void Draw(const std::string& name, PathField* path, WidgetRects* widgets,
            const std::string& file_extension = "");

 private:
  // The popup's list: sub-folders, then the files with `file_extension` when it is not
  // empty. Returns the entry clicked (empty when none).
  std::filesystem::path DrawFolderList(const std::string& file_extension, WidgetRects* widgets);

  // Makes the sub-folder named in new_folder_ and lists it; false with the message in
  // create_error_ (an empty name, a path, a folder that is there, what the system says).
  bool CreateFolder();

  std::filesystem::path browse_dir_;  // the folder listed
  PathField new_folder_{};
  std::string create_error_;
};

}  // namespace tessera::gui
