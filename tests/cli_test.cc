// The `tessera` executable as users run it: exit codes and one-line messages.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>

#include "tessera/io/file_io.h"
#include "tessera/plugin.h"
#include "test_support.h"
#include "util/workspace_lock.h"

namespace tessera {
namespace {

using testing::CommandResult;

CommandResult RunTessera(const std::string& arguments, const std::string& environment = "") {
  return testing::RunCommand(TESSERA_TEST_EXECUTABLE, arguments, environment);
}

TEST(Cli, PrintsItsVersion) {
  const auto result = RunTessera("--version");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.output.find("0."), std::string::npos) << result.output;
}

TEST(Cli, BadArgumentsAreExitCode2) {
  EXPECT_EQ(RunTessera("").exit_code, 2);
  EXPECT_EQ(RunTessera("frobnicate").exit_code, 2);
  EXPECT_EQ(RunTessera("run --output /tmp/x").exit_code, 2);  // --images missing
}

TEST(Cli, PluginsJsonListsEveryBundledPluginWithKindAndVersion) {
  const auto result = RunTessera("plugins --json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(result.output);
  std::map<std::string, std::string> kinds;
  for (const auto& plugin : json["plugins"]) {
    EXPECT_TRUE(plugin["usable"].get<bool>()) << plugin.dump();
    EXPECT_FALSE(plugin["version"].get<std::string>().empty());
    kinds[plugin["name"].get<std::string>()] = plugin["kind"].get<std::string>();
  }
  const std::map<std::string, std::string> expected = {{"sift", "detector"},
                                                       {"orb", "detector"},
                                                       {"brute_force", "matcher"},
                                                       {"flann", "matcher"},
                                                       {"exhaustive", "pair_selector"},
                                                       {"sequential", "pair_selector"},
                                                       {"window", "pair_selector"},
                                                       {"window_anchor", "pair_selector"},
                                                       {"spatial", "pair_selector"},
                                                       {"retrieval", "pair_selector"},
                                                       {"incremental", "mapper"},
                                                       {"global", "mapper"},
                                                       {"ceres", "bundle_adjuster"},
                                                       {"colmap_binary", "exporter"},
                                                       {"colmap_text", "exporter"},
                                                       {"ply", "exporter"},
                                                       {"gaussian_splatting", "exporter"},
                                                       {"transforms_json", "exporter"}};
  for (const auto& [name, kind] : expected) {
    ASSERT_TRUE(kinds.count(name)) << "bundled plugin '" << name << "' not listed";
    EXPECT_EQ(kinds[name], kind) << name;
  }
  EXPECT_EQ(kinds.size(), 18u) << result.output;
}

TEST(Cli, PluginsMarksRefusedFilesWithWhy) {
  const std::string path = std::string(TESSERA_TEST_PLUGIN_ROOT) + "/wrong_abi";
  const auto with_broken = RunTessera("plugins", "TESSERA_PLUGIN_PATH=" + path);
  EXPECT_EQ(with_broken.exit_code, 0);
  EXPECT_NE(with_broken.output.find("REFUSED " + path), std::string::npos) << with_broken.output;
  EXPECT_NE(with_broken.output.find("got version 999, supported version is " +
                                    std::to_string(TESSERA_PLUGIN_ABI_VERSION)),
            std::string::npos);
}

TEST(Cli, WarnsNamingAPluginPathFolderThatDoesNotExist) {
  testing::TemporaryDir dir;
  const std::string missing = (dir.path() / "no_such_plugins").string();
  const auto result = RunTessera("plugins", "TESSERA_PLUGIN_PATH=" + missing);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("TESSERA_PLUGIN_PATH: '" + missing +
                               "' does not exist; no plugins are loaded from it"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("sift"), std::string::npos) << result.output;  // bundled ones
}

TEST(Cli, MisspeltPluginFailsBeforeReadingImagesWithASuggestion) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "typo.json";
  std::ofstream(manifest) << R"({"pipeline": {"detector": {"plugin": "sift"},
                                               "pair_selector": {"plugin": "exhaustive"},
                                               "matcher": {"plugin": "flan"}}})";
  // The image folder does not exist: the manifest error must come first.
  const auto result =
      RunTessera("run --images " + (dir.path() / "no_such_folder").string() + " --output " +
                 (dir.path() / "out").string() + " --manifest " + manifest.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(manifest.string() +
                               ": pipeline.matcher.plugin: no matcher plugin 'flan'; did you mean "
                               "'flann'?"),
            std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "database.db"));
}

