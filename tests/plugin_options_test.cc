// Plugins' option descriptions (tessera/option_list.h): checked as input when read, and,
// for every bundled plugin, the same options, defaults, ranges and choices that the
// plugin reads, round-tripped through `tessera plugins NAME --json`.

#include <gtest/gtest.h>

#include <map>

#include "plugin/option_descriptions.h"
#include "plugin/plugin_registry.h"
#include "test_support.h"

namespace tessera {
namespace {

const std::filesystem::path kTestPluginRoot = TESSERA_TEST_PLUGIN_ROOT;
const std::filesystem::path kBundledPlugins = TESSERA_TEST_BUNDLED_PLUGIN_DIR;

testing::CommandResult RunTessera(const std::string& arguments, const std::string& environment) {
  return testing::RunCommand(TESSERA_TEST_EXECUTABLE, arguments, environment);
}

// The message of the InputError that `fn` throws, or "" when it throws none.
template <typename Fn>
std::string InputErrorOf(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

nlohmann::json Option(nlohmann::json fields) {
  nlohmann::json option = {{"name", "ratio"}, {"type", "number"}, {"default", 0.8},
                           {"min", 0},        {"max", 1},         {"help", "Lowe's ratio"}};
  if (!fields.is_null()) option.update(fields);
  return option;
}

std::string ParseError(const nlohmann::json& option) {
  return InputErrorOf([&] { ParseOptionDescriptions(nlohmann::json::array({option}), "who"); });
}

TEST(OptionDescriptions, AWellFormedDescriptionRoundTrips) {
  const nlohmann::json described = nlohmann::json::array(
      {Option({}),
       {{"name", "loss"},
        {"type", "string"},
        {"default", "huber"},
        {"choices", {"huber", "cauchy"}},
        {"help", "robust loss"}},
       {{"name", "folder"}, {"type", "path"}, {"default", "out"}, {"help", "where"}},
       {{"name", "count"},
        {"type", "integer"},
        {"default", 3},
        {"min", nullptr},
        {"max", nullptr},
        {"help", ""}},
       {{"name", "share"},
        {"type", "number"},
        {"default", 0.5},
        {"min", 0},
        {"max", 1},
        {"min_exclusive", true},
        {"help", "above 0"}}});
  const std::vector<OptionDescription> options = ParseOptionDescriptions(described, "who");
  ASSERT_EQ(options.size(), 5u);
  nlohmann::json again = nlohmann::json::array();
  for (const OptionDescription& option : options) again.push_back(option.ToJson());
  EXPECT_EQ(again, described);
  EXPECT_EQ(OptionRangeText(options[0]), "[0, 1]");
  EXPECT_EQ(OptionRangeText(options[1]), "'huber', 'cauchy'");
  EXPECT_EQ(OptionRangeText(options[3]), "");
  EXPECT_EQ(OptionRangeText(options[4]), "(0, 1]");
}

TEST(OptionDescriptions, EachFaultIsOneLineNamingTheOption) {
  EXPECT_EQ(ParseError(Option({{"default", 1.5}})),
            "who: options[0] ('ratio'): the default 1.5 is out of its range [0, 1]");
  EXPECT_EQ(ParseError(Option({{"type", "numbr"}})),
            "who: options[0] ('ratio'): unknown type 'numbr'; did you mean 'number'?");
  EXPECT_EQ(ParseError(Option({{"default", "0.8"}})),
            "who: options[0] ('ratio'): the default \"0.8\" is not of type number");
  EXPECT_EQ(ParseError(Option({{"default", 0}, {"min_exclusive", true}})),
            "who: options[0] ('ratio'): the default 0 is out of its range (0, 1]");
  EXPECT_EQ(ParseError(Option({{"min", nullptr}, {"min_exclusive", true}})),
            "who: options[0] ('ratio'): 'min_exclusive' without 'min'");
  EXPECT_EQ(ParseError(Option({{"min", 2}})),
            "who: options[0] ('ratio'): 'min' 2 is above 'max' 1");
  EXPECT_EQ(ParseError(Option({{"helpp", "x"}})),
            "who: options[0] ('ratio'): unknown key 'helpp'; did you mean 'help'?");
  EXPECT_EQ(ParseError(Option({{"name", ""}})),
            "who: options[0]: 'name' must be a non-empty string");
  EXPECT_EQ(
      ParseError({{"name", "loss"}, {"type", "string"}, {"default", "l2"}, {"choices", {"huber"}}}),
      "who: options[0] ('loss'): the default 'l2' is not one of its choices");
  EXPECT_EQ(ParseError({{"name", "flag"}, {"type", "boolean"}, {"default", true}, {"min", 0}}),
            "who: options[0] ('flag'): 'min' is for numbers only");
  EXPECT_EQ(InputErrorOf([] {
              ParseOptionDescriptions(nlohmann::json::array({Option({}), Option({})}), "who");
            }),
            "who: options[1]: the option 'ratio' is described twice");
  EXPECT_EQ(InputErrorOf([] { ParseOptionDescriptions(nlohmann::json::object(), "who"); }),
            "who: its option description is an object, not an array");
}

TEST(OptionDescriptions, MarkdownEscapesTheCellSeparator) {
  EXPECT_EQ(OptionDescriptionsMarkdown({}), "It takes no options.\n");
  OptionDescription option;
  option.name = "contrast";
  option.type = "number";
  option.default_value = 0.02;
  option.min_value = 0;
  option.help = "kept when |D| is large";
  EXPECT_EQ(OptionDescriptionsMarkdown({option}),
            "| option | type | default | range or choices | meaning |\n"
            "| --- | --- | --- | --- | --- |\n"
            "| `contrast` | number | `0.02` | >= 0 | kept when \\|D\\| is large |\n");
}

TEST(PluginOptions, APluginThatDescribesNothingIsListedAsSuch) {
  const PluginRegistry registry = PluginRegistry::Discover({kTestPluginRoot / "good"});
  const PluginRecord& record = registry.Find("consecutive");
  EXPECT_FALSE(record.describes_options);
  EXPECT_FALSE(registry.DescribeOptions(record).has_value());

  const std::string path = "TESSERA_PLUGIN_PATH=" + (kTestPluginRoot / "good").string();
  const auto text = RunTessera("plugins consecutive", path);
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_NE(text.output.find("plugin 'consecutive' (" + record.file.string() +
                             ") does not describe its options"),
            std::string::npos)
      << text.output;
  const auto json = RunTessera("plugins consecutive --json", path);
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const nlohmann::json parsed = nlohmann::json::parse(json.output);
  EXPECT_TRUE(parsed["options"].is_null());
  EXPECT_FALSE(parsed["describes_options"].get<bool>());
  const auto markdown = RunTessera("plugins consecutive --markdown", path);
  EXPECT_EQ(markdown.exit_code, 2) << markdown.output;
}

TEST(PluginOptions, AWrongDescriptionIsAnInputErrorNamingThePlugin) {
  const PluginRegistry registry = PluginRegistry::Discover({kTestPluginRoot / "described"});
  const PluginRecord& wrong = registry.Find("bad_description");
  EXPECT_EQ(InputErrorOf([&] { registry.DescribeOptions(wrong); }),
            "plugin 'bad_description' (" + wrong.file.string() +
                "): options[0] ('step'): the default 0 is out of its range [1, 9]");
  const PluginRecord& throwing = registry.Find("describer_throws");
  EXPECT_EQ(InputErrorOf([&] { registry.DescribeOptions(throwing); }),
            "plugin 'describer_throws' (" + throwing.file.string() +
                "): describing its options failed: no description today");

  const std::string path = "TESSERA_PLUGIN_PATH=" + (kTestPluginRoot / "described").string();
  const auto result = RunTessera("plugins bad_description", path);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("('step'): the default 0 is out of its range"), std::string::npos)
      << result.output;
  const auto unknown = RunTessera("plugins bad_descripton", path);
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("no plugin 'bad_descripton' on the plugin path; did you mean "
                                "'bad_description'?"),
            std::string::npos)
      << unknown.output;
}

// A value just outside a numeric option's range, or null when it has none on that side.
nlohmann::json Outside(const OptionDescription& option, bool below) {
  const nlohmann::json& bound = below ? option.min_value : option.max_value;
  if (bound.is_null()) return nullptr;
  if (below && option.min_exclusive) return bound;  // the open bound itself
  const double step =
      option.type == "integer" ? 1.0 : std::max(1e-3, std::abs(bound.get<double>()));
  const double value = bound.get<double>() + (below ? -step : step);
  if (option.type == "integer") return static_cast<int64_t>(value);
  return value;
}

// The plugin accepts `options`, or refuses them with an InputError whose text is returned.
std::string Refusal(const PluginRegistry& registry, const PluginRecord& record,
                    const nlohmann::json& options) {
  return InputErrorOf(
      [&] { registry.Create<Plugin>(record.kind, record.name, options, "pipeline.slot"); });
}

// Each bundled plugin's description agrees with what the plugin reads: every option it
// records with no options given is described with that default; each described default
// is accepted on its own; a value outside a described range or choice is refused naming
// the option.
void CheckDescriptionAgainstPlugin(const PluginRegistry& registry, const PluginRecord& record,
                                   const std::vector<OptionDescription>& options) {
  const nlohmann::json effective = registry.DefaultOptions(record);
  std::map<std::string, const OptionDescription*> by_name;
  for (const OptionDescription& option : options) by_name[option.name] = &option;
  for (const auto& [key, value] : effective.items()) {
    ASSERT_TRUE(by_name.count(key)) << record.name << ": '" << key << "' is not described";
    EXPECT_EQ(by_name[key]->default_value, value) << record.name << "." << key;
  }
  for (const OptionDescription& option : options) {
    SCOPED_TRACE(record.name + "." + option.name);
    EXPECT_FALSE(option.help.empty());
    const std::string alone = Refusal(registry, record, {{option.name, option.default_value}});
    if (!alone.empty()) {
      // Only an option that depends on another may be refused on its own, and its
      // refusal names the other.
      bool names_another = false;
      for (const OptionDescription& other : options) {
        names_another |= other.name != option.name && alone.find(other.name) != std::string::npos;
      }
      EXPECT_TRUE(names_another) << alone;
    }
    for (const bool below : {true, false}) {
      const nlohmann::json outside = Outside(option, below);
      if (outside.is_null()) continue;
      EXPECT_NE(Refusal(registry, record, {{option.name, outside}}).find(option.name),
                std::string::npos)
          << outside.dump() << " was not refused";
    }
    if (!option.choices.empty()) {
      EXPECT_NE(Refusal(registry, record, {{option.name, "no_such_choice"}}).find(option.name),
                std::string::npos);
    }
  }
}

TEST(PluginOptions, EveryBundledPluginDescribesWhatItReads) {
  const PluginRegistry registry = PluginRegistry::Discover({kBundledPlugins});
  size_t checked = 0;
  for (const PluginRecord& record : registry.records()) {
    ASSERT_TRUE(record.usable()) << record.refusal;
    SCOPED_TRACE(record.name);
    ASSERT_TRUE(record.describes_options);
    const std::optional<std::vector<OptionDescription>> options = registry.DescribeOptions(record);
    ASSERT_TRUE(options.has_value());
    CheckDescriptionAgainstPlugin(registry, record, *options);

    // Round trip: what `tessera plugins NAME --json` prints is the description.
    const auto printed = RunTessera("plugins " + record.name + " --json",
                                    "TESSERA_PLUGIN_PATH=" + kBundledPlugins.string());
    ASSERT_EQ(printed.exit_code, 0) << printed.output;
    const nlohmann::json json = nlohmann::json::parse(printed.output);
    EXPECT_EQ(json["name"], record.name);
    EXPECT_EQ(json["kind"], record.kind);
    const std::vector<OptionDescription> again =
        ParseOptionDescriptions(json["options"], "printed");
    ASSERT_EQ(again.size(), options->size());
    for (size_t i = 0; i < again.size(); ++i) EXPECT_EQ(again[i].ToJson(), (*options)[i].ToJson());
    ++checked;
  }
  EXPECT_GE(checked, 18u);
}

// One name, one meaning: an option that two plugins both take is stated with the same type
// and range in each, so that a user reading either reads the same thing. The names below
// are the exceptions, each for its reason; any other difference fails.
TEST(PluginOptions, AnOptionNamedInTwoPlacesHasOneTypeAndRange) {
  const std::map<std::string, std::string> different_meanings = {
      {"edge_threshold", "OpenCV's names: SIFT's ratio of curvatures, ORB's border in pixels"},
      {"max_distance", "spatial's metres between GPS positions, the matchers' descriptor distance"},
      {"seed",
       "retrieval's is faiss's k-means seed (an int); the global mapper's is replaced by "
       "the run's seed"}};
  const PluginRegistry registry = PluginRegistry::Discover({kBundledPlugins});
  std::map<std::string, std::pair<std::string, nlohmann::json>> first_seen;
  size_t shared = 0;
  for (const PluginRecord& record : registry.records()) {
    if (!record.usable() || !record.describes_options) continue;
    const std::optional<std::vector<OptionDescription>> described =
        registry.DescribeOptions(record);
    for (const OptionDescription& option : *described) {
      const nlohmann::json stated = {option.type, option.min_value, option.max_value,
                                     option.min_exclusive, option.choices};
      const auto [it, inserted] =
          first_seen.emplace(option.name, std::make_pair(record.name, stated));
      if (inserted || different_meanings.count(option.name)) continue;
      ++shared;
      EXPECT_EQ(it->second.second, stated)
          << "'" << option.name << "' is " << stated.dump() << " in " << record.name << " but "
          << it->second.second.dump() << " in " << it->second.first;
    }
  }
  // ratio, cross_check, max_num_features, min_num_matches, ...: the test compares something.
  EXPECT_GE(shared, 10u);
  for (const auto& [name, reason] : different_meanings) {
    EXPECT_TRUE(first_seen.count(name)) << name << " is no longer taken: drop it from the list";
  }
}

}  // namespace
}  // namespace tessera
