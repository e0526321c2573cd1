#include "gui/option_form_view.h"

#include <imgui.h>

#include <algorithm>
#include <array>

#include "gui/json_text_edit.h"
#include "gui/panel_widgets.h"
#include "plugin/option_descriptions.h"
#include "plugin/plugin_registry.h"
#include "tessera/errors.h"
#include "tessera/options.h"

namespace tessera::gui {
namespace {

// The colour of an option's name whose value is not its default.
const ImVec4 kChangedColor(1.0f, 0.78f, 0.3f, 1.0f);
const ImVec4 kErrorColor(1.0f, 0.35f, 0.3f, 1.0f);

// "default 8192, [1, 1000000]" (and "changed: " first when the value is not the default).
std::string DefaultLine(const OptionField& field) {
  std::string line = "default " + OptionValueText(field.option.default_value);
  const std::string range = OptionRangeText(field.option);
  if (!range.empty()) line += (field.option.choices.empty() ? ", " : ", one of ") + range;
  return field.differs ? "changed; " + line : line;
}

// The whole of an option as its name's tooltip: name, help, type, default, range.
std::string OptionTip(const OptionField& field) {
  return field.option.name + " (" + field.option.type + "): " + field.option.help + ". " +
         DefaultLine(field);
}

// The record a run loads for KIND NAME: the first usable one; null when none.
const PluginRecord* RecordOf(const PluginRegistry& registry, const std::string& kind,
                             const std::string& name) {
  for (const PluginRecord& record : registry.records()) {
    if (record.usable() && record.kind == kind && record.name == name) return &record;
  }
  return nullptr;
}

// A line drawn in `color`, cut to the width left, the whole in a tooltip.
void ColoredFitText(const std::string& text, const ImVec4& color, WidgetRects* widgets) {
  ImGui::PushStyleColor(ImGuiCol_Text, color);
  FitText(text, widgets);
  ImGui::PopStyleColor();
}

}  // namespace

const OptionFormView::Described& OptionFormView::Describe(const std::string& kind,
                                                          const std::string& plugin) {
  const std::string id = kind + " " + plugin;
  if (const auto found = described_.find(id); found != described_.end()) return found->second;
  Described described;
  const PluginRecord* record = registry_ ? RecordOf(*registry_, kind, plugin) : nullptr;
  if (record == nullptr) {
    described.note = "no usable " + kind + " plugin '" + plugin + "' on the plugin path";
  } else {
    try {
      described.options = registry_->DescribeOptions(*record);
      if (!described.options) described.note = kNoDescription;
    } catch (const std::exception& error) {
      // A malformed description is the plugin's fault, not the manifest's: said, and
      // its options are edited as JSON.
      described.error = error.what();
    }
  }
  return described_[id] = std::move(described);
}

void OptionFormView::Update(const std::string& text, const PluginRegistry* registry) {
  if (updated_ && registry == registry_ && text == text_) return;
  if (registry != registry_) described_.clear();
  registry_ = registry;
  text_ = text;
  updated_ = true;
  slots_.clear();
  problems_.clear();
  problem_fields_.clear();
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  parsed_ = !json.is_discarded();
  if (!parsed_) return;
  for (const FormSlot& form_slot : FormSlots(json)) {
    Slot slot;
    slot.slot = form_slot;
    const std::string options_path = form_slot.json_path + ".options";
    if (form_slot.plugin.empty()) {
      slot.note = "names no plugin";
      slots_.push_back(std::move(slot));
      continue;
    }
    const Described& described = Describe(form_slot.kind, form_slot.plugin);
    slot.note = described.note;
    slot.error = described.error;
    if (described.options && !form_slot.options.is_null() && !form_slot.options.is_object()) {
      // As the plugin's reader refuses it.
      slot.error = options_path + ": expected a JSON object, got " +
                   OptionReader::TypeName(form_slot.options);
      problems_.push_back(slot.error);
      problem_fields_.push_back(form_slot.label + " ");
    } else if (described.options) {
      slot.fields = OptionFields(*described.options, form_slot.options);
      slot.unknown = UnknownOptions(*described.options, form_slot.options);
      // In the order the form draws them: the unknown keys first.
      for (const auto& [key, why] : slot.unknown) {
        problems_.push_back(OptionError::Join(options_path + "." + key, why));
        problem_fields_.push_back(form_slot.label + " " + key);
      }
      for (const OptionField& field : *slot.fields) {
        if (field.problem.empty()) continue;
        problems_.push_back(
            OptionError::Join(options_path + "." + field.option.name, field.problem));
        problem_fields_.push_back(form_slot.label + " " + field.option.name);
      }
    }
    slots_.push_back(std::move(slot));
  }
}

const OptionFormView::Slot* OptionFormView::Find(const std::string& label) const {
  for (const Slot& slot : slots_) {
    if (slot.slot.label == label) return &slot;
  }
  return nullptr;
}

std::string OptionFormView::EditOption(const std::string& text, const Slot& slot,
                                       const std::string& key,
                                       std::optional<nlohmann::json> value) {
  if (value && slot.fields) {
    for (const OptionField& field : *slot.fields) {
      // Back to its default: no longer written.
      if (field.option.name == key && IsDefaultValue(field.option, *value)) value.reset();
    }
  }
  if (const std::optional<std::string> edited =
          SetOptionInText(text, slot.slot.steps, key, value)) {
    return *edited;
  }
  // Not editable in place (as far as the edit reads it): the JSON written anew.
  nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded()) return text;
  nlohmann::json* at = &json;
  for (const std::string& step : slot.slot.steps) {
    at = at->is_array() ? &(*at)[std::stoul(step)] : &(*at)[step];
  }
  if (!at->is_object()) return text;
  nlohmann::json& options = (*at)["options"];
  if (!options.is_object()) options = nlohmann::json::object();
  if (value) {
    options[key] = *value;
  } else {
    options.erase(key);
  }
  if (options.empty()) at->erase("options");
  return json.dump(2);
}