TEST(Cli, PairSelectorRefusingTheDetectorsDescriptorsFailsBeforeExtraction) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "orb_float.json";
  std::ofstream(manifest) << R"({"plugin_paths": [")" << TESSERA_TEST_PLUGIN_ROOT
                          << R"(/float_only"],
    "pipeline": {"detector": {"plugin": "orb"},
                 "pair_selector": [{"plugin": "exhaustive"}, {"plugin": "float_only"}],
                 "matcher": {"plugin": "brute_force"}, "bundle_adjuster": {"plugin": "ceres"}}})";
  // The image folder does not exist: the selector's refusal must come first.
  const auto result =
      RunTessera("run --images " + (dir.path() / "no_such_folder").string() + " --output " +
                 (dir.path() / "out").string() + " --manifest " + manifest.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(manifest.string() +
                               ": pipeline.pair_selector[1].options: needs float (L2) "
                               "descriptors, not binary ones (pair selector 'float_only', "
                               "hamming descriptors)"),
            std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "database.db"));
}

TEST(Cli, InvalidPluginOptionIsExitCode2) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "bad.json";
  std::ofstream(manifest) << R"({"pipeline": {"detector": {"plugin": "sift",
                                 "options": {"max_num_featurs": 10}}}})";
  const auto result =
      RunTessera("extract --images /nonexistent --output " + (dir.path() / "out").string() +
                 " --manifest " + manifest.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("pipeline.detector.options.max_num_featurs: unknown key; did you "
                               "mean 'max_num_features'?"),
            std::string::npos)
      << result.output;
}

// The global mapper reads its own options and hands the rest to GlobalMapperOptions:
// an unknown key is named with the closest of all of them, or with the whole list.
TEST(Cli, GlobalMapperUnknownKeysNameEveryKnownKey) {
  testing::TemporaryDir dir;
  const auto map_with = [&](const std::string& options) {
    const auto manifest = dir.path() / "global.json";
    std::ofstream(manifest) << R"({"pipeline": {"mapper": {"plugin": "global", "options": )"
                            << options << "}}}";
    return RunTessera("map --output " + (dir.path() / "out").string() + " --manifest " +
                      manifest.string());
  };
  const auto own_key = map_with(R"({"use_gps_priors": true})");
  EXPECT_EQ(own_key.exit_code, 2) << own_key.output;
  EXPECT_NE(
      own_key.output.find(
          "pipeline.mapper.options.use_gps_priors: unknown key; did you mean 'use_gps_prior'?"),
      std::string::npos)
      << own_key.output;
  const auto shared_key = map_with(R"({"ba_num_round": 2})");
  EXPECT_NE(shared_key.output.find(
                "pipeline.mapper.options.ba_num_round: unknown key; did you mean 'ba_num_rounds'?"),
            std::string::npos)
      << shared_key.output;
  const auto far_key = map_with(R"({"completely_unrelated": 1})");
  EXPECT_EQ(far_key.exit_code, 2) << far_key.output;
  for (const char* key : {"ba_function_tolerance", "gps_min_images", "min_model_agreement",
                          "reg_max_rotation_error", "seed", "use_gps_prior"}) {
    EXPECT_NE(far_key.output.find(key), std::string::npos)
        << key << " not listed: " << far_key.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "database.db"));
}

// Range messages say the range in a few characters: CLI11's NonNegativeNumber wrote its
// upper bound, DBL_MAX, in 309 digits.
TEST(Cli, ANegativeModelIndexIsRefusedReadably) {
  const auto result =
      RunTessera("export --model /nonexistent --format ply --output /tmp/x --model-index -1");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--model-index: Value -1 is not a whole number of at least 0"),
            std::string::npos)
      << result.output;
  EXPECT_LT(result.output.size(), 300u) << result.output;
}

