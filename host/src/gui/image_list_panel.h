#pragma once

// The "Images" window: every image of the workspace shown (image_list.h), the model it
// is in and, for one in no model, why it was left out. A click on an image in a model
// asks for its camera to be picked in the 3D view (the window shows that model first).

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "gui/image_list.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class ImageListPanel {
 public:
  // on_select(name, model): an image of model N (sparse/N) was clicked.
  explicit ImageListPanel(std::function<void(const std::string&, int)> on_select)
      : on_select_(std::move(on_select)) {}

  // Reads the list of `workspace` (its images beside `image_dir`'s) and opens the
  // window; false with the message in Error() (also logged) when it cannot.
  bool Open(const std::filesystem::path& workspace, const std::filesystem::path& image_dir);
  // The list is read anew on the next frame it is drawn (a run ended).
  void Invalidate() { stale_ = true; }
  // Called each frame with the workspace of the model shown and the Images field: an
  // open list of another is read anew for these (not while `being_written` by a run).
  void Follow(const std::filesystem::path& workspace, const std::filesystem::path& image_dir,
              bool being_written);

  // The "Image list" button of the set-up window (records "image list") and its message.
  void DrawOpenButton(const std::filesystem::path& workspace,
                      const std::filesystem::path& image_dir, WidgetRects* widgets);
  // The window, while open, at the bottom left of `view_rect`; `selected`: the image
  // picked now (highlighted). Records "image list window" and "image row NAME".
  void Draw(const WidgetRect& view_rect, const std::string& selected, WidgetRects* widgets);

  const ImageList* list() const { return show_ && list_ ? &*list_ : nullptr; }
  const std::string& Error() const { return error_; }

 private:
  std::function<void(const std::string&, int)> on_select_;
  bool show_ = false;
  bool stale_ = false;
  std::optional<ImageList> list_;
  std::filesystem::path image_dir_;
  std::string error_;
};

}  // namespace tessera::gui
