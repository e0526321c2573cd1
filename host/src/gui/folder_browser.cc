#include "gui/folder_browser.h"

#include <imgui.h>

#include <algorithm>
#include <vector>

namespace tessera::gui {
namespace fs = std::filesystem;

void FolderBrowser::Draw(const std::string& name, PathField* path, WidgetRects* widgets) {
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
  ImGui::TextUnformatted(browse_dir_.string().c_str());
  if (ImGui::Button("Choose this folder")) {
    SetPathField(browse_dir_, path);
    ImGui::CloseCurrentPopup();
  }
  widgets->RecordLastItem("choose folder");
  ImGui::Separator();
  if (ImGui::Selectable("..", false, ImGuiSelectableFlags_DontClosePopups)) {
    browse_dir_ = browse_dir_.parent_path();
  }
  const fs::path next = DrawFolderList(widgets);
  if (!next.empty()) browse_dir_ = next;
  ImGui::EndPopup();
}

fs::path FolderBrowser::DrawFolderList(WidgetRects* widgets) {
  // At most 1000 sub-folders, so that a huge folder costs little on the UI thread.
  std::vector<std::string> folders;
  std::error_code error;
  for (fs::directory_iterator it(browse_dir_, fs::directory_options::skip_permission_denied, error),
       end;
       !error && it != end && folders.size() < 1000; it.increment(error)) {
    std::error_code type_error;
    if (it->is_directory(type_error)) folders.push_back(it->path().filename().string());
  }
  std::sort(folders.begin(), folders.end());
  fs::path next;
  for (const std::string& folder : folders) {
    if (ImGui::Selectable((folder + "/").c_str(), false, ImGuiSelectableFlags_DontClosePopups)) {
      next = browse_dir_ / folder;
    }
    widgets->RecordLastItem("folder " + folder);
  }
  return next;
}

}  // namespace tessera::gui