TEST(Cli, GtOriginAltitudeIsRangeChecked) {
  for (const char* origin : {"46.5,6.5,1e9", "46.5,6.5,-200000", "46.5,6.5,nan"}) {
    const auto result = RunTessera(std::string("eval /nonexistent /nonexistent --no-align "
                                               "--gt-origin ") +
                                   origin);
    EXPECT_EQ(result.exit_code, 2) << origin << ": " << result.output;
    EXPECT_NE(result.output.find("--gt-origin: expected LAT,LON,ALT (latitude in [-90, 90], "
                                 "longitude in [-180, 180] degrees, altitude in [-100000, "
                                 "100000] metres), got '" +
                                 std::string(origin) + "'"),
              std::string::npos)
        << result.output;
  }
  // In range: past the argument check, to the model folder.
  const auto in_range =
      RunTessera("eval /nonexistent /nonexistent --no-align --gt-origin 46.5,6.5,8848");
  EXPECT_EQ(in_range.output.find("--gt-origin"), std::string::npos) << in_range.output;
}

TEST(Cli, TooFewImagesIsExitCode2) {
  testing::TemporaryDir dir;
  std::filesystem::create_directories(dir.path() / "images");
  std::ofstream(dir.path() / "images" / "notes.txt") << "not an image";
  const auto result = RunTessera("extract --images " + (dir.path() / "images").string() +
                                 " --output " + (dir.path() / "out").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("0 usable image(s); at least 2 are needed"), std::string::npos)
      << result.output;
}

// Masks that cannot be used are warnings naming the image; the images are used without.
TEST(Cli, UnusableMasksAreWarningsNamingTheImage) {
  testing::TemporaryDir dir;
  std::filesystem::create_directories(dir.path() / "images");
  std::filesystem::create_directories(dir.path() / "masks");
  std::filesystem::create_directories(dir.path() / "no_masks");
  const std::filesystem::path sample =
      testing::SourceDir() / "examples" / "fountain-P11-small" / "images";
  for (const char* name : {"0000.jpg", "0001.jpg"}) {
    std::filesystem::copy_file(sample / name, dir.path() / "images" / name);
  }
  std::ofstream(dir.path() / "masks" / "0001.jpg.png") << "not a PNG";
  std::ofstream(dir.path() / "m.json")
      << R"({"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 500}}}})";
  const std::string common = "extract --images " + (dir.path() / "images").string() +
                             " --manifest " + (dir.path() / "m.json").string() + " --masks ";
  auto result = RunTessera(common + (dir.path() / "masks").string() + " --output " +
                           (dir.path() / "out1").string());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("'0000.jpg': no mask in"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("'0001.jpg': its mask " +
                               (dir.path() / "masks" / "0001.jpg.png").string() +
                               " cannot be decoded; used without a mask"),
            std::string::npos)
      << result.output;
  result = RunTessera(common + (dir.path() / "no_masks").string() + " --output " +
                      (dir.path() / "out2").string());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("matches none of the 2 images"), std::string::npos) << result.output;
  result = RunTessera(common + (dir.path() / "nothing").string() + " --output " +
                      (dir.path() / "out3").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find((dir.path() / "nothing").string() + ": no such mask folder"),
            std::string::npos)
      << result.output;
}

TEST(Cli, MissingManifestIsExitCode2) {
  const auto result =
      RunTessera("run --images /tmp --output /tmp/out --manifest /nonexistent/m.json");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("/nonexistent/m.json: cannot read the manifest"), std::string::npos)
      << result.output;
}

