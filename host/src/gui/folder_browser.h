#pragma once

// A "..." button beside a path field that opens a popup listing the sub-folders of the
// field's folder (or of the working folder): ".." goes up, a folder goes in, "Choose this
// folder" writes the folder into the field. Given a file extension (the manifest field's
// ".json"), it lists the files with it too, and a file clicked is written into the field
// instead of a folder. "New folder" makes a sub-folder of the folder listed and goes in.
// Each folder listed shows how many images it holds (directly), and so does the folder
// listed; a path typed (and Return) goes to that folder, or chooses that file.

#include <filesystem>
#include <string>
#include <vector>

#include "gui/panel_widgets.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class FolderBrowser {
 public:
  // The button and its popup "browse <name>"; records "browse <name>", "choose folder"
  // (without `file_extension`), "new folder name", "create folder", "browse path" (the
  // typed path), "folder <sub-folder>", "images in <sub-folder>: N" (its count) and "file
  // <file>" in `widgets`.
  void Draw(const std::string& name, PathField* path, WidgetRects* widgets,
            const std::string& file_extension = "");

 private:
  // The popup's list: sub-folders, then the files with `file_extension` when it is not
  // empty. Returns the entry clicked (empty when none).
  std::filesystem::path DrawFolderList(const std::string& file_extension, WidgetRects* widgets);

  // Makes the sub-folder named in new_folder_ and lists it; false with the message in
  // create_error_ (an empty name, a path, a folder that is there, what the system says).
  bool CreateFolder();

  // Lists browse_dir_ into listing_ when it is not the folder listed: the sub-folders with
  // their image counts, and the files with `file_extension`; at most 1000 entries, so
  // that a huge folder costs little on the UI thread (once, not each frame).
  void ListBrowseDir(const std::string& file_extension);
  // Goes to the folder typed (or chooses the file typed, given a file extension); false
  // with the message in go_error_ when it is neither.
  bool GoToTyped(const std::string& file_extension, PathField* path);

  struct Listing {
    std::filesystem::path dir;  // the folder listed; empty: none yet
    std::string file_extension;
    std::vector<std::string> folders;
    std::vector<size_t> folder_images;  // images directly in each of folders
    std::vector<std::string> files;
    size_t images = 0;  // directly in dir
  };

  std::filesystem::path browse_dir_;  // the folder listed
  Listing listing_;
  PathField typed_{};
  std::string go_error_;
  PathField new_folder_{};
  std::string create_error_;
};

}  // namespace tessera::gui
