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

// Issue 52 item 9: the options a new plugin does not take are dropped in place, each
// with its comma; the rest of the text is as it was.
TEST(RemoveOptionsInText, DropsOnlyTheKeysNamed) {
  const std::string text = R"({
  "pipeline": {
    "mapper": {"plugin": "incremental", "options": {
      "ba_refine_principal_point": true,
      "use_gps_prior": false,
      "init_min_num_inliers": 50
    }},
    "detector": {"plugin": "orb", "options": {"max_num_features": 500}}
  }
})";
  const std::string first_and_last = R"({
  "pipeline": {
    "mapper": {"plugin": "incremental", "options": {
      "use_gps_prior": false
    }},
    "detector": {"plugin": "orb", "options": {"max_num_features": 500}}
  }
})";
  EXPECT_EQ(
      RemoveOptionsInText(text, "mapper", {"ba_refine_principal_point", "init_min_num_inliers"}),
      first_and_last);
  const std::optional<std::string> none =
      RemoveOptionsInText(text, "detector", {"max_num_features"});
  ASSERT_TRUE(none.has_value());
  EXPECT_NE(none->find(R"("detector": {"plugin": "orb", "options": {}})"), std::string::npos)
      << *none;
  const size_t detector = text.find("\"detector\"");
  EXPECT_EQ(none->substr(0, detector), text.substr(0, detector));  // the mapper as it was
  // A key not there: the text unchanged; no options object: nothing to edit.
  EXPECT_EQ(RemoveOptionsInText(text, "mapper", {"absent"}), text);
  EXPECT_EQ(
      RemoveOptionsInText(R"({"pipeline": {"mapper": {"plugin": "global"}}})", "mapper", {"a"}),
      std::nullopt);
  EXPECT_EQ(RemoveOptionsInText(R"({"pipeline": {"mapper": {"options": {"a": 1,)", "mapper", {"a"}),
            std::nullopt);
}

}  // namespace
}  // namespace tessera::gui