// `--manifest fast` is the bundled recipe from any working folder; a file of that name in
// the working folder wins; a name that is neither is refused with the list of recipes.
TEST(Cli, ManifestNamesABundledRecipeFromAnotherFolder) {
  testing::TemporaryDir dir;
  std::filesystem::create_directories(dir.path() / "images");
  const std::filesystem::path sample =
      testing::SourceDir() / "examples" / "fountain-P11-small" / "images";
  for (const char* name : {"0000.jpg", "0001.jpg"}) {
    std::filesystem::copy_file(sample / name, dir.path() / "images" / name);
  }
  const std::string in_dir = "cd " + dir.path().string() + " &&";
  auto result = RunTessera("extract --images images --output out --manifest fast -q", in_dir);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  result = RunTessera("extract --images images --output out2 --manifest fst", in_dir);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("fst: cannot read the manifest: no such file, nor a recipe (the "
                               "recipes: "),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("fast, "), std::string::npos) << result.output;
  std::ofstream(dir.path() / "fast.json") << R"({"pipeline": {"detector": {"plugin": "nosuch"}}})";
  result = RunTessera("extract --images images --output out3 --manifest fast.json", in_dir);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find((dir.path() / "fast.json").string()), std::string::npos)
      << result.output;
}

// A two-image text model in exactly the layout the COLMAP text writer produces.
void WriteSmallTextModel(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "cameras.txt") << "# Camera list with one line of data per camera:\n"
                                        "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                                        "# Number of cameras: 1\n"
                                        "1 SIMPLE_RADIAL 640 480 500 320 240 0.01\n";
  std::ofstream(dir / "images.txt") << "# Image list with two lines of data per image:\n"
                                       "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
                                       "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
                                       "# Number of images: 2, mean observations per image: 1\n"
                                       "1 1 0 0 0 0 0 0 1 a.jpg\n"
                                       "320 240 7 10 10 -1\n"
                                       "2 1 0 0 0 -1 0 0 1 b.jpg\n"
                                       "220 240 7\n";
  std::ofstream(dir / "points3D.txt")
      << "# 3D point list with one line of data per point:\n"
         "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
         "# Number of points: 1, mean track length: 2\n"
         "7 0 0 5 255 128 0 0.5 1 0 2 0\n";
}

TEST(Cli, ExportWritesAModelWithAnyExporterAndBackAgain) {
  testing::TemporaryDir dir;
  WriteSmallTextModel(dir.path() / "text");
  const auto to_binary =
      RunTessera("export --model " + (dir.path() / "text").string() +
                 " --format colmap_binary --output " + (dir.path() / "out").string());
  ASSERT_EQ(to_binary.exit_code, 0) << to_binary.output;
  EXPECT_NE(to_binary.output.find("export: 2 images, 1 points, 2 observations written with "
                                  "'colmap_binary' to " +
                                  (dir.path() / "out").string()),
            std::string::npos)
      << to_binary.output;
  const auto binary_dir = dir.path() / "out" / "sparse" / "0";
  ASSERT_TRUE(std::filesystem::is_regular_file(binary_dir / "points3D.bin"));

  // Binary back to text, as model 3: the very same bytes.
  const auto to_text =
      RunTessera("-q export --model " + binary_dir.string() + " --format colmap_text --output " +
                 (dir.path() / "out").string() + " --model-index 3");
  ASSERT_EQ(to_text.exit_code, 0) << to_text.output;
  EXPECT_EQ(to_text.output, "");
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_EQ(ReadFileContents(dir.path() / "out" / "sparse" / "3" / name),
              ReadFileContents(dir.path() / "text" / name))
        << name;
  }

  const auto ply =
      RunTessera("export --model " + binary_dir.string() + " --format ply --output " +
                 (dir.path() / "out").string() + R"( --options '{"camera_centers": true}')");
  ASSERT_EQ(ply.exit_code, 0) << ply.output;
  EXPECT_NE(ReadFileContents(binary_dir / "points3D.ply").find("element vertex 3\n"),
            std::string::npos);
}

