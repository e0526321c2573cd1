// The manifest editor's form view as data: a manifest's plugin slots, each option's value
// against its description (the plugin's own reader's messages), and one option set or
// removed in the JSON's text in place.

#include "gui/option_form.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "gui/json_text_edit.h"

namespace tessera::gui {
namespace {

OptionDescription Integer(const std::string& name, int default_value, int min_value,
                          int max_value) {
  OptionDescription option;
  option.name = name;
  option.type = "integer";
  option.default_value = default_value;
  option.min_value = min_value;
  option.max_value = max_value;
  option.help = "an integer";
  return option;
}

OptionDescription Described(const std::string& name, const std::string& type,
                            nlohmann::json default_value, std::vector<std::string> choices = {}) {
  OptionDescription option;
  option.name = name;
  option.type = type;
  option.default_value = std::move(default_value);
  option.choices = std::move(choices);
  return option;
}

TEST(FormSlots, ListsEverySlotInPipelineOrderWithPathsAndOptions) {
  const nlohmann::json manifest = nlohmann::json::parse(R"({"pipeline": {
    "exporters": [{"plugin": "colmap_binary"}, {"plugin": "ply", "options": {"file": "a.ply"}}],
    "matcher": {"plugin": "flann", "options": {"ratio": 0.7}},
    "pair_selector": [{"plugin": "sequential"}, {"plugin": "exhaustive"}],
    "detector": {"plugin": "sift"},
    "bundle_adjuster": "ceres"}})");
  const std::vector<FormSlot> slots = FormSlots(manifest);
  std::vector<std::string> labels;
  for (const FormSlot& slot : slots) labels.push_back(slot.label);
  EXPECT_EQ(labels,
            (std::vector<std::string>{"detector", "pair_selector[0]", "pair_selector[1]", "matcher",
                                      "bundle_adjuster", "exporters[0]", "exporters[1]"}));
  EXPECT_EQ(slots[0].plugin, "sift");
  EXPECT_TRUE(slots[0].options.is_null());
  EXPECT_EQ(slots[2].json_path, "pipeline.pair_selector[1]");
  EXPECT_EQ(slots[2].steps, (std::vector<std::string>{"pipeline", "pair_selector", "1"}));
  EXPECT_EQ(slots[3].options, nlohmann::json({{"ratio", 0.7}}));
  EXPECT_EQ(slots[4].plugin, "");  // not an object: names no plugin
  EXPECT_EQ(slots[6].kind, "exporter");
  EXPECT_EQ(slots[6].plugin, "ply");
  EXPECT_TRUE(FormSlots(nlohmann::json::parse(R"({"threads": 2})")).empty());
}

TEST(OptionFields, MarksValuesOtherThanTheDefaultAndWhyOneIsRefused) {
  const std::vector<OptionDescription> described = {
      Integer("max_num_features", 8192, 1, 1000000), Described("root_sift", "boolean", true),
      Described("loss", "string", "huber", {"huber", "cauchy"}), Described("sigma", "number", 1.6)};
  const nlohmann::json written = {
      {"max_num_features", 0}, {"root_sift", true}, {"loss", "cauhcy"}, {"sigma", 2}};
  const std::vector<OptionField> fields = OptionFields(described, written);
  ASSERT_EQ(fields.size(), 4u);
  EXPECT_TRUE(fields[0].written);
  EXPECT_TRUE(fields[0].differs);
  EXPECT_EQ(fields[0].problem, "= 0 is out of range [1, 1000000]");
  EXPECT_TRUE(fields[1].written);
  EXPECT_FALSE(fields[1].differs);  // written, but the default
  EXPECT_EQ(fields[1].problem, "");
  EXPECT_EQ(fields[2].problem, "'cauhcy' is not one of 'huber', 'cauchy'; did you mean 'cauchy'?");
  EXPECT_EQ(fields[3].value, 2);
  EXPECT_TRUE(fields[3].differs);
  EXPECT_EQ(fields[3].problem, "");  // an integer is a number
  // Nothing written: every default, nothing marked.
  for (const OptionField& field : OptionFields(described, nullptr)) {
    EXPECT_FALSE(field.written);
    EXPECT_FALSE(field.differs);
    EXPECT_EQ(field.value, field.option.default_value);
  }
}

