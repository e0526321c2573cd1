#include "gui/folder_browser.h"

#include <imgui.h>

#include <algorithm>
#include <vector>

namespace tessera::gui {
namespace fs = std::filesystem;

void FolderBrowser::Draw(const std::string& name, PathField* path, WidgetRects* widgets,
                         const std::string& file_extension) {
  const std::string popup = "browse " + name;
  if (ImGui::Button(("...##" + name).c_str())) {
    std::error_code error;
    browse_dir_ =
        (*path)[0] != '\0' ? fs::absolute(fs::path(path->data()), error) : fs::current_path(error);
    if (!fs::is_directory(browse_dir_, error)) browse_dir_ = browse_dir_.parent_path();
    ImGui::OpenPopup(popup.c_str());
  }
  widgets->RecordLastItem(popup);
  if (!ImGui::BeginPopup(popup.c_str())) return;
  // A long path wraps at 30 lines' height of width (the popup fits its contents).
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + ImGui::GetFontSize() * 30);
  ImGui::TextUnformatted(browse_dir_.string().c_str());
  ImGui::PopTextWrapPos();
  if (file_extension.empty()) {
    if (ImGui::Button("Choose this folder")) {
      SetPathField(browse_dir_, path);
      ImGui::CloseCurrentPopup();
    }
    widgets->RecordLastItem("choose folder");
  } else {
    ImGui::TextDisabled("choose a %s file", file_extension.c_str());
  }
  // A new folder (a workspace to be): named, made here and gone into.
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 14);
  const bool entered =
      ImGui::InputTextWithHint("##new folder", "new folder name", new_folder_.data(),
                               new_folder_.size(), ImGuiInputTextFlags_EnterReturnsTrue);
  widgets->RecordLastItem("new folder name");
  ImGui::SameLine();
  if (ImGui::Button("New folder") || entered) CreateFolder();
  widgets->RecordLastItem("create folder");
  ErrorText(create_error_, widgets);
  ImGui::Separator();
  if (ImGui::Selectable("..", false, ImGuiSelectableFlags_DontClosePopups)) {
    browse_dir_ = browse_dir_.parent_path();
  }
  const fs::path next = DrawFolderList(file_extension, widgets);
  std::error_code error;
  if (!next.empty() && fs::is_directory(next, error)) {
    browse_dir_ = next;
  } else if (!next.empty()) {  // a file: the field's value
    SetPathField(next, path);
    ImGui::CloseCurrentPopup();
  }
  ImGui::EndPopup();
}

bool FolderBrowser::CreateFolder() {
  const std::string name = new_folder_.data();
  create_error_.clear();
  const fs::path folder = browse_dir_ / name;
  std::error_code error;
  if (name.empty()) {
    create_error_ = "type the new folder's name";
  } else if (name.find('/') != std::string::npos || name == "." || name == "..") {
    create_error_ = "'" + name + "': a folder's name, not a path";
  } else if (fs::exists(folder, error)) {
    create_error_ = folder.string() + " is there already";
  } else if (!fs::create_directory(folder, error) || error) {
    create_error_ = "cannot create the folder " + folder.string() + ": " + error.message();
  }
  if (!create_error_.empty()) return false;
  browse_dir_ = folder;
  new_folder_[0] = '\0';
  return true;
}

fs::path FolderBrowser::DrawFolderList(const std::string& file_extension, WidgetRects* widgets) {
  // At most 1000 entries, so that a huge folder costs little on the UI thread.
  std::vector<std::string> folders, files;
  std::error_code error;
  for (fs::directory_iterator it(browse_dir_, fs::directory_options::skip_permission_denied, error),
       end;
       !error && it != end && folders.size() + files.size() < 1000; it.increment(error)) {
    std::error_code type_error;
    if (it->is_directory(type_error)) {
      folders.push_back(it->path().filename().string());
    } else if (!file_extension.empty() && it->path().extension() == file_extension) {
      files.push_back(it->path().filename().string());
    }
  }
  std::sort(folders.begin(), folders.end());
  std::sort(files.begin(), files.end());
  fs::path next;
  for (const std::string& folder : folders) {
    if (ImGui::Selectable((folder + "/").c_str(), false, ImGuiSelectableFlags_DontClosePopups)) {
      next = browse_dir_ / folder;
    }
    widgets->RecordLastItem("folder " + folder);
  }
  for (const std::string& file : files) {
    if (ImGui::Selectable(file.c_str(), false, ImGuiSelectableFlags_DontClosePopups)) {
      next = browse_dir_ / file;
    }
    widgets->RecordLastItem("file " + file);
  }
  return next;
}

}  // namespace tessera::gui
