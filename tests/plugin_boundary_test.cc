// Plugins can never take the host down: every kind of exception from every plugin kind
// becomes one host-side error naming the plugin, the stage and the image or pair; a
// crash in a plugin ends the run with one line naming it and exit code 4, the next run
// reports it and resumes, and an image that crashed a detector twice is skipped; a
// library that crashes on load is refused, and the other plugins are still listed.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "plugin/bundle_adjuster_guard.h"
#include "plugin/plugin_crash_log.h"
#include "plugin/plugin_registry.h"
#include "tessera/io/file_io.h"
#include "test_support.h"

namespace tessera {
namespace {

const std::filesystem::path kRoot = TESSERA_TEST_PLUGIN_ROOT;
const std::filesystem::path kFailing = kRoot / "failing";

struct Expected {
  std::string how;
  std::string message;
  bool input_error;
};

const std::vector<Expected>& Failures() {
  static const std::vector<Expected> failures = {
      {"input_error", "this input is not acceptable", true},
      {"option_error", "threshold: must be positive", true},
      {"runtime_error", "out of detector memory", false},
      {"custom", "the license has expired", false},
      {"non_std", "it threw an exception that is not a std::exception", false}};
  return failures;
}

// Loads the failing plugin of `kind`, makes it fail `how`, calls it the way the host's
// call site does, and lets the error leave the scope in which the registry and the
// plugin (and so its library) are destroyed.
void CallFailingPlugin(const std::string& kind, const std::string& how) {
  const PluginRegistry registry = PluginRegistry::Discover({kFailing});
  const nlohmann::json options = {{"fail", how}};
  const std::string name = "failing_" + kind;
  if (kind == "detector") {
    const auto detector = registry.Create<Detector>(kind, name, options, "pipeline.detector");
    std::vector<uint8_t> pixels(16 * 16, 128);
    ImageView view;
    view.width = view.height = 16;
    view.stride = 16;
    view.data = pixels.data();
    detector.Call(PluginStage::kDetect, ImageSubject("a.png"),
                  [&](const Detector& plugin) { return plugin.Detect(view); });
  } else if (kind == "matcher") {
    const auto matcher = registry.Create<Matcher>(kind, name, options, "pipeline.matcher");
    matcher.Call(PluginStage::kMatch, PairSubject("a.png", "b.png"),
                 [&](const Matcher& plugin) { return plugin.Match({}, {}); });
  } else if (kind == "pair_selector") {
    const auto selector =
        registry.Create<PairSelector>(kind, name, options, "pipeline.pair_selector");
    PairSelectionInput input;
    input.images.resize(3);
    selector.Call(PluginStage::kSelectPairs, "3 images",
                  [&](const PairSelector& plugin) { return plugin.SelectPairs(input); });
  } else if (kind == "mapper") {
    const auto mapper = registry.Create<Mapper>(kind, name, options, "pipeline.mapper");
    MapperInput input;
    mapper.Call(PluginStage::kMap, "3 images",
                [&](const Mapper& plugin) { return plugin.Map(input, MapperContext()); });
  } else if (kind == "bundle_adjuster") {
    const auto adjuster =
        registry.Create<BundleAdjuster>(kind, name, options, "pipeline.bundle_adjuster");
    Reconstruction reconstruction;
    BundleAdjusterGuard(adjuster).Adjust({}, &reconstruction);
  } else {
    const auto exporter = registry.Create<Exporter>(kind, name, options, "pipeline.exporters[0]");
    exporter.Call(PluginStage::kExport, "model 0", [&](const Exporter& plugin) {
      plugin.Export(Reconstruction(), ExportContext());
    });
  }
}

TEST(PluginBoundary, EveryExceptionFromEveryKindBecomesOneHostErrorNamingPluginAndSubject) {
  const std::map<std::string, std::string> activities = {
      {"detector", "detecting image a.png"},
      {"matcher", "matching images a.png and b.png"},
      {"pair_selector", "selecting pairs among 3 images"},
      {"mapper", "mapping 3 images"},
      {"bundle_adjuster", "adjusting a bundle of 0 images and 0 points"},
      {"exporter", "exporting model 0"}};
  for (const auto& [kind, activity] : activities) {
    for (const Expected& failure : Failures()) {
      SCOPED_TRACE(kind + " " + failure.how);
      try {
        CallFailingPlugin(kind, failure.how);
        ADD_FAILURE() << "no error";
      } catch (const PluginError& error) {
        // The plugin's library is unloaded by now; the error is the host's own.
        EXPECT_EQ(std::string(error.what()), "plugin 'failing_" + kind + "' failed while " +
                                                 activity + ": " + failure.message);
        EXPECT_EQ(error.plugin(), "failing_" + kind);
        EXPECT_EQ(error.message(), failure.message);
        EXPECT_EQ(error.input_error(), failure.input_error);
      }
    }
  }
}

// Bad input (InputError, OptionError) is exit code 2; anything else the constructor
// throws is the plugin's failure, exit code 1, as for a call (the guide says so).
TEST(PluginBoundary, FactoryFailuresOfEveryKindNameTheFileAndPlugin) {
  const PluginRegistry registry = PluginRegistry::Discover({kFailing});
  for (const std::string kind :
       {"detector", "matcher", "pair_selector", "mapper", "bundle_adjuster", "exporter"}) {
    for (const Expected& failure : Failures()) {
      SCOPED_TRACE(kind + " " + failure.how);
      const nlohmann::json options = {{"fail", failure.how}, {"in", "factory"}};
      try {
        registry.Create<Plugin>(kind, "failing_" + kind, options, "pipeline." + kind);
        ADD_FAILURE() << "no error";
      } catch (const PluginError& error) {
        EXPECT_FALSE(failure.input_error);
        EXPECT_FALSE(error.input_error());
        EXPECT_EQ(std::string(error.what()),
                  "plugin 'failing_" + kind + "' failed while starting from " +
                      (kFailing / ("libtessera_test_failing_" + kind + ".so")).string() + ": " +
                      failure.message);
      } catch (const InputError& error) {
        EXPECT_TRUE(failure.input_error);
        const std::string text = error.what();
        EXPECT_NE(text.find("failing_" + kind), std::string::npos) << text;
        if (failure.how == "option_error") {
          EXPECT_EQ(text.rfind("pipeline." + kind + ".options.threshold: must be positive", 0), 0u)
              << text;
        } else {
          EXPECT_NE(text.find("libtessera_test_failing_" + kind + ".so: plugin 'failing_" + kind +
                              "' failed to start: " + failure.message),
                    std::string::npos)
              << text;
        }
      }
    }
  }
}

TEST(PluginBoundary, CrashLogMovesTheLastRunsCrashesIntoTheHistoryAndQuarantinesOnTheSecond) {
  testing::TemporaryDir dir;
  const PluginCrashLog empty = PluginCrashLog::Open(dir.path());
  EXPECT_TRUE(empty.new_crashes().empty());
  EXPECT_FALSE(empty.IsQuarantined("sift", PluginStage::kDetect, ImageSubject("b.png")));

  std::ofstream(PluginCrashLog::PendingFile(dir.path()))
      << "SIGSEGV\tsift\tdetect\timage b.png\nSIGSEGV\tsi";  // the second line was cut short
  const PluginCrashLog once = PluginCrashLog::Open(dir.path());
  ASSERT_EQ(once.new_crashes().size(), 1u);
  EXPECT_EQ(once.new_crashes()[0].Describe(),
            "plugin 'sift' crashed (SIGSEGV) while detecting image b.png");
  EXPECT_EQ(once.NewCrashReports(),
            std::vector<std::string>{"the previous run ended in a crash: plugin 'sift' crashed "
                                     "(SIGSEGV) while detecting image b.png"});
  EXPECT_FALSE(std::filesystem::exists(PluginCrashLog::PendingFile(dir.path())));
  EXPECT_EQ(once.NumCrashes("sift", PluginStage::kDetect, ImageSubject("b.png")), 1u);
  EXPECT_FALSE(once.IsQuarantined("sift", PluginStage::kDetect, ImageSubject("b.png")));

  // Reported once only; the history keeps it.
  EXPECT_TRUE(PluginCrashLog::Open(dir.path()).new_crashes().empty());

  std::ofstream(PluginCrashLog::PendingFile(dir.path())) << "SIGABRT\tsift\tdetect\timage b.png\n";
  const PluginCrashLog twice = PluginCrashLog::Open(dir.path());
  EXPECT_EQ(twice.NewCrashReports(),
            std::vector<std::string>{
                "the previous run ended in a crash: plugin 'sift' crashed (SIGABRT) while "
                "detecting image b.png (2 crashes there: image b.png is skipped from now on)"});
  EXPECT_TRUE(twice.IsQuarantined("sift", PluginStage::kDetect, ImageSubject("b.png")));
  EXPECT_FALSE(twice.IsQuarantined("orb", PluginStage::kDetect, ImageSubject("b.png")));
  EXPECT_FALSE(twice.IsQuarantined("sift", PluginStage::kDetect, ImageSubject("a.png")));
  SetPluginCrashFile("");
}

TEST(PluginBoundary, CrashLogCountsAPluginThatEndedTheProcessAsACrash) {
  testing::TemporaryDir dir;
  std::ofstream(PluginCrashLog::PendingFile(dir.path()))
      << "exit\tsift\tdetect\timage b.png\nquick_exit\tsift\tdetect\timage b.png\n"
         "exited\tsift\tdetect\timage b.png\n";  // not a cause the handlers write
  const PluginCrashLog log = PluginCrashLog::Open(dir.path());
  ASSERT_EQ(log.new_crashes().size(), 2u);
  EXPECT_EQ(log.new_crashes()[0].Describe(),
            "plugin 'sift' ended the process (exit) while detecting image b.png");
  EXPECT_EQ(log.new_crashes()[1].Describe(),
            "plugin 'sift' ended the process (quick_exit) while detecting image b.png");
  EXPECT_TRUE(log.IsQuarantined("sift", PluginStage::kDetect, ImageSubject("b.png")));
  SetPluginCrashFile("");
}

// --- The command line -----------------------------------------------------------------

using testing::CommandResult;

CommandResult RunTessera(const std::string& arguments, const std::string& environment = "") {
  return testing::RunCommand(TESSERA_TEST_EXECUTABLE, arguments, environment);
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// a.png and c.png are 40 px wide, b.png 48 px: the failing detector's `on_width`.
std::filesystem::path WriteImages(const std::filesystem::path& dir) {
  const std::filesystem::path images = dir / "images";
  std::filesystem::create_directories(images);
  for (const auto& [name, width] :
       std::vector<std::pair<std::string, int>>{{"a.png", 40}, {"b.png", 48}, {"c.png", 40}}) {
    cv::Mat image(30, width, CV_8UC1);
    cv::randu(image, 0, 255);
    cv::imwrite((images / name).string(), image);
  }
  return images;
}

// A manifest of failing plugins; `detector` etc. are their options.
std::filesystem::path WriteManifest(const std::filesystem::path& dir,
                                    const nlohmann::json& detector,
                                    const nlohmann::json& pair_selector = {},
                                    const nlohmann::json& matcher = {}) {
  const std::filesystem::path file = dir / "failing.json";
  const nlohmann::json manifest = {
      {"plugin_paths", {kFailing.string()}},
      {"threads", 1},
      {"pipeline",
       {{"detector", {{"plugin", "failing_detector"}, {"options", detector}}},
        {"pair_selector",
         {{"plugin", "failing_pair_selector"},
          {"options", pair_selector.is_null() ? nlohmann::json::object() : pair_selector}}},
        {"matcher",
         {{"plugin", "failing_matcher"},
          {"options", matcher.is_null() ? nlohmann::json::object() : matcher}}},
        {"bundle_adjuster", {{"plugin", "failing_bundle_adjuster"}}}}}};
  std::ofstream(file) << manifest.dump(2);
  return file;
}

std::string Extract(const std::filesystem::path& dir, const std::filesystem::path& manifest) {
  return "extract --images " + (dir / "images").string() + " --output " + (dir / "out").string() +
         " --manifest " + manifest.string();
}

TEST(PluginBoundaryCli, ExporterInputErrorIsExitCode2NamingThePlugin) {
  // Today's main: exit 139, nothing printed.
  testing::TemporaryDir dir;
  const auto model = dir.path() / "model";
  std::filesystem::create_directories(model);
  std::ofstream(model / "cameras.txt") << "1 SIMPLE_RADIAL 640 480 500 320 240 0.01\n";
  std::ofstream(model / "images.txt") << "1 1 0 0 0 0 0 0 1 a.jpg\n\n";
  std::ofstream(model / "points3D.txt") << "";
  const auto result =
      RunTessera("export --model " + model.string() + " --format gaussian_splatting --output " +
                 (dir.path() / "out").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_TRUE(Contains(result.output,
                       "[error] plugin 'gaussian_splatting' failed while exporting model 0: " +
                           (dir.path() / "out" / "gaussian_splatting").string() +
                           ": the gaussian_splatting exporter needs the image folder"))
      << result.output;

  const auto custom = RunTessera("export --model " + model.string() +
                                     " --format failing_exporter --options '{\"fail\": \"custom\"}'"
                                     " --output " +
                                     (dir.path() / "out").string(),
                                 "TESSERA_PLUGIN_PATH=" + kFailing.string());
  EXPECT_EQ(custom.exit_code, 1) << custom.output;
  EXPECT_TRUE(Contains(custom.output,
                       "[error] plugin 'failing_exporter' failed while exporting "
                       "model 0: the license has expired"))
      << custom.output;
}

TEST(PluginBoundaryCli, DetectorErrorsSkipTheImageNamingThePlugin) {
  // Whatever the detector throws on one image, that image is skipped with a warning
  // naming the plugin, the image and the message, and the others are extracted.
  for (const Expected& failure : Failures()) {
    SCOPED_TRACE(failure.how);
    testing::TemporaryDir dir;
    WriteImages(dir.path());
    const auto manifest = WriteManifest(dir.path(), {{"fail", failure.how}, {"on_width", 48}});
    const auto result = RunTessera(Extract(dir.path(), manifest));
    EXPECT_EQ(result.exit_code, 0) << result.output;
    EXPECT_TRUE(Contains(result.output,
                         "[warning] Skipped 'b.png': plugin 'failing_detector' failed while "
                         "detecting image b.png: " +
                             failure.message))
        << result.output;
  }
}

TEST(PluginBoundaryCli, PairSelectorAndMatcherErrorsNameThePluginAndThePair) {
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  const auto good = WriteManifest(dir.path(), nlohmann::json::object());
  ASSERT_EQ(RunTessera(Extract(dir.path(), good)).exit_code, 0);
  const std::string match = "match --output " + (dir.path() / "out").string() + " --manifest ";

  const auto selector = RunTessera(
      match + WriteManifest(dir.path(), nlohmann::json::object(), {{"fail", "non_std"}}).string());
  EXPECT_EQ(selector.exit_code, 1) << selector.output;
  EXPECT_TRUE(Contains(selector.output,
                       "[error] plugin 'failing_pair_selector' failed while selecting pairs among "
                       "3 images: it threw an exception that is not a std::exception"))
      << selector.output;

  const auto matcher = RunTessera(
      match +
      WriteManifest(dir.path(), nlohmann::json::object(), {}, {{"fail", "input_error"}}).string());
  EXPECT_EQ(matcher.exit_code, 2) << matcher.output;
  EXPECT_TRUE(Contains(matcher.output,
                       "[error] plugin 'failing_matcher' failed while matching images a.png and "
                       "b.png: this input is not acceptable"))
      << matcher.output;
}

// A match beyond the keypoints was exit 2 (bad input) with a message naming neither the
// matcher nor the images: it is the matcher's bug, reported as its other failures are.
TEST(PluginBoundaryCli, AMatcherThatReturnsIndicesBeyondTheKeypointsIsNamedWithThePair) {
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  ASSERT_EQ(RunTessera(Extract(dir.path(), WriteManifest(dir.path(), nlohmann::json::object())))
                .exit_code,
            0);
  const auto result = RunTessera(
      "match --output " + (dir.path() / "out").string() + " --manifest " +
      WriteManifest(dir.path(), nlohmann::json::object(), {}, {{"fail", "bad_indices"}}).string());
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_TRUE(Contains(result.output,
                       "[error] plugin 'failing_matcher' failed while matching images a.png and "
                       "b.png: it returned match 16 (0, 23), beyond the images' 16 and 16 "
                       "keypoints\n"))
      << result.output;
}

TEST(PluginBoundaryCli, CrashInDetectIsOneLineAndExit4ThenReportedResumedAndQuarantined) {
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  const auto manifest = WriteManifest(dir.path(), {{"fail", "segv"}, {"on_width", 48}});
  const std::string crash_line =
      "[error] plugin 'failing_detector' crashed (SIGSEGV) while detecting image b.png\n";

  const auto first = RunTessera(Extract(dir.path(), manifest));
  EXPECT_EQ(first.exit_code, 4) << first.output;
  EXPECT_TRUE(Contains(first.output, crash_line)) << first.output;
  EXPECT_TRUE(Contains(first.output, "[1/3] a.png: 16 features")) << first.output;

  // The rerun reports the crash, keeps a.png and crashes on b.png again.
  const auto second = RunTessera(Extract(dir.path(), manifest));
  EXPECT_EQ(second.exit_code, 4) << second.output;
  EXPECT_TRUE(Contains(second.output,
                       "the previous run ended in a crash: plugin 'failing_detector' crashed "
                       "(SIGSEGV) while detecting image b.png\n"))
      << second.output;
  EXPECT_TRUE(Contains(second.output, "(1 already done)")) << second.output;
  EXPECT_TRUE(Contains(second.output, crash_line)) << second.output;

  // Two crashes: b.png is skipped from now on, and the rest is extracted.
  const auto third = RunTessera(Extract(dir.path(), manifest));
  EXPECT_EQ(third.exit_code, 0) << third.output;
  EXPECT_TRUE(Contains(third.output, "(2 crashes there: image b.png is skipped from now on)"))
      << third.output;
  EXPECT_TRUE(Contains(third.output,
                       "extract: skipping b.png: it crashed detector 'failing_detector' twice"))
      << third.output;
  EXPECT_TRUE(Contains(third.output, "[1/1] c.png: 16 features")) << third.output;
  EXPECT_FALSE(Contains(third.output, "[error]")) << third.output;
}

// Shards open the workspace as one process does (Workspace::OpenShard): a crash in an
// extraction shard or a matching shard is recorded in the shard's own crash log,
// reported by the shard run again, and its image or pair quarantined on the second.
TEST(PluginBoundaryCli, CrashesInShardsAreRecordedAndQuarantinedAsInOneProcess) {
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  const auto crashing = WriteManifest(dir.path(), {{"fail", "segv"}, {"on_width", 48}});
  const std::string shard = Extract(dir.path(), crashing) + " --shard 0/1";
  const auto first = RunTessera(shard);
  EXPECT_EQ(first.exit_code, 4) << first.output;
  EXPECT_TRUE(
      std::filesystem::exists(dir.path() / "out" / "shards" / "extract-0-of-1.plugin_crashes.new"));
  const auto second = RunTessera(shard);
  EXPECT_EQ(second.exit_code, 4) << second.output;
  EXPECT_TRUE(Contains(second.output,
                       "the previous run ended in a crash: plugin 'failing_detector' crashed "
                       "(SIGSEGV) while detecting image b.png\n"))
      << second.output;
  const auto third = RunTessera(shard);
  EXPECT_EQ(third.exit_code, 0) << third.output;
  EXPECT_TRUE(Contains(third.output,
                       "extract: skipping b.png: it crashed detector 'failing_detector' twice"))
      << third.output;
  // The workspace's own crash log holds none of it: shards never write it.
  EXPECT_FALSE(std::filesystem::exists(PluginCrashLog::HistoryFile(dir.path() / "out")));

  // Matching shards: the merged extraction, then a matcher that crashes on every pair.
  ASSERT_EQ(RunTessera("merge --output " + (dir.path() / "out").string()).exit_code, 0);
  const auto matcher = WriteManifest(dir.path(), nlohmann::json::object(), {}, {{"fail", "segv"}});
  const std::string match_shard = "match --output " + (dir.path() / "out").string() +
                                  " --manifest " + matcher.string() + " --shard 0/1";
  EXPECT_EQ(RunTessera(match_shard).exit_code, 4);
  EXPECT_EQ(RunTessera(match_shard).exit_code, 4);
  const auto quarantined = RunTessera(match_shard);
  EXPECT_TRUE(Contains(quarantined.output, ": they crashed matcher 'failing_matcher' twice"))
      << quarantined.output;
}

TEST(PluginBoundaryCli, AbortInDetectAndCrashInTheFactoryNameThePlugin) {
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  const auto aborts =
      RunTessera(Extract(dir.path(), WriteManifest(dir.path(), {{"fail", "abort"}})));
  EXPECT_EQ(aborts.exit_code, 4) << aborts.output;
  EXPECT_TRUE(Contains(aborts.output,
                       "[error] plugin 'failing_detector' crashed (SIGABRT) while detecting image "
                       "a.png\n"))
      << aborts.output;

  const auto factory = RunTessera(
      Extract(dir.path(), WriteManifest(dir.path(), {{"fail", "segv"}, {"in", "factory"}})));
  EXPECT_EQ(factory.exit_code, 4) << factory.output;
  EXPECT_TRUE(Contains(factory.output,
                       "[error] plugin 'failing_detector' crashed (SIGSEGV) while starting from " +
                           (kFailing / "libtessera_test_failing_detector.so").string() + "\n"))
      << factory.output;
}

// A plugin that called exit(0) in Detect made `tessera run` exit 0 with nothing done.
TEST(PluginBoundaryCli, APluginThatEndsTheProcessIsExit4NamingPluginAndStage) {
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  const std::string run = "run --images " + (dir.path() / "images").string() + " --output " +
                          (dir.path() / "out").string() + " --manifest ";
  const auto exits =
      RunTessera(run + WriteManifest(dir.path(), {{"fail", "exit"}, {"on_width", 48}}).string());
  EXPECT_EQ(exits.exit_code, 4) << exits.output;
  EXPECT_TRUE(Contains(exits.output,
                       "[error] plugin 'failing_detector' ended the process (exit) while "
                       "detecting image b.png\n"))
      << exits.output;
  EXPECT_TRUE(Contains(exits.output, "[1/3] a.png: 16 features")) << exits.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "sparse")) << exits.output;

  // Recorded as a crash: the rerun reports it, and the second one of a build (the same
  // file and options) quarantines b.png.
  const auto again = RunTessera(
      run + WriteManifest(dir.path(), {{"fail", "quick_exit"}, {"on_width", 48}}).string());
  EXPECT_EQ(again.exit_code, 4) << again.output;
  EXPECT_TRUE(Contains(again.output,
                       "the previous run ended in a crash: plugin 'failing_detector' ended the "
                       "process (exit) while detecting image b.png\n"))
      << again.output;
  EXPECT_TRUE(Contains(again.output,
                       "[error] plugin 'failing_detector' ended the process (quick_exit) while "
                       "detecting image b.png\n"))
      << again.output;
  // A crash counts for the options it ran with: the record of the run with "exit" is set
  // aside while the plugin runs with "quick_exit", and b.png is tried once more.
  const std::string quick_exit =
      Extract(dir.path(), WriteManifest(dir.path(), {{"fail", "quick_exit"}, {"on_width", 48}}));
  const auto other_options = RunTessera(quick_exit);
  EXPECT_EQ(other_options.exit_code, 4) << other_options.output;
  EXPECT_TRUE(Contains(other_options.output,
                       "[info] plugin 'failing_detector': a crash record of an older build"))
      << other_options.output;
  const auto skipped = RunTessera(quick_exit);
  EXPECT_EQ(skipped.exit_code, 0) << skipped.output;
  EXPECT_TRUE(Contains(skipped.output,
                       "extract: skipping b.png: it crashed detector 'failing_detector' twice"))
      << skipped.output;

  // Every stage: a matcher's quick_exit, an exporter's exit.
  const auto matcher = RunTessera(
      "match --output " + (dir.path() / "out").string() + " --manifest " +
      WriteManifest(dir.path(), nlohmann::json::object(), {}, {{"fail", "quick_exit"}}).string());
  EXPECT_EQ(matcher.exit_code, 4) << matcher.output;
  EXPECT_TRUE(Contains(matcher.output,
                       "[error] plugin 'failing_matcher' ended the process (quick_exit) while "
                       "matching images a.png and b.png\n"))
      << matcher.output;
  const auto model = dir.path() / "model";
  std::filesystem::create_directories(model);
  std::ofstream(model / "cameras.txt") << "1 SIMPLE_RADIAL 640 480 500 320 240 0.01\n";
  std::ofstream(model / "images.txt") << "1 1 0 0 0 0 0 0 1 a.jpg\n\n";
  std::ofstream(model / "points3D.txt") << "";
  const auto exporter = RunTessera("export --model " + model.string() +
                                       " --format failing_exporter --options '{\"fail\": "
                                       "\"exit\"}' --output " +
                                       (dir.path() / "exported").string(),
                                   "TESSERA_PLUGIN_PATH=" + kFailing.string());
  EXPECT_EQ(exporter.exit_code, 4) << exporter.output;
  EXPECT_TRUE(Contains(exporter.output,
                       "[error] plugin 'failing_exporter' ended the process (exit) while "
                       "exporting model 0\n"))
      << exporter.output;
}

TEST(PluginBoundaryCli, CrashInMatchNamesThePairAndKeepsTheFeatures) {
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  ASSERT_EQ(RunTessera(Extract(dir.path(), WriteManifest(dir.path(), nlohmann::json::object())))
                .exit_code,
            0);
  const auto manifest = WriteManifest(dir.path(), nlohmann::json::object(), {}, {{"fail", "segv"}});
  const std::string match =
      "match --output " + (dir.path() / "out").string() + " --manifest " + manifest.string();
  const auto result = RunTessera(match);
  EXPECT_EQ(result.exit_code, 4) << result.output;
  EXPECT_TRUE(Contains(result.output,
                       "[error] plugin 'failing_matcher' crashed (SIGSEGV) while matching images "
                       "a.png and b.png\n"))
      << result.output;
  // The workspace is intact: extraction reuses every image.
  const auto again = RunTessera(Extract(dir.path(), manifest));
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(Contains(again.output, "0 to detect with 'failing_detector' (3 already done)"))
      << again.output;
}

TEST(PluginBoundaryCli, ALibraryThatCrashesOnLoadIsRefusedAndTheRestListed) {
  const std::string folder = (kRoot / "crash_on_load").string();
  const auto result =
      RunTessera("plugins", "TESSERA_PLUGIN_PATH=" + folder + ":" + kFailing.string());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(Contains(result.output, "REFUSED " + folder +
                                          "/libtessera_test_crash_on_load.so: crashes on load "
                                          "(SIGSEGV)\n"))
      << result.output;
  for (const std::string kind :
       {"detector", "matcher", "pair_selector", "bundle_adjuster", "exporter"}) {
    EXPECT_TRUE(Contains(result.output, " failing_" + kind + " ")) << result.output;
  }

  // A run whose manifest names it fails with exit code 2, naming why.
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "m.json";
  std::ofstream(manifest) << R"({"pipeline": {"pair_selector": {"plugin": "crash_on_load"}}})";
  const auto run = RunTessera(
      "match --output " + (dir.path() / "out").string() + " --manifest " + manifest.string(),
      "TESSERA_PLUGIN_PATH=" + folder);
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_TRUE(Contains(run.output, "no pair_selector plugin 'crash_on_load'")) << run.output;
  EXPECT_TRUE(Contains(run.output, "; refused: " + folder +
                                       "/libtessera_test_crash_on_load.so: crashes on load "
                                       "(SIGSEGV)\n"))
      << run.output;
}

TEST(PluginBoundaryCli, AMissingPluginPathsFolderIsAnErrorNamingTheJsonPath) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "typo.json";
  std::ofstream(manifest) << R"({"plugin_paths": ["plugns"]})";
  const auto result = RunTessera("plugins --manifest " + manifest.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_EQ(result.output, "[error] " + manifest.string() + ": plugin_paths[0]: " +
                               (dir.path() / "plugns").string() + " is not a folder\n");
}

TEST(PluginBoundaryCli, BenchKeepsARowsExitCode3) {
  // Grid features that never initialise a model: `run` exits 3, and so must the bench
  // (today's main turns it into 1).
  testing::TemporaryDir dir;
  WriteImages(dir.path());
  const auto manifest = WriteManifest(dir.path(), nlohmann::json::object());
  const auto result =
      RunTessera("bench --images " + (dir.path() / "images").string() + " --output " +
                 (dir.path() / "bench").string() + " " + manifest.string());
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_TRUE(Contains(result.output, "bench: failing ended with exit code 3")) << result.output;
}

}  // namespace
}  // namespace tessera
