#include "plugin/plugin_registry.h"

#include <dlfcn.h>

#include <algorithm>
#include <set>

#include "plugin/plugin_probe.h"

namespace tessera {
namespace {

constexpr const char* kInfoSymbol = "tessera_plugin_info";
constexpr const char* kFactorySymbol = "tessera_plugin_create";

bool IsSharedObject(const std::filesystem::path& path) { return path.extension() == ".so"; }

std::string Quote(const std::string& text) { return "'" + text + "'"; }

}  // namespace

const std::vector<std::string>& PluginKindNames() {
  static const std::vector<std::string> kinds = {"detector", "matcher", "pair_selector",
                                                 "bundle_adjuster", "exporter"};
  return kinds;
}

nlohmann::json PluginRecord::ToJson() const {
  nlohmann::json json = {{"file", file.string()},
                         {"kind", kind},
                         {"name", name},
                         {"version", version},
                         {"description", description},
                         {"abi_version", abi_version},
                         {"usable", usable()}};
  if (!usable()) json["refused"] = refusal;
  return json;
}

PluginRecord InspectPluginFile(const std::filesystem::path& file) {
  PluginRecord record;
  record.file = file;
  const std::string where = file.string() + ": ";

  auto library = std::make_shared<boost::dll::shared_library>();
  boost::dll::fs::error_code error;
  {
    // Static initialisers run here: a crash in them is the file's.
    const PluginCallScope scope(file.string(), PluginStage::kLoad, "");
    library->load(file, boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local, error);
  }
  if (error || !library->is_loaded()) {
    const char* reason = dlerror();
    record.refusal = where + "cannot open the library: " +
                     (reason != nullptr ? std::string(reason) : error.message());
    return record;
  }
  if (!library->has(kInfoSymbol)) {
    record.refusal = where + "not a Tessera plugin: it exports no '" + kInfoSymbol + "' record";
    return record;
  }
  const auto& info = library->get_alias<const TesseraPluginInfo>(kInfoSymbol);
  record.abi_version = info.abi_version;
  if (info.abi_version != kPluginAbiVersion) {
    // Nothing past abi_version can be trusted in a record of another version.
    record.refusal = where + "wrong plugin ABI version: got version " +
                     std::to_string(info.abi_version) + ", supported version is " +
                     std::to_string(kPluginAbiVersion);
    return record;
  }
  if (info.kind == nullptr || info.name == nullptr || info.version == nullptr) {
    record.refusal = where + "incomplete info record: kind, name and version are required";
    return record;
  }
  record.kind = info.kind;
  record.name = info.name;
  record.version = info.version;
  record.description = info.description != nullptr ? info.description : "";
  const auto& kinds = PluginKindNames();
  if (std::find(kinds.begin(), kinds.end(), record.kind) == kinds.end()) {
    record.refusal = where + "plugin " + Quote(record.name) + " has unknown kind " +
                     Quote(record.kind) + DidYouMean(record.kind, kinds);
    return record;
  }
  if (record.name.empty()) {
    record.refusal = where + "incomplete info record: the plugin name is empty";
    return record;
  }
  if (!library->has(kFactorySymbol)) {
    record.refusal =
        where + "plugin " + Quote(record.name) + " exports no '" + kFactorySymbol + "' factory";
    return record;
  }
  record.library = std::move(library);
  return record;
}

PluginRegistry PluginRegistry::Discover(const std::vector<std::filesystem::path>& search_paths) {
  PluginRegistry registry;
  std::set<std::filesystem::path> seen_dirs;
  for (const auto& dir : search_paths) {
    std::error_code error;
    if (!std::filesystem::is_directory(dir, error)) continue;
    const auto canonical = std::filesystem::canonical(dir, error);
    if (error || !seen_dirs.insert(canonical).second) continue;
    registry.search_paths_.push_back(canonical);

    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(canonical, error)) {
      if (entry.is_regular_file() && IsSharedObject(entry.path())) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    std::vector<std::optional<PluginRecord>> probed = ProbePluginFiles(files);
    for (size_t i = 0; i < files.size(); ++i) {
      const auto& file = files[i];
      // No child could inspect it: inspect it here, as before the probe existed.
      PluginRecord record = probed[i] ? std::move(*probed[i]) : InspectPluginFile(file);
      if (record.usable()) {
        for (const auto& other : registry.records_) {
          if (other.usable() && other.name == record.name) {
            record.refusal = file.string() + ": duplicate plugin name " + Quote(record.name) +
                             ", already provided by " + other.file.string();
            record.library.reset();
            break;
          }
        }
      }
      registry.records_.push_back(std::move(record));
    }
  }
  return registry;
}

std::vector<std::string> PluginRegistry::NamesOfKind(const std::string& kind) const {
  std::vector<std::string> names;
  for (const auto& record : records_) {
    if (record.usable() && record.kind == kind) names.push_back(record.name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

const PluginRecord& PluginRegistry::Resolve(const std::string& kind, const std::string& name,
                                            const std::string& json_path) const {
  const std::string where = json_path + ".plugin: ";
  for (const auto& record : records_) {
    if (record.name != name) continue;
    if (!record.usable())
      throw InputError(where + "plugin " + Quote(name) + " is refused: " + record.refusal);
    if (record.kind != kind) {
      throw InputError(where + "plugin " + Quote(name) + " (" + record.file.string() + ") is a " +
                       record.kind + ", not a " + kind);
    }
    return record;
  }
  // A refused file may still tell us the name (e.g. a wrong kind only).
  std::string message = where + "no " + kind + " plugin " + Quote(name);
  const std::string suggestion = DidYouMean(name, NamesOfKind(kind));
  if (!suggestion.empty()) {
    message += suggestion;
  } else {
    std::string list;
    for (const auto& known : NamesOfKind(kind)) list += (list.empty() ? "" : ", ") + known;
    message += list.empty() ? " (no " + kind + " plugins were found on the plugin path)"
                            : " (available: " + list + ")";
  }
  // Files refused before their name was known (e.g. one that crashes on load) may be it.
  for (const auto& record : records_) {
    if (!record.usable() && record.name.empty()) message += "; refused: " + record.refusal;
  }
  throw InputError(message);
}

nlohmann::json PluginRegistry::ToJson() const {
  nlohmann::json json = {{"abi_version", kPluginAbiVersion},
                         {"search_paths", nlohmann::json::array()},
                         {"plugins", nlohmann::json::array()}};
  for (const auto& path : search_paths_) json["search_paths"].push_back(path.string());
  for (const auto& record : records_) json["plugins"].push_back(record.ToJson());
  return json;
}

nlohmann::json PluginRegistry::DefaultOptions(const PluginRecord& record) const {
  const std::unique_ptr<Plugin> plugin =
      CreateObject(record, nlohmann::json::object(), record.kind);
  return plugin->EffectiveOptions();
}

std::unique_ptr<Plugin> PluginRegistry::CreateObject(const PluginRecord& record,
                                                     const nlohmann::json& options,
                                                     const std::string& json_path) const {
  if (!record.library) {
    // Inspected in a child process only: open it here now.
    PluginRecord loaded = InspectPluginFile(record.file);
    if (!loaded.usable()) throw InputError(json_path + ".plugin: " + loaded.refusal);
    if (loaded.name != record.name || loaded.kind != record.kind) {
      throw InputError(record.file.string() + ": the file changed while Tessera was running");
    }
    record.library = std::move(loaded.library);
  }
  const auto& factory = record.library->get_alias<PluginFactory>(kFactorySymbol);
  std::unique_ptr<Plugin> plugin;
  try {
    const PluginCallScope scope(record.name, PluginStage::kCreate, "from " + record.file.string());
    plugin = factory(options);
  } catch (const OptionError& error) {
    // Plugins report paths relative to their options; anchor them in the manifest.
    const std::string path =
        json_path + ".options" + (error.path().empty() ? "" : "." + error.path());
    throw InputError(path + ": " + error.message() + " (plugin " + Quote(record.name) + ", " +
                     record.file.string() + ")");
  } catch (const std::exception& error) {
    throw InputError(record.file.string() + ": plugin " + Quote(record.name) +
                     " failed to start: " + error.what());
  } catch (...) {
    throw InputError(record.file.string() + ": plugin " + Quote(record.name) +
                     " failed to start: it threw an exception that is not a std::exception");
  }
  if (plugin == nullptr) {
    throw InputError(record.file.string() + ": plugin " + Quote(record.name) +
                     " failed to start: its factory returned nothing");
  }
  return plugin;
}

}  // namespace tessera
