// Issue 52 item 8: the manifest editor's JSON error names the line and column of the
// last character read, in one line without the library's prefix (the library's own line
// was one past the text when the error came at its end).

#include <gtest/gtest.h>

#include <string>

#include "gui/manifest_editor_panel.h"
#include "gui/match_matrix_panel.h"

namespace tessera::gui {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    const nlohmann::json parsed = nlohmann::json::parse(text);
    return "(parsed: " + parsed.dump() + ")";
  } catch (const nlohmann::json::parse_error& error) {
    return JsonErrorMessage(text, error);
  }
}

TEST(JsonErrorMessage, NamesTheLastCharacterReadNotTheLineAfterIt) {
  // Cut after a comma at the end of line 1: the library says line 2, column 0.
  const std::string cut = ErrorOf("{\"a\": 1,\n");
  EXPECT_EQ(cut.rfind("invalid JSON at line 1, column 8: ", 0), 0u) << cut;
  EXPECT_EQ(cut.find("json.exception"), std::string::npos) << cut;
  EXPECT_NE(cut.find("unexpected end of input"), std::string::npos) << cut;
  // An unexpected character is where it is.
  const std::string brace = ErrorOf("{\"a\": 1,\n  }");
  EXPECT_EQ(brace.rfind("invalid JSON at line 2, column 3: ", 0), 0u) << brace;
  const std::string first = ErrorOf("x");
  EXPECT_EQ(first.rfind("invalid JSON at line 1, column 1: ", 0), 0u) << first;
}

// Issue 52 item 7: at 50 images, column numbers two digits wide on 7-pixel cells are
// labelled every 5th, never running together.
TEST(MatrixLabelStep, LeavesRoomForEachLabel) {
  EXPECT_EQ(MatrixLabelStep(24, 13), 1u);
  EXPECT_EQ(MatrixLabelStep(7.2f, 13), 2u);
  EXPECT_EQ(MatrixLabelStep(7.2f, 14 + 6.5f), 5u);
  EXPECT_EQ(MatrixLabelStep(2, 20.5f), 20u);
  EXPECT_EQ(MatrixLabelStep(0.5f, 30), 100u);
}

}  // namespace
}  // namespace tessera::gui