std::optional<nlohmann::json> OptionFormView::DrawInput(const OptionField& field) {
  const OptionDescription& option = field.option;
  const nlohmann::json& value = field.value;
  if (option.type == "boolean" && value.is_boolean()) {
    bool checked = value.get<bool>();
    if (ImGui::Checkbox("##value", &checked)) return nlohmann::json(checked);
    return std::nullopt;
  }
  if (!option.choices.empty() && value.is_string()) {
    const std::string current = value.get<std::string>();
    std::optional<nlohmann::json> chosen;
    if (ImGui::BeginCombo("##value", current.c_str())) {
      for (const std::string& choice : option.choices) {
        if (ImGui::Selectable(choice.c_str(), choice == current)) chosen = choice;
      }
      ImGui::EndCombo();
    }
    return chosen;
  }
  // Numbers, strings, paths, JSON, and a value of another type than the option's (typed
  // anew, it takes the option's type).
  const bool text_option = option.type == "string" || option.type == "path";
  const std::string shown =
      value.is_string() && text_option ? value.get<std::string>() : value.dump();
  std::array<char, 1024> buffer{};
  std::copy_n(shown.begin(), std::min(shown.size(), buffer.size() - 1), buffer.begin());
  if (!ImGui::InputText("##value", buffer.data(), buffer.size())) return std::nullopt;
  const std::string typed = buffer.data();
  if (text_option) return nlohmann::json(typed);
  const nlohmann::json parsed = nlohmann::json::parse(typed, nullptr, false);
  if (!parsed.is_discarded()) return parsed;
  // Not a number (yet): written as typed, so that the form marks it as the plugin would.
  if (option.type == "json") return std::nullopt;
  return nlohmann::json(typed);
}