TEST(Cli, ExportOfABadModelIsOneLineNamingTheFile) {
  testing::TemporaryDir dir;
  WriteSmallTextModel(dir.path());
  std::ofstream(dir.path() / "cameras.txt") << "1 PINHOLE 640 480 500 500 320\n";
  const auto result =
      RunTessera("export --model " + dir.path().string() + " --format colmap_binary --output " +
                 (dir.path() / "out").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_EQ(result.output, "[error] " + (dir.path() / "cameras.txt").string() +
                               " line 1: PINHOLE takes 4 parameters, found 3.\n");
  const auto missing = RunTessera("export --model " + (dir.path() / "none").string() +
                                  " --format ply --output " + (dir.path() / "out").string());
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find((dir.path() / "none").string() + " is not a COLMAP model"),
            std::string::npos)
      << missing.output;
}

// Four images at (0,0,0), (1,0,0), (0,1,0) and (0,0,1), looking down z: a text model,
// and its ground truth as a transforms.json with `centers` in place of those.
void WriteEvalModel(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "cameras.txt") << "1 SIMPLE_PINHOLE 640 480 500 320 240\n";
  std::ofstream(dir / "images.txt") << "1 1 0 0 0 0 0 0 1 a.jpg\n\n"
                                       "2 1 0 0 0 -1 0 0 1 b.jpg\n\n"
                                       "3 1 0 0 0 0 -1 0 1 c.jpg\n\n"
                                       "4 1 0 0 0 0 0 -1 1 d.jpg\n\n";
  std::ofstream(dir / "points3D.txt") << "";
}

std::filesystem::path WriteEvalGroundTruth(const std::filesystem::path& dir,
                                           const std::vector<std::string>& names,
                                           const std::vector<std::array<double, 3>>& centers) {
  nlohmann::json frames = nlohmann::json::array();
  for (size_t i = 0; i < names.size(); ++i) {
    const auto& c = centers[i];
    frames.push_back({{"file_path", "images/" + names[i]},
                      {"transform_matrix",
                       {{1, 0, 0, c[0]}, {0, -1, 0, c[1]}, {0, 0, -1, c[2]}, {0, 0, 0, 1}}}});
  }
  const auto file = dir / "transforms.json";
  std::ofstream(file) << nlohmann::json{{"frames", frames}}.dump();
  return file;
}

// Ground truth and models eval cannot judge were scored, mostly as perfect: exit 2 now,
// with one error line naming the file and the frame.
TEST(Cli, EvalRefusesGroundTruthAndModelsItCannotJudge) {
  testing::TemporaryDir dir;
  const auto model = dir.path() / "model";
  WriteEvalModel(model);
  const std::vector<std::string> names = {"a.jpg", "b.jpg", "c.jpg", "d.jpg"};
  const std::vector<std::array<double, 3>> centers = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
  const auto eval = [&](const std::filesystem::path& gt) {
    return RunTessera("eval " + model.string() + " " + gt.string());
  };
  const auto good = eval(WriteEvalGroundTruth(dir.path(), names, centers));
  ASSERT_EQ(good.exit_code, 0) << good.output;
  EXPECT_NE(good.output.find("registered: 4/4\nposition error (ground-truth units): mean "),
            std::string::npos)
      << good.output;

  const std::string gt = (dir.path() / "transforms.json").string();
  const auto duplicate =
      eval(WriteEvalGroundTruth(dir.path(), {"a.jpg", "b.jpg", "c.jpg", "d.jpg", "a.jpg"},
                                {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {5, 5, 5}}));
  EXPECT_EQ(duplicate.exit_code, 2) << duplicate.output;
  EXPECT_EQ(duplicate.output, "[error] " + gt +
                                  ": frames[4] (images/a.jpg) has the image name a.jpg of "
                                  "frames[0], so the two cannot be told apart.\n");

  const auto far = eval(
      WriteEvalGroundTruth(dir.path(), names, {{0, 0, 0}, {1e308, 0, 0}, {0, 2, 0}, {0, 0, 2}}));
  EXPECT_EQ(far.exit_code, 2) << far.output;
  EXPECT_EQ(far.output, "[error] " + gt +
                            ": frames[1] (images/b.jpg): the camera centre (1e+308, 0, 0) lies "
                            "beyond 1e+100.\n");

  const auto identical =
      eval(WriteEvalGroundTruth(dir.path(), names, {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}}));
  EXPECT_EQ(identical.exit_code, 2) << identical.output;
  EXPECT_NE(identical.output.find("[error] Cannot score " + model.string() + " against " + gt +
                                  ": the ground truth places the 4 images in both at only 1 "
                                  "distinct camera centre; aligning needs at least 3.\n"),
            std::string::npos)
      << identical.output;

  std::ofstream(model / "images.txt") << "1 1 0 0 0 0 0 0 1 a.jpg\n\n"
                                         "2 1 0 0 0 nan 0 0 1 b.jpg\n\n";
  const auto nan = eval(WriteEvalGroundTruth(dir.path(), names, centers));
  EXPECT_EQ(nan.exit_code, 2) << nan.output;
  EXPECT_EQ(nan.output, "[error] " + (model / "images.txt").string() +
                            " line 3: 'nan' is not a finite translation component.\n");
}

