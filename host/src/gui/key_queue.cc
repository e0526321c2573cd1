#include "gui/key_queue.h"

#include <imgui.h>

#include <algorithm>
#include <vector>

namespace tessera::gui {
namespace {

bool Held(const ImGuiIO& io, const int (&keys)[2]) {
  for (const int key : keys) {
    if (key >= 0 && key < IM_ARRAYSIZE(io.KeysDown) && io.KeysDown[key]) return true;
  }
  return false;
}

}  // namespace

bool KeyQueue::IsModifier(int key) const {
  for (const int(*pair)[2] :
       {&modifiers_.ctrl, &modifiers_.shift, &modifiers_.alt, &modifiers_.super}) {
    if (key == (*pair)[0] || key == (*pair)[1]) return true;
  }
  return false;
}

bool KeyQueue::Matters(const ImGuiIO& io, int key) const {
  if (IsModifier(key)) return true;
  if (std::find(std::begin(io.KeyMap), std::end(io.KeyMap), key) == std::end(io.KeyMap)) {
    return false;
  }
  // The letters of the shortcuts (Ctrl+A, Ctrl+C, ...; GLFW's letter keys are their ASCII
  // capitals) matter only with Ctrl or Super held; typed, their characters say it all.
  const bool letter = key >= 'A' && key <= 'Z';
  return !letter || Held(io, modifiers_.ctrl) || Held(io, modifiers_.super);
}

void KeyQueue::ApplyFrame(ImGuiIO* io) {
  std::vector<int> changed;  // the keys that matter changed this frame
  bool typed = false;        // characters added this frame
  bool acted = false;        // a key that matters, not a modifier, changed this frame
  while (!events_.empty()) {
    const Event& event = events_.front();
    if (event.is_char) {
      if (acted) break;  // Return, then characters: the characters go after it
      io->AddInputCharacter(event.codepoint);
      typed = true;
    } else {
      if (Matters(*io, event.key)) {
        if (typed || acted ||
            std::find(changed.begin(), changed.end(), event.key) != changed.end()) {
          break;
        }
        changed.push_back(event.key);
        if (!IsModifier(event.key)) acted = true;
      }
      if (event.key >= 0 && event.key < IM_ARRAYSIZE(io->KeysDown)) {
        io->KeysDown[event.key] = event.down;
      }
    }
    events_.pop_front();
  }
  io->KeyCtrl = Held(*io, modifiers_.ctrl);
  io->KeyShift = Held(*io, modifiers_.shift);
  io->KeyAlt = Held(*io, modifiers_.alt);
  io->KeySuper = Held(*io, modifiers_.super);
}

}  // namespace tessera::gui
