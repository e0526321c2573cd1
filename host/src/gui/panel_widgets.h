#pragma once

// Small pieces the panels share: the text buffer of a path field (ImGui edits a char
// array in place), a message line in red and a greyed hint.

#include <array>
#include <filesystem>
#include <string>

namespace tessera::gui {

using PathField = std::array<char, 1024>;

// Copies `path` into the field, cut to the field's size.
void SetPathField(const std::filesystem::path& path, PathField* field);

// Draws `text` wrapped, in red; nothing when it is empty.
void ErrorText(const std::string& text);

// Draws `text` wrapped, greyed (a description or hint); nothing when it is empty.
void HintText(const std::string& text);

}  // namespace tessera::gui