TEST(Cli, ExportOfAnUnknownFormatSuggestsTheClosest) {
  testing::TemporaryDir dir;
  WriteSmallTextModel(dir.path());
  const std::string command = "export --model " + dir.path().string() + " --output " +
                              (dir.path() / "out").string() + " --format ";
  const auto typo = RunTessera(command + "plyy");
  EXPECT_EQ(typo.exit_code, 2) << typo.output;
  EXPECT_NE(typo.output.find("exporter.plugin: no exporter plugin 'plyy'; did you mean 'ply'?"),
            std::string::npos)
      << typo.output;
  const auto bad_option = RunTessera(command + R"(ply --options '{"camera_centres": true}')");
  EXPECT_EQ(bad_option.exit_code, 2) << bad_option.output;
  EXPECT_NE(bad_option.output.find("exporter.options.camera_centres: unknown key; did you mean "
                                   "'camera_centers'?"),
            std::string::npos)
      << bad_option.output;
  const auto bad_json = RunTessera(command + "ply --options '{camera_centers: true}'");
  EXPECT_EQ(bad_json.exit_code, 2) << bad_json.output;
  EXPECT_NE(bad_json.output.find("--options: not valid JSON"), std::string::npos)
      << bad_json.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
}

TEST(Cli, AManifestThatIsAFolderIsExitCode2NamingIt) {
  testing::TemporaryDir dir;
  const auto result =
      RunTessera("run --images " + dir.path().string() + " --output " +
                 (dir.path() / "out").string() + " --manifest " + dir.path().string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(dir.path().string() +
                               ": cannot read the manifest: it is a folder, not a file"),
            std::string::npos)
      << result.output;
}

TEST(Cli, ANumberTooLargeForADoubleNamesItsKeyAndLine) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "huge.json";
  std::ofstream(manifest) << "{\"pipeline\": {},\n \"verification\": {\"max_error_px\": 1e400}}\n";
  const auto result = RunTessera("match --output " + (dir.path() / "out").string() +
                                 " --manifest " + manifest.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(manifest.string() +
                               ": invalid JSON at line 2 (key 'max_error_px'): the number "
                               "'1e400' is out of range"),
            std::string::npos)
      << result.output;
}

