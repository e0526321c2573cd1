#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tessera/options.h"
#include "util/parallel.h"
#include "util/paths.h"
#include "util/random.h"
#include "util/strings.h"
#include "util/tessera_commands.h"
#include "util/warning_count.h"

namespace tessera {
namespace {

// A folder of TESSERA_PLUGIN_PATH that does not exist, or is a file, is a warning naming
// it, once per process; the folders that exist give none.
TEST(PluginSearchPath, WarnsOnceNamingEachPluginPathFolderThatIsNone) {
  const std::filesystem::path temp =
      std::filesystem::temp_directory_path() / ("tessera-util-test-" + std::to_string(getpid()));
  std::filesystem::create_directories(temp / "plugins");
  std::ofstream(temp / "file") << "not a folder";
  const std::string missing = (temp / "no-such-folder").string();
  const std::string file = (temp / "file").string();
  const std::string folder = (temp / "plugins").string();
  ASSERT_EQ(setenv("TESSERA_PLUGIN_PATH", (missing + ":" + folder + "::" + file).c_str(), 1), 0);

  std::ostringstream log;
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>(
      "test", std::make_shared<spdlog::sinks::ostream_sink_mt>(log)));
  spdlog::set_pattern("%l %v");
  const std::vector<std::filesystem::path> paths = PluginSearchPath({});
  PluginSearchPath({});  // asked again: no second warning
  spdlog::set_default_logger(previous);
  unsetenv("TESSERA_PLUGIN_PATH");
  std::filesystem::remove_all(temp);

  ASSERT_EQ(paths.size(), 4u);  // the three pieces and the bundled folder, in order
  EXPECT_EQ(paths[0], missing);
  EXPECT_EQ(paths[1], folder);
  EXPECT_EQ(paths[2], file);
  EXPECT_EQ(log.str(), "warning TESSERA_PLUGIN_PATH: '" + missing +
                           "' does not exist; no plugins are loaded from it\n"
                           "warning TESSERA_PLUGIN_PATH: '" +
                           file + "' is not a folder; no plugins are loaded from it\n");
}

// The verdict "(see the warnings above)" is said only where a warning was logged.
TEST(WarningCount, CountsWarningsAndErrorsOnly) {
  auto logger = std::make_shared<spdlog::logger>("counted", WarningCountingSink());
  logger->set_level(spdlog::level::debug);
  const size_t before = NumWarningsLogged();
  logger->debug("d");
  logger->info("i");
  EXPECT_EQ(NumWarningsLogged(), before);
  logger->warn("w");
  logger->error("e");
  EXPECT_EQ(NumWarningsLogged(), before + 2);
}

TEST(NaturalLess, OrdersDigitRunsByValue) {
  std::vector<std::string> names = {"img10.jpg", "img2.jpg", "IMG1.jpg",
                                    "img02.jpg", "a.jpg",    "img1b.jpg"};
  std::sort(names.begin(), names.end(), NaturalLess);
  EXPECT_EQ(names, (std::vector<std::string>{"a.jpg", "IMG1.jpg", "img1b.jpg", "img02.jpg",
                                             "img2.jpg", "img10.jpg"}));
  EXPECT_FALSE(NaturalLess("x", "x"));
  EXPECT_TRUE(NaturalLess("frame_99999999999999999999", "frame_100000000000000000000"));
}

TEST(ParallelFor, VisitsEveryIndexOnceAndRethrows) {
  std::vector<std::atomic<int>> visits(1000);
  ParallelFor(visits.size(), 4, [&](size_t i) { ++visits[i]; });
  EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](const auto& v) { return v == 1; }));
  EXPECT_THROW(ParallelFor(100, 3,
                           [](size_t i) {
                             if (i == 57) throw std::runtime_error("fails");
                           }),
               std::runtime_error);
}

TEST(DeriveSeed, DependsOnBothInputsOnly) {
  EXPECT_EQ(DeriveSeed(1, 2), DeriveSeed(1, 2));
  EXPECT_NE(DeriveSeed(1, 2), DeriveSeed(1, 3));
  EXPECT_NE(DeriveSeed(1, 2), DeriveSeed(2, 2));
}

