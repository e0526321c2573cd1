#include "gui/folder_browser.h"

#include <imgui.h>

#include <algorithm>
#include <vector>

#include "gui/image_list.h"

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
    listing_ = Listing{};  // read anew: the folder may have changed since
    go_error_.clear();
    SetPathField(browse_dir_, &typed_);
    ImGui::OpenPopup(popup.c_str());
  }
  widgets->RecordLastItem(popup);
  if (!ImGui::BeginPopup(popup.c_str())) return;
  ListBrowseDir(file_extension);
  // Where the folder listed changes in this frame, the typed path follows it.
  const fs::path listed = browse_dir_;
  // The folder listed, as a path to edit: Return goes where it names.
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 30);
  if (ImGui::InputTextWithHint("##browse path", "type a folder and press Return", typed_.data(),
                               typed_.size(), ImGuiInputTextFlags_EnterReturnsTrue) &&
      GoToTyped(file_extension, path)) {
    ImGui::EndPopup();
    return;
  }
  widgets->RecordLastItem("browse path");
  ErrorText(go_error_, widgets);
  ImGui::TextDisabled("%zu images in this folder", listing_.images);
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
  if (browse_dir_ != listed) {
    SetPathField(browse_dir_, &typed_);
    go_error_.clear();
  }
  ImGui::EndPopup();
}

bool FolderBrowser::GoToTyped(const std::string& file_extension, PathField* path) {
  go_error_.clear();
  const std::string typed = typed_.data();
  std::error_code error;
  const fs::path target = fs::absolute(fs::path(typed), error);
  if (typed.empty() || error) {
    go_error_ = "type a folder's path";
  } else if (fs::is_directory(target, error)) {
    browse_dir_ = target.lexically_normal();
    SetPathField(browse_dir_, &typed_);
    return false;  // the popup stays, listing it
  } else if (!file_extension.empty() && target.extension() == file_extension &&
             fs::is_regular_file(target, error)) {
    SetPathField(target, path);
    ImGui::CloseCurrentPopup();
    return true;
  } else {
    go_error_ = typed + ": no such folder" +
                (file_extension.empty() ? "" : " or " + file_extension + " file");
  }
  return false;
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

void FolderBrowser::ListBrowseDir(const std::string& file_extension) {
  if (listing_.dir == browse_dir_ && listing_.file_extension == file_extension &&
      !listing_.dir.empty()) {
    return;
  }
  listing_ = Listing{};
  listing_.dir = browse_dir_;
  listing_.file_extension = file_extension;
  std::error_code error;
  for (fs::directory_iterator it(browse_dir_, fs::directory_options::skip_permission_denied, error),
       end;
       !error && it != end && listing_.folders.size() + listing_.files.size() < 1000;
       it.increment(error)) {
    std::error_code type_error;
    if (it->is_directory(type_error)) {
      listing_.folders.push_back(it->path().filename().string());
    } else if (!file_extension.empty() && it->path().extension() == file_extension) {
      listing_.files.push_back(it->path().filename().string());
    }
  }
  std::sort(listing_.folders.begin(), listing_.folders.end());
  std::sort(listing_.files.begin(), listing_.files.end());
  for (const std::string& folder : listing_.folders) {
    listing_.folder_images.push_back(CountImageFiles(browse_dir_ / folder));
  }
  listing_.images = CountImageFiles(browse_dir_);
}

fs::path FolderBrowser::DrawFolderList(const std::string& /*file_extension*/,
                                       WidgetRects* widgets) {
  fs::path next;
  // The counts in a column after the names.
  float name_width = 0;
  for (const std::string& folder : listing_.folders) {
    name_width = std::max(name_width, ImGui::CalcTextSize((folder + "/").c_str()).x);
  }
  const float count_at = ImGui::GetCursorPosX() + name_width + 2 * ImGui::GetFontSize();
  for (size_t i = 0; i < listing_.folders.size(); ++i) {
    const std::string& folder = listing_.folders[i];
    if (ImGui::Selectable((folder + "/").c_str(), false, ImGuiSelectableFlags_DontClosePopups)) {
      next = listing_.dir / folder;
    }
    widgets->RecordLastItem("folder " + folder);
    ImGui::SameLine(count_at);
    const size_t images = listing_.folder_images[i];
    ImGui::TextDisabled("%zu image%s", images, images == 1 ? "" : "s");
    widgets->RecordLastItem("images in " + folder + ": " + std::to_string(images));
  }
  for (const std::string& file : listing_.files) {
    if (ImGui::Selectable(file.c_str(), false, ImGuiSelectableFlags_DontClosePopups)) {
      next = listing_.dir / file;
    }
    widgets->RecordLastItem("file " + file);
  }
  return next;
}

}  // namespace tessera::gui