TEST(Cli, ExporterPathsMustStayInsideTheOutputFolder) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "exporters.json";
  const auto run = [&](const std::string& exporter) {
    std::ofstream(manifest) << R"({"pipeline": {"exporters": [)" << exporter << "]}}";
    return RunTessera("run --images " + (dir.path() / "none").string() + " --output " +
                      (dir.path() / "a" / "b").string() + " --manifest " + manifest.string());
  };
  const auto up = run(R"({"plugin": "transforms_json", "options": {"file": "../../escape.json"}})");
  EXPECT_EQ(up.exit_code, 2) << up.output;
  EXPECT_NE(up.output.find("pipeline.exporters[0].options.file: '../../escape.json' leaves the "
                           "output folder (\"..\"); it must be a relative path inside the output "
                           "folder"),
            std::string::npos)
      << up.output;
  const auto absolute =
      run(R"({"plugin": "gaussian_splatting", "options": {"folder": "/tmp/splat"}})");
  EXPECT_EQ(absolute.exit_code, 2) << absolute.output;
  EXPECT_NE(absolute.output.find("pipeline.exporters[0].options.folder: '/tmp/splat' is absolute"),
            std::string::npos)
      << absolute.output;
  const auto inside = run(R"({"plugin": "transforms_json", "options": {"file": "a/..x/t.json"}})");
  EXPECT_EQ(inside.output.find("options.file"), std::string::npos) << inside.output;
  // The export verb uses the same exporters, so the same check.
  WriteSmallTextModel(dir.path() / "model");
  const auto exported = RunTessera(
      "export --model " + (dir.path() / "model").string() + " --format transforms_json --output " +
      (dir.path() / "out").string() + R"( --options '{"file": "../escape.json"}')");
  EXPECT_EQ(exported.exit_code, 2) << exported.output;
  EXPECT_NE(exported.output.find("exporter.options.file: '../escape.json' leaves"),
            std::string::npos)
      << exported.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "escape.json"));
}

TEST(Cli, ASecondWriterOfAWorkspaceIsRefusedNamingTheFirst) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  const WorkspaceLock lock(workspace);
  for (const std::string& verb : {"extract --images " + dir.path().string(), std::string("match"),
                                  std::string("map"), "run --images " + dir.path().string()}) {
    const auto result = RunTessera(verb + " --output " + workspace.string());
    EXPECT_EQ(result.exit_code, 2) << verb << ": " << result.output;
    EXPECT_NE(result.output.find("workspace " + workspace.string() + " is in use by process " +
                                 std::to_string(getpid()) + " (since "),
              std::string::npos)
        << verb << ": " << result.output;
  }
  EXPECT_FALSE(std::filesystem::exists(workspace / "database.db"));
}

// --threads is bounded as the manifest's "threads" is: 65537 threads crashed OpenCV's
// TBB at exit, and -1 was answered with DBL_MAX written out.
TEST(Cli, ThreadsOutsideZeroTo1024AreRefusedByEveryVerb) {
  testing::TemporaryDir dir;
  for (const std::string& verb :
       {"run --images " + dir.path().string() + " --output " + (dir.path() / "o").string(),
        "extract --images " + dir.path().string() + " --output " + (dir.path() / "o").string(),
        "match --output " + (dir.path() / "o").string(),
        "bench --images " + dir.path().string() + " --output " + (dir.path() / "o").string(),
        "vocab --images " + dir.path().string() + " --output " + (dir.path() / "c").string()}) {
    for (const std::string threads : {"65537", "-1"}) {
      const auto result = RunTessera(verb + " --threads " + threads);
      EXPECT_EQ(result.exit_code, 2) << verb << ": " << result.output;
      EXPECT_NE(result.output.find("--threads: Value " + threads + " not in range 0 to 1024"),
                std::string::npos)
          << verb << ": " << result.output;
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "o"));
}

// CLI11's PositiveNumber wrote its upper bound, DBL_MAX, out in 309 digits.
TEST(Cli, ANumberBelowItsMinimumIsRefusedPlainly) {
  for (const std::string value : {"-1", "0", "2.5"}) {
    const auto result = RunTessera("gui --screenshot /nonexistent/s.png --frames " + value);
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_EQ(result.output.rfind(
                  "--frames: Value " + value + " is not a whole number of at least 1\n", 0),
              0u)
        << result.output;
  }
}

