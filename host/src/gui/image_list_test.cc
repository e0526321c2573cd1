#include "gui/image_list.h"

#include <gtest/gtest.h>

#include "gui/image_list_test_workspace.h"
#include "tessera/errors.h"
#include "test_support.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

TEST(ImageList, ListsEveryImageWithItsModelOrWhyItWasLeftOut) {
  tessera::testing::TemporaryDir dir;
  WriteImageListWorkspace(dir.path(), /*with_summary=*/true);
  const ImageList list = ReadImageList(dir.path(), dir.path() / "images");
  ASSERT_EQ(list.entries.size(), 5u);  // the database's four, then late.png; not notes.txt
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(list.entries[i].name, "frame_" + std::to_string(i + 1) + ".jpg");
    EXPECT_EQ(list.entries[i].model, 0);
    EXPECT_EQ(list.entries[i].reason, "");
  }
  // The summary's reason, not sparse/1 (which the summary does not list).
  EXPECT_EQ(list.entries[3].name, "frame_4.jpg");
  EXPECT_EQ(list.entries[3].model, kInNoModel);
  EXPECT_EQ(list.entries[3].reason, kLeftOutReason);
  EXPECT_EQ(list.entries[4].name, "late.png");
  EXPECT_EQ(list.entries[4].model, kInNoModel);
  EXPECT_NE(list.entries[4].reason.find("not in the workspace database"), std::string::npos)
      << list.entries[4].reason;
  EXPECT_EQ(list.NumInModels(), 3u);
}

TEST(ImageList, WithoutASummaryTheModelsSayWhichImagesTheyHold) {
  tessera::testing::TemporaryDir dir;
  WriteImageListWorkspace(dir.path(), /*with_summary=*/false);
  const ImageList list = ReadImageList(dir.path(), "");  // no Images folder: not listed
  ASSERT_EQ(list.entries.size(), 4u);
  EXPECT_EQ(list.entries[0].model, 0);
  EXPECT_EQ(list.entries[3].name, "frame_4.jpg");
  EXPECT_EQ(list.entries[3].model, 1);
  fs::remove_all(dir.path() / "sparse" / "1");
  const ImageList without = ReadImageList(dir.path(), "");
  EXPECT_EQ(without.entries[3].model, kInNoModel);
  EXPECT_EQ(without.entries[3].reason, "in no model (no mapping_summary.json records why)");
}

TEST(ImageList, AModelFolderAloneListsItsImages) {
  tessera::testing::TemporaryDir dir;
  WriteImageListWorkspace(dir.path(), /*with_summary=*/false);
  const ImageList list = ReadImageList(dir.path() / "sparse" / "0", dir.path() / "images");
  ASSERT_EQ(list.entries.size(), 5u);  // the model's three, then the folder's others
  EXPECT_EQ(list.NumInModels(), 3u);
  EXPECT_EQ(list.entries[3].name, "frame_4.jpg");
  EXPECT_EQ(list.entries[3].reason, "in no model");
}

TEST(ImageList, ABrokenSummaryIsNamed) {
  tessera::testing::TemporaryDir dir;
  WriteImageListWorkspace(dir.path(), /*with_summary=*/false);
  std::ofstream(dir.path() / "mapping_summary.json") << "{";
  try {
    ReadImageList(dir.path(), "");
    FAIL() << "a broken mapping_summary.json must be refused";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("mapping_summary.json"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera::gui
