#pragma once

// The window's key and character events in the order they came, fed to ImGui a frame at a
// time. ImGui 1.86 reads the keys' state (io.KeysDown) when a frame starts, not the
// events between two frames: while the window was busy drawing, a key pressed and
// released before the next frame (Return, Ctrl+A) was never seen, and typed characters
// landed where the cursor was instead of over the selection. Each frame takes the events
// up to the first that would change what an earlier one of the frame meant to ImGui.

#include <cstddef>
#include <deque>

struct ImGuiIO;

namespace tessera::gui {

class KeyQueue {
 public:
  // The window system's codes of the modifier keys, left and right (GLFW's).
  struct ModifierKeys {
    int ctrl[2];
    int shift[2];
    int alt[2];
    int super[2];
  };
  explicit KeyQueue(const ModifierKeys& modifiers) : modifiers_(modifiers) {}

  // A key pressed (down) or released, as an io.KeysDown index (GLFW's key code); repeats
  // are not queued (ImGui repeats a key held itself).
  void PushKey(int key, bool down) { events_.push_back({false, key, down, 0}); }
  void PushChar(unsigned int codepoint) { events_.push_back({true, 0, false, codepoint}); }
  bool empty() const { return events_.empty(); }
  size_t size() const { return events_.size(); }

  // Applies this frame's events to `io` (before ImGui::NewFrame) and sets the modifier
  // flags from the keys held. A frame takes the events up to, not including: a key
  // ImGui acts on (a modifier, a key of io.KeyMap other than a letter typed without Ctrl
  // or Super) that changes again, or follows characters or another such key that is not
  // a modifier; a character that follows such a key. Letters typed without Ctrl go with
  // their characters, so a typed path takes one frame.
  void ApplyFrame(ImGuiIO* io);

 private:
  struct Event {
    bool is_char;
    int key;
    bool down;
    unsigned int codepoint;
  };
  bool IsModifier(int key) const;
  // Whether ImGui acts on `key` changing, with the modifiers now held in `io`.
  bool Matters(const ImGuiIO& io, int key) const;

  ModifierKeys modifiers_;
  std::deque<Event> events_;
};

}  // namespace tessera::gui
