#pragma once

// Where the named widgets were drawn in the last frame, in window pixels: tests click
// them by name (ImGui 1.86 has no test engine).

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tessera::gui {

// A widget's rectangle in window pixels, recorded as it was last drawn.
struct WidgetRect {
  float min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  float CenterX() const { return (min_x + max_x) / 2; }
  float CenterY() const { return (min_y + max_y) / 2; }
};

class WidgetRects {
 public:
  // Forgets every rectangle (a new frame records them again).
  void Clear() {
    rects_.clear();
    elided_.clear();
    tooltip_.clear();
    errors_.clear();
  }
  // Records ImGui's last item under `name`.
  void RecordLastItem(const std::string& name);
  void Set(const std::string& name, const WidgetRect& rect) { rects_[name] = rect; }
  std::optional<WidgetRect> Find(const std::string& name) const;
  // The texts drawn cut short ("...") this frame, with their whole text (FitText).
  void AddElided(const WidgetRect& rect, const std::string& text) {
    elided_.emplace_back(rect, text);
  }
  const std::vector<std::pair<WidgetRect, std::string>>& Elided() const { return elided_; }
  // The text of the tooltip shown this frame for an elided text; empty when none.
  void set_tooltip(const std::string& text) { tooltip_ = text; }
  const std::string& tooltip() const { return tooltip_; }
  // The error messages drawn this frame (ErrorText), each time it was drawn.
  void AddError(const std::string& text) { errors_.push_back(text); }
  const std::vector<std::string>& Errors() const { return errors_; }

 private:
  std::map<std::string, WidgetRect> rects_;
  std::vector<std::pair<WidgetRect, std::string>> elided_;
  std::string tooltip_;
  std::vector<std::string> errors_;
};

}  // namespace tessera::gui
