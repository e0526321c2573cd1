// Issue 52 item 9: choosing a slot's plugin edits the manifest's text in place: the
// other slots' text (order, spacing, options) and this slot's options are kept.

#include "gui/json_text_edit.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tessera::gui {
namespace {

TEST(SetPluginInText, ReplacesOnlyThePluginsName) {
  const std::string text = R"({
  "threads": 2,
  "pipeline": {
    "mapper": {"plugin": "incremental", "options": {"ba_refine_principal_point": true}},
    "detector": {"options": {"max_num_features": 500}, "plugin": "orb"}
  }
})";
  std::string expected = text;
  expected.replace(expected.find("\"incremental\""), 13, "\"global\"");
  EXPECT_EQ(SetPluginInText(text, "mapper", "global"), expected);
  std::string sift = text;
  sift.replace(sift.find("\"orb\""), 5, "\"sift\"");
  EXPECT_EQ(SetPluginInText(text, "detector", "sift"), sift);
}

TEST(SetPluginInText, AddsAnAbsentSlotOrPluginAndReplacesAList) {
  const std::string text = R"({"pipeline": {"matcher": {"options": {"ratio": 0.8}},
    "pair_selector": [{"plugin": "sequential"}, {"plugin": "retrieval"}]}})";
  const std::optional<std::string> added = SetPluginInText(text, "detector", "orb");
  ASSERT_TRUE(added.has_value());
  EXPECT_EQ(*added,
            R"({"pipeline": {"detector": {"plugin": "orb"}, "matcher": {"options": {"ratio": 0.8}},
    "pair_selector": [{"plugin": "sequential"}, {"plugin": "retrieval"}]}})");
  const nlohmann::json matcher =
      nlohmann::json::parse(*SetPluginInText(text, "matcher", "flann"))["pipeline"]["matcher"];
  EXPECT_EQ(matcher, nlohmann::json::parse(R"({"plugin": "flann", "options": {"ratio": 0.8}})"));
  const nlohmann::json pairs = nlohmann::json::parse(
      *SetPluginInText(text, "pair_selector", "exhaustive"))["pipeline"]["pair_selector"];
  EXPECT_EQ(pairs, nlohmann::json::parse(R"({"plugin": "exhaustive"})"));
  EXPECT_EQ(SetPluginInText(R"({"pipeline": {}})", "mapper", "global"),
            R"({"pipeline": {"mapper": {"plugin": "global"}}})");
  // Nothing to edit in place: the caller writes the JSON anew.
  EXPECT_EQ(SetPluginInText(R"({"threads": 1})", "mapper", "global"), std::nullopt);
  EXPECT_EQ(SetPluginInText("[1, 2]", "mapper", "global"), std::nullopt);
}

}  // namespace
}  // namespace tessera::gui
