#include "gui/model_loader.h"

#include <gtest/gtest.h>

#include <fstream>

#include "small_colmap_model.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "test_support.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

TEST(ModelLoader, FindsAModelFolderAWorkspaceAndItsDatabase) {
  testing::TemporaryDir dir;
  const Reconstruction model = testing::SmallColmapModel();
  WriteColmapModel(model, dir.path() / "sparse" / "1", ColmapModelFormat::kText);
  WriteColmapModel(model, dir.path() / "sparse" / "0", ColmapModelFormat::kBinary);
  fs::create_directories(dir.path() / "sparse" / "2");  // empty: not a model
  EXPECT_EQ(FindModelFolders(dir.path() / "sparse" / "1"),
            std::vector<fs::path>{dir.path() / "sparse" / "1"});
  const std::vector<fs::path> expected = {dir.path() / "sparse" / "0", dir.path() / "sparse" / "1"};
  EXPECT_EQ(FindModelFolders(dir.path()), expected);
  std::ofstream(dir.path() / "database.db") << "";
  EXPECT_EQ(FindModelFolders(dir.path() / "database.db"), expected);
  // The model picker's counts, read from the files' heads.
  EXPECT_EQ(CountModelImages(dir.path() / "sparse" / "0"), model.images.size());
  EXPECT_EQ(CountModelImages(dir.path() / "sparse" / "1"), model.images.size());
  EXPECT_EQ(CountModelImages(dir.path() / "sparse" / "2"), std::nullopt);
  EXPECT_EQ(CountModelPoints(dir.path() / "sparse" / "0"), model.points3D.size());
  EXPECT_EQ(CountModelPoints(dir.path() / "sparse" / "1"), model.points3D.size());
  EXPECT_EQ(CountModelPoints(dir.path() / "sparse" / "2"), std::nullopt);
}

TEST(ModelLoader, RefusesWhatIsNotAModelNamingIt) {
  testing::TemporaryDir dir;
  try {
    FindModelFolders(dir.path());
    FAIL() << "an empty folder is not a model";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              dir.path().string() +
                  ": not a model: no cameras, images and points3D (.bin or .txt) in it, and no "
                  "sparse/N model folders beside a workspace database");
  }
  EXPECT_THROW(FindModelFolders(dir.path() / "missing"), InputError);
  std::ofstream(dir.path() / "notes.txt") << "x";
  EXPECT_THROW(FindModelFolders(dir.path() / "notes.txt"), InputError);
}

}  // namespace
}  // namespace tessera::gui
