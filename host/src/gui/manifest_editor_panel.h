#pragma once

// The manifest editor, a collapsing section of the set-up window: the manifest's JSON in
// a text box (loaded from the manifest field's file, or the default manifest) or, with
// the Form / JSON switch, each slot's options as a form built from its plugin's
// description (option_form_view.h; edits rewrite the text), one plugin per slot chosen
// from the plugins found on the plugin path, Check (as `tessera run` does: parsed, every
// plugin created with its options; first, every option against its plugin's
// description), Reload, and Save as, which makes the saved file the manifest field's.
// Once loaded, the editor's text is what Run runs; it is reloaded when the manifest field
// names another file.

#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "gui/option_form_view.h"
#include "gui/panel_widgets.h"
#include "gui/widget_rects.h"

namespace tessera {
class PluginRegistry;
}

namespace tessera::gui {

// A JSON parse error of `text` as one line: "invalid JSON at line L, column C: REASON",
// the place being the last character read before the error (not the library's, which is
// the line after it when the error comes at a line's end).
std::string JsonErrorMessage(const std::string& text, const nlohmann::json::parse_error& error);

class ManifestEditorPanel {
 public:
  // manifest_field: the set-up window's manifest field, read by Load and Check and
  // written by Save; it must outlive the editor.
  explicit ManifestEditorPanel(PathField* manifest_field);

  // Each is false with the message in Error().
  // Loads the manifest field's file (empty: the default manifest) into the editor.
  bool Load();
  // Checks the editor's JSON as `tessera run` does, after its options against their
  // plugins' descriptions (the form's problems, the first named with its JSON path): an
  // invalid option refuses Run with its reason.
  bool Check();
  // Saves the editor's JSON to `file` (after checking) and sets the manifest field to it.
  bool Save(const std::filesystem::path& file);
  // Sets the plugin of a slot ("detector", "pair_selector", "matcher", "mapper",
  // "bundle_adjuster") in the editor's JSON, in place (SetPluginInText: the rest of the
  // text and the slot's options kept; Check names an option the new plugin does not
  // take). For the mapper, a top-level "mapper" object of an older manifest is removed
  // (it would be refused beside it): that JSON is written anew, the slot without options.
  bool SetPlugin(const std::string& slot, const std::string& plugin);
  // As a slot's dropdown: SetPlugin, unless the slot's options hold some the new plugin
  // does not take (those not among its options with defaults filled in), or the plugin
  // is a mapper and an older manifest's top-level "mapper" options would go with the
  // rewrite: then the editor asks first (Question()). "Change and drop them" ("... it") sets the
  // plugin and removes those options in place (RemoveOptionsInText); "Keep PLUGIN"
  // leaves the text as it was.
  void RequestSetPlugin(const std::string& slot, const std::string& plugin);
  // The plugin the editor's JSON names for a slot, as its dropdown shows it: when the
  // slot is absent, the plugin a run uses then (the mapper: "incremental", its dropdown
  // reading "incremental (default)") or "(none)" (a run has no such stage);
  // "(invalid JSON)" when the text does not parse; several pair selectors are joined
  // with " + ".
  std::string PluginOf(const std::string& slot) const;
  // The description drawn under a slot's dropdown in the last frame (of the plugin it
  // shows); empty when none was.
  std::string DescriptionShown(const std::string& slot) const {
    const auto found = descriptions_shown_.find(slot);
    return found == descriptions_shown_.end() ? "" : found->second;
  }

