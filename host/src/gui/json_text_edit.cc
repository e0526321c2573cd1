#include "gui/json_text_edit.h"

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <vector>

namespace tessera::gui {
namespace {

constexpr size_t kNone = std::string::npos;

size_t SkipSpace(const std::string& text, size_t at) {
  while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at]))) ++at;
  return at;
}

// The end (one past) of the string starting at `at` ('"'); kNone when unterminated.
size_t StringEnd(const std::string& text, size_t at) {
  for (size_t i = at + 1; i < text.size(); ++i) {
    if (text[i] == '\\') {
      ++i;
    } else if (text[i] == '"') {
      return i + 1;
    }
  }
  return kNone;
}

// The end (one past) of the JSON value starting at `at`; kNone when it does not end.
size_t ValueEnd(const std::string& text, size_t at) {
  if (at >= text.size()) return kNone;
  if (text[at] == '"') return StringEnd(text, at);
  if (text[at] == '{' || text[at] == '[') {
    int depth = 0;
    for (size_t i = at; i < text.size(); ++i) {
      if (text[i] == '"') {
        i = StringEnd(text, i);
        if (i == kNone) return kNone;
        --i;
      } else if (text[i] == '{' || text[i] == '[') {
        ++depth;
      } else if ((text[i] == '}' || text[i] == ']') && --depth == 0) {
        return i + 1;
      }
    }
    return kNone;
  }
  size_t i = at;
  while (i < text.size() && text[i] != ',' && text[i] != '}' && text[i] != ']' &&
         !std::isspace(static_cast<unsigned char>(text[i]))) {
    ++i;
  }
  return i;
}

// A member of an object: where its key starts (its '"'), where its value starts and
// ends (one past), and its name.
struct Member {
  size_t key = kNone;
  size_t value = kNone;
  size_t end = kNone;
  std::string name;
};

// The members of the object whose '{' is at `open`, as far as they read as JSON;
// *complete: whether the object's '}' was reached.
std::vector<Member> Members(const std::string& text, size_t open, bool* complete) {
  std::vector<Member> members;
  *complete = false;
  size_t at = SkipSpace(text, open + 1);
  while (at < text.size() && text[at] == '"') {
    Member member;
    member.key = at;
    const size_t key_end = StringEnd(text, at);
    if (key_end == kNone) return members;
    member.name = text.substr(at + 1, key_end - at - 2);
    size_t value = SkipSpace(text, key_end);
    if (value >= text.size() || text[value] != ':') return members;
    member.value = SkipSpace(text, value + 1);
    member.end = ValueEnd(text, member.value);
    members.push_back(member);
    if (member.end == kNone) return members;
    at = SkipSpace(text, member.end);
    if (at >= text.size() || text[at] != ',') break;
    at = SkipSpace(text, at + 1);
  }
  *complete = at < text.size() && text[at] == '}';
  return members;
}

// In the object whose '{' is at `open`, where the value of `key` starts; kNone when the
// object has no such key.
size_t FindMember(const std::string& text, size_t open, const std::string& key) {
  bool complete = false;
  for (const Member& member : Members(text, open, &complete)) {
    if (member.name == key) return member.value;
  }
  return kNone;
}

// `member` ("KEY": VALUE) put first in the object whose '{' is at `open`.
std::string InsertFirst(const std::string& text, size_t open, const std::string& member) {
  const bool empty = text[SkipSpace(text, open + 1)] == '}';
  return text.substr(0, open + 1) + member + (empty ? "" : ", ") + text.substr(open + 1);
}

// The starts of the elements of the array whose '[' is at `open`, as far as they read.
std::vector<size_t> Elements(const std::string& text, size_t open) {
  std::vector<size_t> elements;
  size_t at = SkipSpace(text, open + 1);
  while (at < text.size() && text[at] != ']') {
    elements.push_back(at);
    const size_t end = ValueEnd(text, at);
    if (end == kNone) break;
    at = SkipSpace(text, end);
    if (at >= text.size() || text[at] != ',') break;
    at = SkipSpace(text, at + 1);
  }
  return elements;
}