// An image folder that is the output folder, or lies where models are replaced, is
// refused before anything is written: the photos stay as they were, and no lock or
// database is left among them.
TEST(Cli, AnImageFolderInTheOutputsPlaceIsRefusedBeforeAnythingIsWritten) {
  testing::TemporaryDir dir;
  const auto images = dir.path() / "out" / "sparse" / "3";
  std::filesystem::create_directories(images);
  std::ofstream(images / "a.jpg") << "not really a photo";
  for (const std::string& verb : {std::string("run"), std::string("extract")}) {
    const auto inside = RunTessera(verb + " --images " + images.string() + " --output " +
                                   (dir.path() / "out").string());
    EXPECT_EQ(inside.exit_code, 2) << inside.output;
    EXPECT_NE(inside.output.find(images.string() + ": the image folder lies in " +
                                 (dir.path() / "out" / "sparse").string()),
              std::string::npos)
        << inside.output;
    const auto same =
        RunTessera(verb + " --images " + images.string() + " --output " + images.string());
    EXPECT_EQ(same.exit_code, 2) << same.output;
    EXPECT_NE(same.output.find("the image folder is the output folder of this run"),
              std::string::npos)
        << same.output;
  }
  EXPECT_TRUE(std::filesystem::exists(images / "a.jpg"));
  EXPECT_FALSE(std::filesystem::exists(images / ".tessera.lock"));
  EXPECT_FALSE(std::filesystem::exists(images / "database.db"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "database.db"));
}

// -v and -q work after the verb as before it.
TEST(Cli, VerboseAndQuietAreTakenAfterTheVerb) {
  testing::TemporaryDir dir;
  WriteSmallTextModel(dir.path() / "text");
  const std::string export_command = "export --model " + (dir.path() / "text").string() +
                                     " --format ply --output " + (dir.path() / "out").string();
  const auto loud = RunTessera(export_command);
  ASSERT_EQ(loud.exit_code, 0) << loud.output;
  EXPECT_NE(loud.output.find("[info] export:"), std::string::npos) << loud.output;
  const auto quiet = RunTessera(export_command + " -q");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
  EXPECT_EQ(RunTessera("plugins -v").exit_code, 0);
  const auto unknown = RunTessera("plugins --verbosest");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
}

// `bench` replaces a row's workspace only when it made it (.tessera_bench): a folder of
// the user's where a row would go is refused before any row runs, and left as it was.
TEST(Cli, BenchReplacesOnlyTheWorkspacesItMade) {
  testing::TemporaryDir dir;
  const auto theirs = dir.path() / "o" / "tessera" / "default";  // the Tessera row's folder
  std::filesystem::create_directories(theirs);
  std::ofstream(theirs / "notes.txt") << "mine";
  const std::string manifest = (testing::SourceDir() / "manifests" / "default.json").string();
  const auto result = RunTessera("bench --images " + dir.path().string() + " --output " +
                                 (dir.path() / "o").string() + " " + manifest);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(theirs.string() + ": exists and was not made by tessera bench"),
            std::string::npos)
      << result.output;
  EXPECT_TRUE(std::filesystem::exists(theirs / "notes.txt"));
}

// The verbs beside the stages take the same lock: `vocab --workspace`, `merge`, and
// `export` and `eval` of a model in the workspace (or `export` into it).
TEST(Cli, EveryVerbThatTouchesAWorkspaceTakesItsLock) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  const WorkspaceLock lock(workspace);
  WriteSmallTextModel(workspace / "sparse" / "0");
  WriteSmallTextModel(dir.path() / "model");
  const std::string model = (workspace / "sparse" / "0").string();
  for (const std::string& verb :
       {"vocab --images " + dir.path().string() + " --output " + (dir.path() / "c.bin").string() +
            " --workspace " + workspace.string(),
        "merge --output " + workspace.string() + " --stage extract",
        "export --model " + model + " --format ply --output " + (dir.path() / "e").string(),
        "export --model " + (dir.path() / "model").string() + " --format ply --output " +
            workspace.string(),
        "eval " + model + " " + model}) {
    const auto result = RunTessera(verb);
    EXPECT_EQ(result.exit_code, 2) << verb << ": " << result.output;
    EXPECT_NE(result.output.find("workspace " + workspace.string() + " is in use by process " +
                                 std::to_string(getpid()) + " (since "),
              std::string::npos)
        << verb << ": " << result.output;
  }
  EXPECT_FALSE(std::filesystem::exists(workspace / "database.db"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "e"));
}

}  // namespace
}  // namespace tessera