  // Reloads the editor when the manifest field no longer names the file it was loaded
  // from, clearing the messages of the old file (RequestLoad: asking first when the
  // editor holds unsaved edits).
  void FollowManifestField();
  // Load, unless the editor holds edits not loaded or saved (Edited()): then the editor
  // asks first (Question()); "Replace" loads, "Keep my text" puts the manifest field back
  // to the file the text came from, so that the field and the editor agree.
  void RequestLoad();
  // Save, unless `file` exists and is not the file the text came from: then it asks first.
  void RequestSave(const std::filesystem::path& file);
  // Whether the text differs from the file it was loaded from or saved to.
  bool Edited() const { return Loaded() && Text() != clean_text_; }
  // Why the manifest field's file could not be loaded last (the field then names a file
  // the editor does not hold: Run refuses with this); empty once a file is loaded.
  const std::string& LoadError() const { return load_error_; }
  // The question the editor asks before it replaces text or a file; empty when none.
  const std::string& Question() const { return question_; }
  // Answers the question: true replaces (loads or saves), false keeps what is there.
  void Answer(bool replace);
  // The question's modal popup (recorded as "replace answer" and "keep answer"); drawn
  // whether or not the section is open.
  void DrawQuestion(WidgetRects* widgets);
  // Whether the section was open in the last frame.
  bool open() const { return open_; }
  // Whether the editor holds a manifest (it is loaded when first opened).
  bool Loaded() const { return text_[0] != '\0'; }

  // Shows the options as a form (true) or the JSON text (false), as the switch does.
  void ShowForm(bool form) { form_view_ = form; }
  bool FormShown() const { return form_view_; }
  // The form of the editor's text as last drawn or checked.
  const OptionFormView& form() const { return form_; }
  OptionFormView& form() { return form_; }

  // Replaces the text; as typing does, a new text clears the messages about the old.
  void SetText(const std::string& text);
  std::string Text() const { return text_.data(); }
  const std::string& Error() const { return error_; }

  // The section (its header records "manifest editor"); loads the manifest and finds the
  // plugins when first opened.
  void Draw(WidgetRects* widgets);

 private:
  // The plugins of each slot's kind on the plugin path, found once.
  void FindPlugins();
  // PluginOf, and whether the plugin is the slot's default (the text names none).
  std::string PluginOf(const std::string& slot, bool* is_default) const;
  // A slot's dropdown (recorded as "slot KIND", its entries as "plugin KIND NAME"), its
  // preview the plugin the text names, and that plugin's description beneath it.
  void DrawSlot(const std::string& kind, WidgetRects* widgets);
  // The Form / JSON switch (recorded as "form view" and "json view"), the view chosen
  // ("option form" or "manifest json") and a line beneath: the first invalid option, or
  // a hint.
  void DrawViews(WidgetRects* widgets);

  PathField* manifest_field_;
  std::vector<char> text_ = std::vector<char>(1 << 16, '\0');
  PathField save_path_{};
  std::string error_, status_;
  std::string loaded_from_;  // the manifest field's value when last loaded or saved
  std::string clean_text_;   // the text as loaded or saved (Edited compares with it)
  // The options of a slot's text that `plugin` would not take (*legacy: the top-level
  // "mapper" options, all of which a mapper's rewrite drops); empty when none would go.
  std::vector<std::string> OptionsDropped(const std::string& slot, const std::string& plugin,
                                          bool* legacy);
  // The option names a plugin takes (its options with defaults filled in, found once);
  // nothing when it cannot be made with none (Check then names what it refuses).
  std::optional<std::set<std::string>> OptionsTaken(const std::string& kind,
                                                    const std::string& plugin);

  // The question asked, and what a "replace" answer does.
  std::string question_;
  std::string load_error_;
  enum class Pending { kNone, kLoad, kSave, kPlugin } pending_ = Pending::kNone;
  std::filesystem::path pending_save_;
  // kPlugin: the slot, the plugin picked, the one kept on "Keep", the options dropped.
  std::string pending_slot_, pending_plugin_, pending_kept_;
  std::vector<std::string> pending_drop_;
  std::shared_ptr<const PluginRegistry> registry_;  // found with the plugins
  std::map<std::string, std::optional<std::set<std::string>>> options_taken_;
  bool question_open_ = false;
  bool open_ = false;
  // Per kind: each plugin's name and description.
  std::map<std::string, std::vector<std::pair<std::string, std::string>>> plugins_by_kind_;
  std::map<std::string, std::string> descriptions_shown_;  // per slot, DescriptionShown
  bool form_view_ = false;                                 // the switch: Form (true) or JSON
  OptionFormView form_;
};

}  // namespace tessera::gui
