#pragma once

// Small pieces the panels share: the text buffer of a path field (ImGui edits a char
// array in place), a message line in red, a greyed hint and a line of text that is cut
// to the width left ("...") with the whole text in a tooltip.

#include <array>
#include <filesystem>
#include <string>

#include "gui/widget_rects.h"

namespace tessera::gui {

using PathField = std::array<char, 1024>;

// Copies `path` into the field, cut to the field's size.
void SetPathField(const std::filesystem::path& path, PathField* field);

// Draws `text` wrapped, in red; nothing when it is empty.
void ErrorText(const std::string& text, WidgetRects* widgets = nullptr);

// Draws `text` in red on one line, the line taken even when `text` is empty: a message
// appearing or going never moves what is below it (a click aimed at it lands on it). A
// longer message is cut with "..." and shown whole in a tooltip (as FitText); the log
// holds it whole too.
void ErrorLine(const std::string& text, WidgetRects* widgets);

// Draws `text` wrapped, greyed (a description or hint); nothing when it is empty.
void HintText(const std::string& text);

// Draws `text` on one line, elided with "..." when wider than the space left on the line;
// an elided text shows the whole of it in a tooltip while hovered (recorded in `widgets`:
// WidgetRects::Elided, WidgetRects::tooltip). `disabled`: greyed.
void FitText(const std::string& text, WidgetRects* widgets, bool disabled = false);
// A tooltip wrapped to fit the window (a long description is never cut at its edge),
// recorded as the tooltip shown when `widgets` is given.
void WrappedTooltip(const std::string& text, WidgetRects* widgets = nullptr);

// `text` cut to `width` pixels of the current font, with "..." at the end; unchanged when
// it fits.
std::string ElideToWidth(const std::string& text, float width);

}  // namespace tessera::gui
