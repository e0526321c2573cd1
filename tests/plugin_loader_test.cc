// Every way the loader refuses a plugin, each with its exact message, and the host
// never crashing on a broken plugin.

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <sstream>

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
  ASSERT_EQ(kPluginAbiVersion, 12u);
  const auto file = File("abi_one", "abi_one");
  EXPECT_EQ(InspectPluginFile(file).refusal,
            file.string() + ": wrong plugin ABI version: got version 1, supported version is 12");
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "abi_one"});
  EXPECT_TRUE(registry.NamesOfKind("pair_selector").empty());
}

// Built with -D_GLIBCXX_USE_CXX11_ABI=0, it used to be listed as usable and then fail
// with std::bad_alloc naming no plugin.
TEST(PluginLoader, RefusesAPluginBuiltWithAnotherStringAbiNamingTheSetting) {
  const auto file = File("old_string_abi", "old_string_abi");
  EXPECT_EQ(InspectPluginFile(file).refusal,
            file.string() +
                ": plugin 'old_string_abi' built with -D_GLIBCXX_USE_CXX11_ABI=0 (the C++ "
                "library's string ABI), the host with 1; a plugin must be built as the host is, "
                "since C++ objects cross the boundary");
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "old_string_abi"});
  EXPECT_TRUE(registry.NamesOfKind("pair_selector").empty());
}

TEST(PluginLoader, BuildMismatchNamesTheFirstSettingThatDiffers) {
  const TesseraBuildRecord host = HostBuildRecord();
  EXPECT_EQ(BuildMismatch(host, host), "");
  TesseraBuildRecord other = host;
  other.compiler = host.compiler == 1 ? 2 : 1;
  other.compiler_major = 99;
  EXPECT_EQ(BuildMismatch(other, host)
                .rfind(std::string("built with ") + (other.compiler == 1 ? "GCC 99" : "Clang 99") +
                           ", the host with ",
                       0),
            0u)
      << BuildMismatch(other, host);
  other = host;
  other.sizeof_json += 8;
  EXPECT_EQ(BuildMismatch(other, host)
                .rfind("built with a nlohmann::json of " + std::to_string(host.sizeof_json + 8) +
                           " bytes, the host's has " + std::to_string(host.sizeof_json),
                       0),
            0u)
      << BuildMismatch(other, host);
  other = host;
  other.standard_library = 2;
  other.string_abi = 0;
  EXPECT_EQ(BuildMismatch(other, host).rfind("built against libc++, the host against libstdc++", 0),
            0u)
      << BuildMismatch(other, host);
}

// A plugin's Logger writes through the host's log, named, and honours -q.
TEST(PluginLog, LinesGoToTheHostsLogWithThePluginsNameAndSubject) {
  std::ostringstream out;
  const auto previous = spdlog::default_logger();
  const auto capture = std::make_shared<spdlog::logger>(
      "capture", std::make_shared<spdlog::sinks::ostream_sink_mt>(out));
  capture->set_pattern("[%l] %v");
  capture->set_level(spdlog::level::info);
  spdlog::set_default_logger(capture);
  const LogSink sink = PluginLogSink("sift");
  sink(LogLevel::kInfo, "outside a call");
  {
    const PluginCallScope scope("sift", PluginStage::kDetect, ImageSubject("a.jpg"));
    sink(LogLevel::kWarning, "inside");
    sink(LogLevel::kDebug, "debug is for -v");
  }
  capture->set_level(spdlog::level::warn);  // -q
  sink(LogLevel::kInfo, "quiet");
  sink(LogLevel::kWarning, "still shown");
  spdlog::set_default_logger(previous);
  EXPECT_EQ(out.str(),
            "[info] sift: outside a call\n[warning] sift (image a.jpg): inside\n"
            "[warning] sift: still shown\n");
  // The registry connects every plugin it makes.
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
  auto selector = registry.Create<PairSelector>("pair_selector", "consecutive", {}, "p");
  out.str("");
  spdlog::set_default_logger(capture);
  testing::Unguarded(selector).log().Warn("from the plugin");
  spdlog::set_default_logger(previous);
  EXPECT_EQ(out.str(), "[warning] consecutive: from the plugin\n");
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

// A constructor's std::runtime_error is the plugin's failure, not bad input: exit code 1,
// as for a call that throws it (docs/plugin_authors_guide.md).
TEST(PluginLoader, ReportsAFactoryThatThrows) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "factory_throws"});
  const auto file = File("factory_throws", "factory_throws");
  try {
    registry.Create<PairSelector>("pair_selector", "throws", {}, "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const PluginError& error) {
    EXPECT_EQ(std::string(error.what()), "plugin 'throws' failed while starting from " +
                                             file.string() + ": cannot reach the license server");
    EXPECT_FALSE(error.input_error());
  }
}

