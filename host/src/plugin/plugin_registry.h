#pragma once

#include <boost/dll/shared_library.hpp>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plugin/plugin_call.h"
#include "tessera/sdk.h"

namespace tessera {

// The six plugin kinds, by the names used in info records and manifests.
const std::vector<std::string>& PluginKindNames();

// One plugin file found on the search path, loadable or not.
struct PluginRecord {
  std::filesystem::path file;
  uint32_t abi_version = 0;
  std::string kind;
  std::string name;
  std::string version;
  std::string description;
  // Whether it exports the description of its options (TESSERA_PLUGIN_OPTIONS).
  bool describes_options = false;
  // Why the host refuses this plugin; empty when it is usable.
  std::string refusal;
  // Opened when the host first makes an object of a usable record (discovery inspects
  // files in a child process); shared with every object made from it.
  mutable std::shared_ptr<boost::dll::shared_library> library;

  bool usable() const { return refusal.empty(); }
  nlohmann::json ToJson() const;
};

// A plugin object together with the library it came from. Members are destroyed in
// reverse order, so the object always goes before its library is unloaded.
template <typename Interface>
class PluginInstance {
 public:
  PluginInstance() = default;
  PluginInstance(std::shared_ptr<boost::dll::shared_library> library,
                 std::unique_ptr<Interface> object, const PluginRecord& record)
      : library_(std::move(library)),
        object_(std::move(object)),
        name_(record.name),
        version_(record.version),
        file_(record.file) {}
  PluginInstance(PluginInstance&&) noexcept = default;
  PluginInstance& operator=(PluginInstance&& other) noexcept {
    object_ = std::move(other.object_);  // release our object before our library
    library_ = std::move(other.library_);
    name_ = std::move(other.name_);
    version_ = std::move(other.version_);
    file_ = std::move(other.file_);
    return *this;
  }
  ~PluginInstance() { object_.reset(); }

  explicit operator bool() const { return object_ != nullptr; }
  const std::string& name() const { return name_; }
  const std::string& version() const { return version_; }
  const std::filesystem::path& file() const { return file_; }

  // The only way in: calls `fn(plugin)` through CallPlugin, so that whatever it throws
  // becomes a PluginError naming this plugin, `stage` and `subject` ("image a.jpg"),
  // and a crash is attributed to them. No pointer to the object leaves this holder.
  template <typename Fn>
  decltype(auto) Call(PluginStage stage, const std::string& subject, Fn&& fn) const {
    Interface& object = *object_;
    return CallPlugin(name_, stage, subject, [&]() -> decltype(auto) { return fn(object); });
  }

  // The options in effect, defaults filled in.
  nlohmann::json EffectiveOptions() const {
    return Call(PluginStage::kOptions, "",
                [](const Interface& plugin) { return plugin.EffectiveOptions(); });
  }
  // Name, version and effective options: what produced a result.
  nlohmann::json Provenance() const {
    return {{"plugin", name_}, {"version", version_}, {"options", EffectiveOptions()}};
  }

 private:
  std::shared_ptr<boost::dll::shared_library> library_;  // first: destroyed last
  std::unique_ptr<Interface> object_;
  std::string name_;
  std::string version_;
  std::filesystem::path file_;
};

// Why a plugin built as `plugin` says cannot run in a host built as `host`, as the end
// of a sentence ("built with -D_GLIBCXX_USE_CXX11_ABI=0 (...), the host with 1; ..."),
// naming the first setting that differs; empty when none does.
std::string BuildMismatch(const TesseraBuildRecord& plugin, const TesseraBuildRecord& host);
// This host's build record.
const TesseraBuildRecord& HostBuildRecord();

// Reads the info record of one file and checks it: opens, has the record, ABI version
// equal to the host's, known kind, has a factory. Never throws; a failure is
// recorded in `refusal` as one sentence naming the file.
PluginRecord InspectPluginFile(const std::filesystem::path& file);

class HostPluginServices;

// Every plugin found on a search path.
class PluginRegistry {
 public:
  // Scans the folders in order for shared objects (*.so). Each file is inspected in a
  // child process (ProbePluginFiles): one that crashes, exits or hangs on load is
  // refused with why, and no library is loaded here until Create needs it. A name seen a second
  // time is refused as a duplicate; the first one found wins. Missing folders are skipped.
  static PluginRegistry Discover(const std::vector<std::filesystem::path>& search_paths);

  const std::vector<PluginRecord>& records() const { return records_; }
  const std::vector<std::filesystem::path>& search_paths() const { return search_paths_; }

  // What `tessera plugins --json` prints: {"abi_version", "search_paths", "plugins":
  // [PluginRecord::ToJson, ...]}.
  nlohmann::json ToJson() const;

  // The options a usable plugin runs with when given none, defaults filled in: it is
  // loaded here and made with {}. Throws InputError naming the file when its factory
  // refuses that (a plugin with a required option).
  nlohmann::json DefaultOptions(const PluginRecord& record) const;

  // The description of a usable plugin's options (tessera/option_list.h), checked as
  // input: nullopt when the plugin does not describe them. Loads the plugin, without
  // making it. Throws InputError naming the file when the description is malformed.
  std::optional<std::vector<OptionDescription>> DescribeOptions(const PluginRecord& record) const;

  // The usable plugin named `name`, of any kind; InputError naming the closest name
  // when there is none.
  const PluginRecord& Find(const std::string& name) const;

  // Usable plugin names of a kind, sorted.
  std::vector<std::string> NamesOfKind(const std::string& kind) const;

  // Makes the plugin `name` for the slot of kind `kind`. `json_path` is where the
  // slot sits in the manifest (e.g. "pipeline.detector"); errors name it and the file.
  // `options_path`: where the options sit when not at json_path + ".options".
  // Throws InputError when the plugin is missing, refused, of another kind, its
  // factory throws or it rejects its options.
  template <typename Interface>
  PluginInstance<Interface> Create(const std::string& kind, const std::string& name,
                                   const nlohmann::json& options, const std::string& json_path,
                                   const std::string& options_path = "") const {
    const PluginRecord& record = Resolve(kind, name, json_path);
    std::unique_ptr<Plugin> plugin = CreateObject(record, options, json_path, options_path);
    auto* typed = dynamic_cast<Interface*>(plugin.get());
    if (typed == nullptr) {
      throw InputError(record.file.string() + ": plugin '" + name + "' says it is a " + kind +
                       " but its factory made an object of another kind");
    }
    plugin.release();
    return PluginInstance<Interface>(record.library, std::unique_ptr<Interface>(typed), record);
  }

 private:
  friend class HostPluginServices;

  const PluginRecord& Resolve(const std::string& kind, const std::string& name,
                              const std::string& json_path) const;
  // Opens a record's library when discovery inspected it in a child process only.
  void EnsureLoaded(const PluginRecord& record, const std::string& json_path) const;
  std::unique_ptr<Plugin> CreateObject(const PluginRecord& record, const nlohmann::json& options,
                                       const std::string& json_path,
                                       const std::string& options_path) const;

  std::vector<std::filesystem::path> search_paths_;
  std::vector<PluginRecord> records_;
  // The services every plugin made here gets (Plugin::host()): a copy of this registry
  // that makes guarded plugins. Owned here (and by each plugin made with them); the
  // copy inside them refers to them weakly, so that nothing owns itself.
  std::shared_ptr<const PluginServices> own_services_;
  std::weak_ptr<const PluginServices> services_;
};

}  // namespace tessera