TEST(OptionReader, SuggestsTheClosestKnownName) {
  EXPECT_EQ(EditDistance("flan", "flann"), 1u);
  EXPECT_EQ(ClosestName("flan", {"brute_force", "flann"}), "flann");
  EXPECT_EQ(ClosestName("zzzzzz", {"brute_force", "flann"}), "");
  OptionReader reader(nlohmann::json{{"ratoi", 0.7}});
  EXPECT_EQ(reader.Get<double>("ratio", 0.8, 0, 1), 0.8);
  try {
    reader.Finish();
    FAIL();
  } catch (const OptionError& error) {
    EXPECT_EQ(std::string(error.what()), "ratoi: unknown key; did you mean 'ratio'?");
    EXPECT_EQ(error.path(), "ratoi");
  }
}

TEST(OptionReader, ChecksTypesAndRangesAndRecordsEffectiveOptions) {
  OptionReader reader(nlohmann::json{{"n", 5}, {"name", "b"}}, "opts");
  EXPECT_EQ(reader.Get<int>("n", 1, 1, 10), 5);
  EXPECT_EQ(reader.GetString("name", "a", {"a", "b"}), "b");
  EXPECT_TRUE(reader.GetBool("flag", true));
  reader.Finish();
  EXPECT_EQ(reader.Effective(), (nlohmann::json{{"n", 5}, {"name", "b"}, {"flag", true}}));

  OptionReader bad(nlohmann::json{{"n", 2.5}});
  EXPECT_THROW(bad.Get<int>("n", 1), OptionError);
  OptionReader out_of_range(nlohmann::json{{"x", 11.0}}, "o");
  try {
    out_of_range.Get<double>("x", 1, 0, 10);
    FAIL();
  } catch (const OptionError& error) {
    EXPECT_EQ(std::string(error.what()), "o.x = 11.0 is out of range [0, 10]");
  }
  EXPECT_THROW(OptionReader(nlohmann::json::array()), OptionError);
}

// What a child printed reaches a message short and printable, whatever it was.
TEST(PrintableExcerpt, EscapesAndCuts) {
  EXPECT_EQ(PrintableExcerpt("COLMAP 3.8", 100), "COLMAP 3.8");
  EXPECT_EQ(PrintableExcerpt("a\nb\t\x01\x1b[31m\xff", 100), "a\\nb\\t\\x01\\x1b[31m\\xff");
  EXPECT_EQ(PrintableExcerpt(std::string(1000, 'x'), 10), "xxxxxxxxxx... (990 more bytes)");
  // An escape is never cut in two.
  EXPECT_EQ(PrintableExcerpt("ab\x01", 4), "ab... (1 more bytes)");
  EXPECT_EQ(FirstLine("\n  COLMAP 3.8\r\nusage"), "COLMAP 3.8");
  EXPECT_EQ(FirstLine(" \n "), "");
}

TEST(SafeFileName, IsOneFileNameOfSafeCharacters) {
  EXPECT_EQ(SafeFileName("colmap-3.8", 64), "colmap-3.8");
  EXPECT_EQ(SafeFileName("colmap-3.8/../../x y", 64), "colmap-3.8_.._.._x_y");
  EXPECT_EQ(SafeFileName("..", 64), "_..");
  EXPECT_EQ(SafeFileName("", 64), "_");
  EXPECT_EQ(SafeFileName("\xc3\xa9t\xc3\xa9", 64), "__t__");
  EXPECT_EQ(SafeFileName(std::string(100, 'a'), 10), std::string(10, 'a'));
}

// bench's `tessera run`, written where every `tessera` command line is.
TEST(TesseraCommands, BenchRunCommand) {
  BenchRunArguments run;
  run.tessera = "/opt/bin/tessera";
  run.images = "/photos";
  run.output = "/bench/tessera/fast";
  run.manifest = "fast.json";
  EXPECT_EQ(BenchRunCommand(run),
            (std::vector<std::string>{"/opt/bin/tessera", "run", "--images", "/photos", "--output",
                                      "/bench/tessera/fast", "--manifest", "fast.json"}));
  run.threads = 2;
  run.camera_K = "K.txt";
  run.camera_per_folder = true;
  EXPECT_EQ(BenchRunCommand(run),
            (std::vector<std::string>{"/opt/bin/tessera", "run", "--images", "/photos", "--output",
                                      "/bench/tessera/fast", "--manifest", "fast.json", "--threads",
                                      "2", "--camera-K", "K.txt", "--camera-per-folder"}));
}

}  // namespace
}  // namespace tessera