TEST(OptionValueProblem, SaysWhatThePluginsReaderSays) {
  const OptionDescription count = Integer("n", 3, 1, 10);
  EXPECT_EQ(OptionValueProblem(count, 10), "");
  EXPECT_EQ(OptionValueProblem(count, 11), "= 11 is out of range [1, 10]");
  EXPECT_EQ(OptionValueProblem(count, 2.5), "expected an integer, got a number");
  EXPECT_EQ(OptionValueProblem(count, "12a"), "expected an integer, got a string");
  EXPECT_EQ(OptionValueProblem(Described("b", "boolean", false), "yes"),
            "expected true or false, got a string");
  EXPECT_EQ(OptionValueProblem(Described("p", "path", "model.ply"), "../x.ply"),
            "'../x.ply' leaves the output folder (\"..\"); it must be a relative path inside "
            "the output folder");
  EXPECT_EQ(OptionValueProblem(Described("j", "json", nullptr), nlohmann::json::array()), "");
  OptionDescription unbounded = Described("x", "number", 0.5);
  unbounded.min_value = 0.0;  // max null: unbounded
  EXPECT_EQ(OptionValueProblem(unbounded, 1e300), "");
  EXPECT_NE(OptionValueProblem(unbounded, -1), "");
}

TEST(UnknownOptions, NamesTheClosestKnownKey) {
  const std::vector<OptionDescription> described = {Integer("max_num_features", 8192, 1, 1000000)};
  const auto unknown =
      UnknownOptions(described, {{"max_num_feature", 5}, {"max_num_features", 5}, {"zzz", 1}});
  ASSERT_EQ(unknown.size(), 2u);
  EXPECT_EQ(unknown[0].first, "max_num_feature");
  EXPECT_EQ(unknown[0].second, "unknown key; did you mean 'max_num_features'?");
  EXPECT_EQ(unknown[1].second, "unknown key of this plugin");
}

TEST(IsDefaultValue, ComparesNumbersByValue) {
  EXPECT_TRUE(IsDefaultValue(Described("x", "number", 10.0), 10));
  EXPECT_TRUE(IsDefaultValue(Integer("n", 8192, 1, 100000), 8192));
  EXPECT_FALSE(IsDefaultValue(Integer("n", 8192, 1, 100000), 8193));
  EXPECT_FALSE(IsDefaultValue(Described("b", "boolean", true), "true"));
  EXPECT_EQ(OptionValueText("huber"), "'huber'");
  EXPECT_EQ(OptionValueText(0.8), "0.8");
}

TEST(SetOptionInText, ReplacesAddsAndRemovesOneOptionKeepingTheRest) {
  const std::string text = R"({
  "pipeline": {
    "detector": {"plugin": "sift", "options": {"max_num_features": 12000, "root_sift": true}},
    "exporters": [{"plugin": "colmap_binary"}, {"plugin": "ply"}]
  }
})";
  const std::vector<std::string> detector = {"pipeline", "detector"};
  std::string replaced = text;
  replaced.replace(replaced.find("12000"), 5, "20000");
  EXPECT_EQ(SetOptionInText(text, detector, "max_num_features", nlohmann::json(20000)), replaced);
  std::string added = text;
  added.replace(added.find("true}}"), 4, "true, \"sigma\": 2.5");
  EXPECT_EQ(SetOptionInText(text, detector, "sigma", nlohmann::json(2.5)), added);
  std::string removed = text;
  removed.replace(removed.find("\"max_num_features\": 12000, "), 27, "");
  EXPECT_EQ(SetOptionInText(text, detector, "max_num_features", std::nullopt), removed);
  // The last option removed: the options object goes with it.
  const std::optional<std::string> none =
      SetOptionInText(removed, detector, "root_sift", std::nullopt);
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(nlohmann::json::parse(*none)["pipeline"]["detector"],
            nlohmann::json({{"plugin", "sift"}}));
  // An exporter in the list, without options: they are added after its last member.
  std::string exporter = text;
  exporter.replace(exporter.find("\"ply\"}"), 6, "\"ply\", \"options\": {\"file\": \"m.ply\"}}");
  EXPECT_EQ(SetOptionInText(text, {"pipeline", "exporters", "1"}, "file", nlohmann::json("m.ply")),
            exporter);
  // Nothing to remove: the text as it was.
  EXPECT_EQ(SetOptionInText(text, {"pipeline", "exporters", "0"}, "file", std::nullopt), text);
  // No such slot, or options that are not an object: not edited in place.
  EXPECT_FALSE(SetOptionInText(text, {"pipeline", "exporters", "2"}, "file", nlohmann::json(1)));
  EXPECT_FALSE(SetOptionInText(text, {"pipeline", "matcher"}, "ratio", nlohmann::json(1)));
  EXPECT_FALSE(SetOptionInText(R"({"pipeline": {"detector": {"options": []}}})", detector, "x",
                               nlohmann::json(1)));
}

}  // namespace
}  // namespace tessera::gui