// Where the value at `steps` (object keys, or an array's index in decimal) starts; kNone
// when the text has none.
size_t FindPath(const std::string& text, const std::vector<std::string>& steps) {
  size_t at = SkipSpace(text, 0);
  for (const std::string& step : steps) {
    if (at >= text.size()) return kNone;
    if (text[at] == '{') {
      at = FindMember(text, at, step);
    } else if (text[at] == '[' && !step.empty() && step.size() < 10 &&
               std::all_of(step.begin(), step.end(),
                           [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
      const std::vector<size_t> elements = Elements(text, at);
      const size_t index = std::stoul(step);
      at = index < elements.size() ? elements[index] : kNone;
    } else {
      return kNone;
    }
    if (at == kNone) return kNone;
  }
  return at;
}

// `member` ("KEY": VALUE) put after the last member of the object whose '{' is at `open`.
std::optional<std::string> InsertLast(const std::string& text, size_t open,
                                      const std::string& member) {
  bool complete = false;
  const std::vector<Member> members = Members(text, open, &complete);
  if (!complete) return std::nullopt;
  if (members.empty()) return InsertFirst(text, open, member);
  const size_t end = members.back().end;
  return text.substr(0, end) + ", " + member + text.substr(end);
}

// `text` without the member `key` of the object whose '{' is at `open` (its comma goes
// with it); the text as it is when the object has no such key.
std::optional<std::string> RemoveMember(const std::string& text, size_t open,
                                        const std::string& key) {
  bool complete = false;
  const std::vector<Member> members = Members(text, open, &complete);
  if (!complete) return std::nullopt;
  const auto found = std::find_if(members.begin(), members.end(),
                                  [&](const Member& member) { return member.name == key; });
  if (found == members.end()) return text;
  const size_t index = static_cast<size_t>(found - members.begin());
  if (index + 1 < members.size()) {
    // Up to the next key: the next member takes this one's place and indentation.
    return text.substr(0, found->key) + text.substr(members[index + 1].key);
  }
  if (index > 0) {
    // The last: from the end of the member before it (its comma goes too).
    return text.substr(0, members[index - 1].end) + text.substr(found->end);
  }
  return text.substr(0, open + 1) + text.substr(found->end);
}

}  // namespace

std::optional<std::string> SetPluginInText(const std::string& text, const std::string& slot,
                                           const std::string& plugin) {
  const std::string name = nlohmann::json(plugin).dump();  // quoted and escaped
  const size_t root = SkipSpace(text, 0);
  if (root >= text.size() || text[root] != '{') return std::nullopt;
  const size_t pipeline = FindMember(text, root, "pipeline");
  if (pipeline == kNone || text[pipeline] != '{') return std::nullopt;
  const size_t value = FindMember(text, pipeline, slot);
  if (value == kNone) {
    return InsertFirst(text, pipeline,
                       nlohmann::json(slot).dump() + ": {\"plugin\": " + name + "}");
  }
  const size_t value_end = ValueEnd(text, value);
  if (value_end == kNone) return std::nullopt;
  if (text[value] != '{') {
    return text.substr(0, value) + "{\"plugin\": " + name + "}" + text.substr(value_end);
  }
  const size_t current = FindMember(text, value, "plugin");
  if (current == kNone) return InsertFirst(text, value, "\"plugin\": " + name);
  const size_t current_end = ValueEnd(text, current);
  if (current_end == kNone) return std::nullopt;
  return text.substr(0, current) + name + text.substr(current_end);
}

std::optional<std::string> RemoveOptionsInText(const std::string& text, const std::string& slot,
                                               const std::vector<std::string>& keys) {
  std::string edited = text;
  for (const std::string& key : keys) {
    // Found anew for each key: the text before it has changed.
    const size_t options = FindPath(edited, {"pipeline", slot, "options"});
    if (options == kNone || edited[options] != '{') return std::nullopt;
    const std::optional<std::string> removed = RemoveMember(edited, options, key);
    if (!removed) return std::nullopt;
    edited = *removed;
  }
  return edited;
}

std::string MarkDescriptionEditedInText(const std::string& text) {
  const size_t root = SkipSpace(text, 0);
  if (root >= text.size() || text[root] != '{') return text;
  const size_t value = FindMember(text, root, "description");
  if (value == kNone || text[value] != '"') return text;
  if (text.compare(value + 1, kEditedDescription.size(), kEditedDescription) == 0) return text;
  return text.substr(0, value + 1) + std::string(kEditedDescription) + text.substr(value + 1);
}

std::optional<std::string> SetOptionInText(const std::string& text,
                                           const std::vector<std::string>& slot_steps,
                                           const std::string& key,
                                           const std::optional<nlohmann::json>& value) {
  const size_t slot = FindPath(text, slot_steps);
  if (slot == kNone || text[slot] != '{') return std::nullopt;
  const size_t options = FindMember(text, slot, "options");
  if (options != kNone && text[options] != '{') return std::nullopt;
  if (value) {
    const std::string member = nlohmann::json(key).dump() + ": " + value->dump();
    if (options == kNone) return InsertLast(text, slot, "\"options\": {" + member + "}");
    const size_t current = FindMember(text, options, key);
    if (current == kNone) return InsertLast(text, options, member);
    const size_t current_end = ValueEnd(text, current);
    if (current_end == kNone) return std::nullopt;
    return text.substr(0, current) + value->dump() + text.substr(current_end);
  }
  if (options == kNone) return text;
  const std::optional<std::string> removed = RemoveMember(text, options, key);
  if (!removed) return std::nullopt;
  // The edit was after the slot's '{' and the options' '{': both are where they were.
  bool complete = false;
  if (Members(*removed, options, &complete).empty() && complete) {
    return RemoveMember(*removed, slot, "options");
  }
  return removed;
}

}  // namespace tessera::gui