// The message of the InputError that Create of the wrapping_a bundle adjuster with
// `options` throws ("" when none).
std::string WrappingError(const nlohmann::json& options) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "wrapping"});
  try {
    registry.Create<BundleAdjuster>("bundle_adjuster", "wrapping_a", options,
                                    "pipeline.bundle_adjuster");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(PluginLoader, APluginThatAsksTheHostForItselfIsRefusedNamingTheChain) {
  const std::string file = File("wrapping", "wrapping_a").string();
  EXPECT_EQ(WrappingError({{"wrap", "wrapping_a"}, {"options", {{"wrap", "wrapping_a"}}}}),
            "pipeline.bundle_adjuster: plugin creation loops: 'wrapping_a' -> 'wrapping_a': plugin "
            "'wrapping_a' asks the host for the bundle_adjuster 'wrapping_a', which is already "
            "being made or called (" +
                file + "); a plugin cannot wrap itself");
  // A -> B -> A.
  EXPECT_EQ(WrappingError({{"wrap", "wrapping_b"}, {"options", {{"wrap", "wrapping_a"}}}}),
            "pipeline.bundle_adjuster: plugin creation loops: 'wrapping_a' -> 'wrapping_b' -> "
            "'wrapping_a': plugin 'wrapping_b' asks the host for the bundle_adjuster "
            "'wrapping_a', which is already being made or called (" +
                file + "); a plugin cannot wrap itself");
  // A wraps B, which wraps nothing: no loop.
  EXPECT_EQ(WrappingError({{"wrap", "wrapping_b"}}), "");
}

// The same loop made during a call (Adjust asks the host for itself): refused, not a
// stack overflow.
TEST(PluginLoader, APluginThatAsksForItselfDuringACallIsRefusedNamingTheChain) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "wrapping"});
  const auto adjuster =
      registry.Create<BundleAdjuster>("bundle_adjuster", "wrapping_a",
                                      {{"wrap", "wrapping_a"},
                                       {"lazy", true},
                                       {"options", {{"wrap", "wrapping_a"}, {"lazy", true}}}},
                                      "pipeline.bundle_adjuster");
  Reconstruction reconstruction;
  try {
    adjuster.Call(PluginStage::kAdjust, "a bundle", [&](const BundleAdjuster& plugin) {
      return plugin.Adjust(BundleAdjustmentConfig(), &reconstruction);
    });
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("plugin creation loops: 'wrapping_a' -> 'wrapping_a': "
                        "plugin 'wrapping_a' asks the host for the bundle_adjuster 'wrapping_a'"),
              std::string::npos)
        << error.what();
  }
}

TEST(PluginLoader, OptionErrorsOfAWrappedPluginNameTheirPathInTheManifest) {
  const std::string file_b = File("wrapping", "wrapping_b").string();
  EXPECT_EQ(WrappingError({{"wrap", "wrapping_b"}, {"options", {{"levle", 2}}}}),
            "pipeline.bundle_adjuster.options.options.levle: unknown key; did you mean "
            "'level'? (plugin 'wrapping_b', " +
                file_b + ", made by plugin 'wrapping_a')");
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
               "pipeline.pair_selector.options.overlap = 0 is out of range [1, 100] "
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

TEST(PluginLoader, RefusesAPluginOfAnotherKindAsTheMapper) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
  try {
    registry.Create<Mapper>("mapper", "consecutive", {}, "pipeline.mapper");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), "pipeline.mapper.plugin: plugin 'consecutive' (" +
                                             File("good", "good").string() +
                                             ") is a pair_selector, not a mapper");
  }
}

TEST(PluginLoader, OptionErrorsNameTheOptionsPathTheSlotGives) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "good"});
  try {
    registry.Create<PairSelector>("pair_selector", "consecutive", {{"overlap", 0}},
                                  "pipeline.pair_selector", "legacy");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("legacy.overlap = 0 is out of range", 0), 0u)
        << error.what();
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
  // no_info, wrong_abi, abi_one, old_string_abi, unknown_kind, no_factory, the second
  // twin, and crash_on_load and term_on_load, which the probe refused without this process
  // ever loading them.
  EXPECT_EQ(refused, 9u);
  EXPECT_EQ(registry.NamesOfKind("pair_selector"),
            (std::vector<std::string>{"bad_description", "consecutive", "describer_throws",
                                      "failing_pair_selector", "float_only", "throws", "twin"}));
}

// A probe child ended by SIGTERM (or SIGINT: an interrupt reaching it) was "crashes on
// load (SIGTERM)": an interrupt is never called a crash of the plugin.
TEST(PluginLoader, AProbeChildEndedByAnInterruptIsNotACrash) {
  const PluginRegistry registry = PluginRegistry::Discover({kRoot / "term_on_load"});
  ASSERT_EQ(registry.records().size(), 1u);
  const PluginRecord& record = registry.records().front();
  EXPECT_FALSE(record.usable());
  EXPECT_NE(record.refusal.find("not inspected: the plugin scan was interrupted (SIGTERM)"),
            std::string::npos)
      << record.refusal;
  EXPECT_EQ(record.refusal.find("crash"), std::string::npos) << record.refusal;
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
