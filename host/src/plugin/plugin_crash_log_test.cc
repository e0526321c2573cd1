// The quarantine belongs to the plugin as it was built: crash records carry the plugin's
// version, file hash and options digest, and only the records of the build that runs now
// count. Records of another build, or of the old four-field format, are set aside.

#include "plugin/plugin_crash_log.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <sstream>

#include "tessera/io/file_io.h"
#include "test_support.h"

namespace tessera {
namespace {

const PluginBuild kOld = {"1.0.0", "00000000000000aa", "00000000000000bb"};
const PluginBuild kRebuilt = {"1.0.0", "00000000000000cc", "00000000000000bb"};

std::string Record(const std::string& plugin, const PluginBuild& build) {
  return "SIGSEGV\t" + plugin + "\tdetect\timage b.png\t" + build.version + "\t" + build.file_hash +
         "\t" + build.options_digest + "\n";
}

// What spdlog logs while `fn` runs.
template <typename Fn>
std::string Logged(Fn&& fn) {
  std::ostringstream stream;
  const auto previous = spdlog::default_logger();
  auto logger = std::make_shared<spdlog::logger>(
      "capture", std::make_shared<spdlog::sinks::ostream_sink_mt>(stream));
  logger->set_pattern("[%l] %v");
  spdlog::set_default_logger(logger);
  fn();
  spdlog::set_default_logger(previous);
  return stream.str();
}

TEST(PluginCrashLog, ReadsTheBuildOfNewRecordsAndOldRecordsAsOfAnUnknownBuild) {
  const std::vector<PluginCrash> crashes =
      ParsePluginCrashes(Record("sift", kOld) + "SIGABRT\tsift\tdetect\timage c.png\n" +
                         "SIGSEGV\tsift\tdetect\timage d.png\t1.0\tcut");  // cut short
  ASSERT_EQ(crashes.size(), 2u);
  EXPECT_EQ(crashes[0].build, kOld);
  EXPECT_EQ(crashes[0].subject, "image b.png");
  EXPECT_FALSE(crashes[1].build.known());
  EXPECT_EQ(crashes[1].build.Describe(),
            "an unknown build (a record written before builds were recorded)");
}

TEST(PluginCrashLog, OnlyTheCrashesOfTheBuildThatRunsNowQuarantine) {
  testing::TemporaryDir dir;
  std::ofstream(PluginCrashLog::PendingFile(dir.path()))
      << Record("rebuilt", kOld) << Record("rebuilt", kOld);
  const PluginCrashLog log = PluginCrashLog::Open(dir.path());
  SetPluginCrashFile("");
  EXPECT_EQ(log.NewCrashReports().back(),
            "the previous run ended in a crash: plugin 'rebuilt' crashed (SIGSEGV) while "
            "detecting image b.png (2 crashes there: image b.png is skipped from now on)");
  // The build that crashed is still the one that runs: quarantined.
  SetCurrentPluginBuild("rebuilt", kOld);
  EXPECT_TRUE(log.IsQuarantined("rebuilt", PluginStage::kDetect, ImageSubject("b.png")));

  // Rebuilt (another file hash): its crash records are set aside, once said.
  SetCurrentPluginBuild("rebuilt", kRebuilt);
  const std::string logged = Logged([&] {
    EXPECT_FALSE(log.IsQuarantined("rebuilt", PluginStage::kDetect, ImageSubject("b.png")));
    EXPECT_EQ(log.NumCrashes("rebuilt", PluginStage::kDetect, ImageSubject("b.png")), 0u);
  });
  EXPECT_EQ(logged,
            "[info] plugin 'rebuilt': 2 crash records of an older build (version 1.0.0, file "
            "00000000000000aa, options 00000000000000bb) were set aside (plugin_crashes.tsv): "
            "this build (version 1.0.0, file 00000000000000cc, options 00000000000000bb) runs "
            "again while detecting image b.png\n");

  // Other options are another build too.
  SetCurrentPluginBuild("rebuilt", {"1.0.0", "00000000000000aa", "00000000000000dd"});
  EXPECT_FALSE(log.IsQuarantined("rebuilt", PluginStage::kDetect, ImageSubject("b.png")));
}

TEST(PluginCrashLog, OldFormatRecordsAreSetAsideOnceTheBuildIsKnown) {
  testing::TemporaryDir dir;
  std::ofstream(PluginCrashLog::HistoryFile(dir.path()))
      << "SIGSEGV\told_format\tdetect\timage b.png\nSIGSEGV\told_format\tdetect\timage b.png\n";
  const PluginCrashLog log = PluginCrashLog::ReadHistory(dir.path());
  // Not made in this process: every record counts, as before builds were recorded.
  EXPECT_TRUE(log.IsQuarantined("old_format", PluginStage::kDetect, ImageSubject("b.png")));
  SetCurrentPluginBuild("old_format", kOld);
  const std::string logged = Logged([&] {
    EXPECT_FALSE(log.IsQuarantined("old_format", PluginStage::kDetect, ImageSubject("b.png")));
  });
  EXPECT_NE(logged.find("2 crash records of an older build (an unknown build (a record written "
                        "before builds were recorded)) were set aside"),
            std::string::npos)
      << logged;
}

TEST(PluginCrashLog, NewCrashesCountOnlyTheirOwnBuildTowardsTheQuarantine) {
  testing::TemporaryDir dir;
  std::ofstream(PluginCrashLog::HistoryFile(dir.path())) << Record("counted", kOld);
  std::ofstream(PluginCrashLog::PendingFile(dir.path())) << Record("counted", kRebuilt);
  const PluginCrashLog log = PluginCrashLog::Open(dir.path());
  SetPluginCrashFile("");
  EXPECT_EQ(log.NewCrashReports(),
            std::vector<std::string>{"the previous run ended in a crash: plugin 'counted' "
                                     "crashed (SIGSEGV) while detecting image b.png"});
  // The history file keeps the build of each record.
  EXPECT_EQ(ParsePluginCrashes(ReadFileContents(PluginCrashLog::HistoryFile(dir.path())))[1].build,
            kRebuilt);
}

TEST(PluginCrashLog, ABuildIsTheVersionTheFileAndTheOptions) {
  testing::TemporaryDir dir;
  const std::filesystem::path a = dir.path() / "a.so", b = dir.path() / "b.so";
  std::ofstream(a) << "one build";
  std::ofstream(b) << "another build";
  const PluginBuild build = MakePluginBuild("1.0", a, R"({"x":1})");
  EXPECT_EQ(build.version, "1.0");
  EXPECT_EQ(build.file_hash.size(), 16u);
  EXPECT_EQ(build, MakePluginBuild("1.0", a, R"({"x":1})"));
  EXPECT_NE(build, MakePluginBuild("1.0", b, R"({"x":1})"));
  EXPECT_NE(build, MakePluginBuild("1.0", a, R"({"x":2})"));
  EXPECT_NE(build, MakePluginBuild("1.1", a, R"({"x":1})"));
}

TEST(PluginCrashLog, ForgettingRemovesEveryRecordOfTheWorkspaceAndItsShards) {
  testing::TemporaryDir dir;
  std::filesystem::create_directories(dir.path() / "shards");
  std::ofstream(PluginCrashLog::HistoryFile(dir.path())) << Record("x", kOld) << Record("x", kOld);
  std::ofstream(PluginCrashLog::PendingFile(dir.path())) << Record("x", kOld);
  std::ofstream(PluginCrashLog::HistoryFile(dir.path() / "shards", "s0.plugin_crashes"))
      << "SIGSEGV\tx\tmatch\timages a and b\n";
  std::ofstream(dir.path() / "shards" / "s0.db") << "kept";
  EXPECT_EQ(ForgetPluginCrashes(dir.path()), 4u);
  EXPECT_FALSE(std::filesystem::exists(PluginCrashLog::HistoryFile(dir.path())));
  EXPECT_FALSE(std::filesystem::exists(PluginCrashLog::PendingFile(dir.path())));
  EXPECT_FALSE(std::filesystem::exists(
      PluginCrashLog::HistoryFile(dir.path() / "shards", "s0.plugin_crashes")));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "shards" / "s0.db"));
  EXPECT_EQ(ForgetPluginCrashes(dir.path()), 0u);
  EXPECT_THROW(ForgetPluginCrashes(dir.path() / "missing"), InputError);
}

}  // namespace
}  // namespace tessera
