// Every way the loader refuses a plugin, each with its exact message, and the host
// never crashing on a broken plugin.

#include <gtest/gtest.h>

#include <fstream>

#include "plugin/plugin_registry.h"
#include "test_support.h"

namespace tessera {
namespace {

const std::filesystem::path kRoot = TESSERA_TEST_PLUGIN_ROOT;

std::filesystem::path File(const std::string& folder, const std::string& target) {
  return kRoot / folder / ("libtessera_test_" + target + ".so");
}

TEST(PluginLoader, LoadsAGoodPluginAndReadsItsInfo) {
  const PluginRecord record = InspectPluginFile(File("good", "good"));
  ASSERT_TRUE(record.usable()) << record.refusal;
  EXPECT_EQ(record.kind, "pair_selector");
  EXPECT_EQ(record.name, "consecutive");
  EXPECT_EQ(record.version, "1.2.3");
  EXPECT_EQ(record.description, "Each image with the next one");
  EXPECT_EQ(record.abi_version, kPluginAbiVersion);

  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
  auto selector = registry.Create<PairSelector>("pair_selector", "consecutive", {{"overlap", 2}},
                                                "pipeline.pair_selector");
  PairSelectionInput input;
  input.images.resize(3);
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(input).size(), 2u);
  EXPECT_EQ(testing::Unguarded(selector).EffectiveOptions(), nlohmann::json({{"overlap", 2}}));
  EXPECT_EQ(selector.name(), "consecutive");
}

TEST(PluginLoader, RefusesAFileThatWillNotOpen) {
  testing::TemporaryDir dir;
  const auto file = dir.path() / "libnot_a_library.so";
  // Longer than an ELF header, so the loader reads it and rejects its contents.
  std::ofstream(file) << std::string(200, '#') << "\nthis is a text file, not a shared object\n";
  const PluginRecord record = InspectPluginFile(file);
  EXPECT_FALSE(record.usable());
  EXPECT_EQ(record.refusal.rfind(file.string() + ": cannot open the library: ", 0), 0u)
      << record.refusal;
  EXPECT_NE(record.refusal.find("invalid ELF header"), std::string::npos) << record.refusal;
}

TEST(PluginLoader, RefusesAMissingInfoRecord) {
  const auto file = File("no_info", "no_info");
  EXPECT_EQ(InspectPluginFile(file).refusal,
            file.string() + ": not a Tessera plugin: it exports no 'tessera_plugin_info' record");
}

TEST(PluginLoader, RefusesAnotherAbiVersionNamingBothNumbers) {
  const auto file = File("wrong_abi", "wrong_abi");
  EXPECT_EQ(InspectPluginFile(file).refusal,
            file.string() + ": wrong plugin ABI version: got version 999, supported version is " +
                std::to_string(kPluginAbiVersion));
}

TEST(PluginLoader, RefusesAPluginBuiltAgainstAbiOne) {
  ASSERT_EQ(kPluginAbiVersion, 4u);
  const auto file = File("abi_one", "abi_one");
  EXPECT_EQ(InspectPluginFile(file).refusal,
            file.string() + ": wrong plugin ABI version: got version 1, supported version is 4");
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "abi_one"});
  EXPECT_TRUE(registry.NamesOfKind("pair_selector").empty());
}

TEST(PluginLoader, RefusesAnUnknownKindWithASuggestion) {
  const auto file = File("unknown_kind", "unknown_kind");
  EXPECT_EQ(
      InspectPluginFile(file).refusal,
      file.string() + ": plugin 'typo_kind' has unknown kind 'detectr'; did you mean 'detector'?");
}

TEST(PluginLoader, RefusesAMissingFactory) {
  const auto file = File("no_factory", "no_factory");
  EXPECT_EQ(InspectPluginFile(file).refusal,
            file.string() + ": plugin 'no_factory' exports no 'tessera_plugin_create' factory");
}

