#include "gui/key_queue.h"

#include <gtest/gtest.h>
#include <imgui.h>

#include <string>

namespace tessera::gui {
namespace {

// GLFW's codes: the letters are their ASCII capitals, Return 257, left Ctrl 341.
constexpr int kReturn = 257;
constexpr int kLeftCtrl = 341;

class KeyQueueTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.KeyMap[ImGuiKey_A] = 'A';
    io.KeyMap[ImGuiKey_Enter] = kReturn;
  }
  void TearDown() override { ImGui::DestroyContext(); }

  // One frame's events applied; what ImGui would see: the keys held and the characters.
  std::string Frame() {
    ImGuiIO& io = ImGui::GetIO();
    io.InputQueueCharacters.resize(0);
    queue_.ApplyFrame(&io);
    std::string seen;
    if (io.KeyCtrl) seen += "ctrl ";
    if (io.KeysDown['A']) seen += "A ";
    if (io.KeysDown[kReturn]) seen += "return ";
    for (const ImWchar c : io.InputQueueCharacters) seen += static_cast<char>(c);
    return seen;
  }

  KeyQueue queue_{{{kLeftCtrl, 345}, {340, 344}, {342, 346}, {343, 347}}};
};

// What a busy window's one poll collects: Ctrl+A, a path typed, Return. Given at once
// ImGui saw none of the keys down; a frame at a time, each is seen, in order.
TEST_F(KeyQueueTest, KeysPressedAndReleasedBetweenTwoFramesEachGetAFrame) {
  queue_.PushKey(kLeftCtrl, true);
  queue_.PushKey('A', true);
  queue_.PushKey('A', false);
  queue_.PushKey(kLeftCtrl, false);
  for (const char c : std::string("/a/b")) {
    if (c == 'a') queue_.PushKey('A', true);
    queue_.PushChar(static_cast<unsigned char>(c));
    if (c == 'a') queue_.PushKey('A', false);
  }
  queue_.PushKey(kReturn, true);
  queue_.PushKey(kReturn, false);
  EXPECT_EQ(Frame(), "ctrl A ");  // Ctrl+A
  EXPECT_EQ(Frame(), "ctrl ");    // A released
  EXPECT_EQ(Frame(), "/a/b");     // Ctrl released, then the path in one frame
  EXPECT_EQ(Frame(), "return ");
  EXPECT_EQ(Frame(), "");
  EXPECT_TRUE(queue_.empty());
}

TEST_F(KeyQueueTest, CharactersAfterReturnWaitForTheNextFrame) {
  queue_.PushChar('x');
  queue_.PushKey(kReturn, true);
  queue_.PushChar('y');
  EXPECT_EQ(Frame(), "x");
  EXPECT_EQ(Frame(), "return ");
  EXPECT_EQ(Frame(), "return y");
}

}  // namespace
}  // namespace tessera::gui