std::optional<std::string> OptionFormView::DrawField(const Slot& slot, const OptionField& field,
                                                     WidgetRects* widgets) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const std::string& name = field.option.name;
  const std::string id = slot.slot.label + " " + name;
  ImGui::PushID(name.c_str());
  // Row 1: the name (its help in the tooltip), the input, reset.
  const float row_x = ImGui::GetCursorScreenPos().x;
  const float name_width =
      std::max(ImGui::GetFontSize() * 6, ImGui::GetContentRegionAvail().x * 0.4f);
  const float input_x = row_x + name_width + style.ItemSpacing.x;
  const std::string tip = OptionTip(field);
  const std::string shown = ElideToWidth(name, name_width);
  ImGui::AlignTextToFramePadding();
  ImGui::PushStyleColor(ImGuiCol_Text, field.differs ? kChangedColor : style.Colors[ImGuiCol_Text]);
  ImGui::TextUnformatted(shown.c_str());
  ImGui::PopStyleColor();
  const ImVec2 min = ImGui::GetItemRectMin(), max = ImGui::GetItemRectMax();
  if (shown != name && ImGui::IsItemVisible())
    widgets->AddElided({min.x, min.y, max.x, max.y}, tip);
  widgets->RecordLastItem("name " + id);
  if (ImGui::IsItemHovered()) WrappedTooltip(tip, widgets);
  ImGui::SameLine();
  ImGui::SetCursorScreenPos(ImVec2(input_x, ImGui::GetCursorScreenPos().y));
  const float reset_width = ImGui::CalcTextSize("reset").x + 2 * style.FramePadding.x;
  ImGui::SetNextItemWidth(
      std::max(ImGui::GetFontSize() * 3,
               ImGui::GetContentRegionAvail().x - reset_width - style.ItemSpacing.x));
  std::optional<nlohmann::json> edited = DrawInput(field);
  widgets->RecordLastItem("option " + id);
  if (scroll_to_ == id) {
    ImGui::SetScrollHereY(0.3f);
    scroll_to_.clear();
  }
  ImGui::SameLine();
  ImGui::BeginDisabled(!field.written);
  const bool reset = ImGui::Button("reset");
  ImGui::EndDisabled();
  widgets->RecordLastItem("reset " + id);
  // Row 2, the row's width but a little indented: the default and range, or why the
  // value is refused; one line either way.
  ImGui::SetCursorScreenPos(ImVec2(row_x + ImGui::GetFontSize(), ImGui::GetCursorScreenPos().y));
  if (field.problem.empty()) {
    FitText(DefaultLine(field), widgets, /*disabled=*/true);
  } else {
    const std::string message = OptionError::Join(name, field.problem);
    widgets->AddError(OptionError::Join(slot.slot.json_path + ".options." + name, field.problem));
    ColoredFitText(message, kErrorColor, widgets);
  }
  widgets->RecordLastItem("line " + id);
  ImGui::PopID();
  if (reset) return EditOption(text_, slot, name, std::nullopt);
  if (edited) return EditOption(text_, slot, name, std::move(edited));
  return std::nullopt;
}

std::optional<std::string> OptionFormView::DrawSlot(const Slot& slot, WidgetRects* widgets) {
  std::optional<std::string> edited;
  ImGui::PushID(slot.slot.json_path.c_str());
  ImGui::TextUnformatted(
      (slot.slot.label + (slot.slot.plugin.empty() ? "" : ": " + slot.slot.plugin)).c_str());
  if (!slot.note.empty()) {
    HintText(slot.note);
    widgets->RecordLastItem("options of " + slot.slot.label);
  }
  ErrorText(slot.error, widgets);
  if (!slot.fields && slot.slot.options.is_object() && !slot.slot.options.empty()) {
    // Left as written; shown so that the form does not look as if there were none.
    std::string written;
    for (const auto& [key, value] : slot.slot.options.items()) {
      written += (written.empty() ? "" : ", ") + key + " = " + OptionValueText(value);
    }
    HintText("as written: " + written);
  }
  for (const auto& [key, why] : slot.unknown) {
    ImGui::PushID(key.c_str());
    // The button first: it stays where it is whatever the message's length.
    if (ImGui::Button("remove")) edited = EditOption(text_, slot, key, std::nullopt);
    widgets->RecordLastItem("remove " + slot.slot.label + " " + key);
    if (scroll_to_ == slot.slot.label + " " + key) {
      ImGui::SetScrollHereY(0.3f);
      scroll_to_.clear();
    }
    ImGui::SameLine();
    const std::string message = OptionError::Join(key, why);
    widgets->AddError(OptionError::Join(slot.slot.json_path + ".options." + key, why));
    ColoredFitText(message, kErrorColor, widgets);
    ImGui::PopID();
  }
  if (slot.fields) {
    for (const OptionField& field : *slot.fields) {
      if (std::optional<std::string> text = DrawField(slot, field, widgets)) {
        edited = std::move(text);
      }
    }
  }
  ImGui::PopID();
  return edited;
}

std::optional<std::string> OptionFormView::Draw(float height, WidgetRects* widgets) {
  std::optional<std::string> edited;
  ImGui::BeginChild("##option form", ImVec2(-1, height), true);
  if (!parsed_) {
    HintText("the JSON does not parse: fix it in the JSON view");
  } else if (slots_.empty()) {
    HintText("the manifest names no plugins (pipeline.detector, ...): pick them above");
  }
  for (size_t i = 0; i < slots_.size(); ++i) {
    if (i > 0) ImGui::Separator();
    if (std::optional<std::string> text = DrawSlot(slots_[i], widgets)) edited = std::move(text);
  }
  ImGui::EndChild();
  return edited;
}

}  // namespace tessera::gui