TEST(PluginLoader, RefusesADuplicateNameAndKeepsTheFirst) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "duplicate"});
  ASSERT_EQ(registry.records().size(), 2u);
  const auto& first = registry.records()[0];
  const auto& second = registry.records()[1];
  EXPECT_TRUE(first.usable());
  EXPECT_EQ(second.refusal, second.file.string() +
                                ": duplicate plugin name 'twin', already provided by " +
                                first.file.string());
  EXPECT_EQ(registry.NamesOfKind("pair_selector"), std::vector<std::string>{"twin"});
}

TEST(PluginLoader, ReportsAFactoryThatThrows) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "factory_throws"});
  const auto file = File("factory_throws", "factory_throws");
  try {
    registry.Create<PairSelector>("pair_selector", "throws", {}, "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              file.string() + ": plugin 'throws' failed to start: cannot reach the license server");
  }
}

TEST(PluginLoader, ReportsInvalidOptionsWithTheirJsonPath) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
  const auto file = File("good", "good");
  auto expect_error = [&](const nlohmann::json& options, const std::string& expected) {
    try {
      registry.Create<PairSelector>("pair_selector", "consecutive", options,
                                    "pipeline.pair_selector");
      FAIL() << "expected an error for " << options.dump();
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()), expected);
    }
  };
  expect_error({{"overlap", 0}},
               "pipeline.pair_selector.options.overlap: = 0 is out of range; must be in [1, 100] "
               "(plugin 'consecutive', " +
                   file.string() + ")");
  expect_error({{"overlpa", 2}},
               "pipeline.pair_selector.options.overlpa: unknown key; did you mean 'overlap'? "
               "(plugin 'consecutive', " +
                   file.string() + ")");
  expect_error({{"overlap", "two"}},
               "pipeline.pair_selector.options.overlap: expected an integer, got a string "
               "(plugin 'consecutive', " +
                   file.string() + ")");
  expect_error(nlohmann::json::array(),
               "pipeline.pair_selector.options: expected a JSON object, got an array "
               "(plugin 'consecutive', " +
                   file.string() + ")");
}

TEST(PluginLoader, RefusesAPluginOfAnotherKindForASlot) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
  try {
    registry.Create<Detector>("detector", "consecutive", {}, "pipeline.detector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), "pipeline.detector.plugin: plugin 'consecutive' (" +
                                             File("good", "good").string() +
                                             ") is a pair_selector, not a detector");
  }
}

TEST(PluginLoader, SuggestsTheClosestNameForAMisspeltPlugin) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
  try {
    registry.Create<PairSelector>("pair_selector", "consecutiv", {}, "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "pipeline.pair_selector.plugin: no pair_selector plugin 'consecutiv'; did you mean "
              "'consecutive'?");
  }
}

TEST(PluginLoader, DiscoveryListsRefusedFilesWithoutThrowing) {
  // All the broken cases at once: discovery must survive every one of them.
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::directory_iterator(kRoot))
    paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  const PluginRegistry registry = PluginRegistry::Discover(paths);
  size_t refused = 0;
  for (const auto& record : registry.records()) refused += record.usable() ? 0 : 1;
  // no_info, wrong_abi, abi_one, unknown_kind, no_factory, the second twin, and
  // crash_on_load, which the probe refused without this process ever loading it.
  EXPECT_EQ(refused, 7u);
  EXPECT_EQ(registry.NamesOfKind("pair_selector"),
            (std::vector<std::string>{"consecutive", "failing_pair_selector", "float_only",
                                      "throws", "twin"}));
}

TEST(PluginLoader, ObjectsOutliveTheRegistryThatMadeThem) {
  PluginInstance<PairSelector> selector;
  {
    const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
    selector = registry.Create<PairSelector>("pair_selector", "consecutive", {}, "p");
  }
  // The instance holds the library open: calling into it after the registry is gone is safe.
  PairSelectionInput input;
  input.images.resize(2);
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(input).size(), 1u);
}

}  // namespace
}  // namespace tessera
