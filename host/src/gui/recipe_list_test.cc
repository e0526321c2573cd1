#include "gui/recipe_list.h"

#include <gtest/gtest.h>

#include <fstream>

#include "test_support.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

// The recipes are the .json files, sorted, each with its "description"; one that cannot
// be read is listed with why; other files and folders are not recipes.
TEST(RecipeList, ListsTheJsonFilesWithTheirDescriptions) {
  testing::TemporaryDir dir;
  std::ofstream(dir.path() / "b.json") << R"({"description": "the second", "seed": 0})";
  std::ofstream(dir.path() / "a.json") << R"({"seed": 0})";
  std::ofstream(dir.path() / "broken.json") << "{";
  std::ofstream(dir.path() / "notes.txt") << "not a recipe";
  fs::create_directories(dir.path() / "folder.json");
  const std::vector<Recipe> recipes = FindRecipes(dir.path());
  ASSERT_EQ(recipes.size(), 3u);
  EXPECT_EQ(recipes[0].name, "a");
  EXPECT_EQ(recipes[0].description, "");
  EXPECT_EQ(recipes[1].name, "b");
  EXPECT_EQ(recipes[1].file, dir.path() / "b.json");
  EXPECT_EQ(recipes[1].description, "the second");
  EXPECT_EQ(recipes[2].name, "broken");
  EXPECT_NE(recipes[2].description.find("invalid JSON"), std::string::npos);
  EXPECT_TRUE(FindRecipes(dir.path() / "missing").empty());
}

// The repository's manifests/ (copied beside the executable), the list's default folder:
// every recipe there describes itself.
TEST(RecipeList, TheShippedRecipesHaveDescriptions) {
  RecipeList list;
  ASSERT_NE(list.Find("default"), nullptr) << list.folder();
  ASSERT_NE(list.Find("fast"), nullptr);
  for (const Recipe& recipe : FindRecipes(list.folder())) {
    EXPECT_FALSE(recipe.description.empty()) << recipe.file;
  }
  EXPECT_EQ(list.Find("no_such_recipe"), nullptr);
}

}  // namespace
}  // namespace tessera::gui

namespace tessera::gui {
namespace {

// The source tree's manifests/fast.json is the recipe "fast" of the list (a copy of it
// beside the executable): the same name and bytes; a changed copy is another file.
TEST(RecipeList, ACopyOfARecipeIsThatRecipe) {
  RecipeList list;
  const std::filesystem::path source = testing::SourceDir() / "manifests" / "fast.json";
  const Recipe* current = list.Current(source.string());
  ASSERT_NE(current, nullptr);
  EXPECT_EQ(current->name, "fast");
  testing::TemporaryDir dir;
  std::filesystem::copy_file(source, dir.path() / "fast.json");
  std::ofstream(dir.path() / "fast.json", std::ios::app) << "\n";
  EXPECT_EQ(list.Current((dir.path() / "fast.json").string()), nullptr);
}

}  // namespace
}  // namespace tessera::gui
