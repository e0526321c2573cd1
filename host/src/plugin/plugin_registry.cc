#include "plugin/plugin_registry.h"

#include <dlfcn.h>

#include <algorithm>
#include <set>

#include "plugin/host_plugin_services.h"
#include "plugin/plugin_probe.h"

namespace tessera {
namespace {

constexpr const char* kInfoSymbol = "tessera_plugin_info";
constexpr const char* kFactorySymbol = "tessera_plugin_create";

bool IsSharedObject(const std::filesystem::path& path) { return path.extension() == ".so"; }

std::string Quote(const std::string& text) { return "'" + text + "'"; }

std::string CompilerName(uint32_t compiler, uint32_t major) {
  const char* family = compiler == 1 ? "GCC" : compiler == 2 ? "Clang" : "an unknown compiler";
  return std::string(family) + (compiler == 1 || compiler == 2 ? " " + std::to_string(major) : "");
}

std::string LibraryName(uint32_t library) {
  return library == 1 ? "libstdc++" : library == 2 ? "libc++" : "an unknown standard library";
}

}  // namespace

std::string BuildMismatch(const TesseraBuildRecord& plugin, const TesseraBuildRecord& host) {
  const std::string tail =
      "; a plugin must be built as the host is, since C++ objects cross "
      "the boundary";
  if (plugin.standard_library != host.standard_library) {
    return "built against " + LibraryName(plugin.standard_library) + ", the host against " +
           LibraryName(host.standard_library) + tail;
  }
  if (plugin.string_abi != host.string_abi) {
    return "built with -D_GLIBCXX_USE_CXX11_ABI=" + std::to_string(plugin.string_abi) +
           " (the C++ library's string ABI), the host with " + std::to_string(host.string_abi) +
           tail;
  }
  if (plugin.compiler != host.compiler || plugin.compiler_major != host.compiler_major) {
    return "built with " + CompilerName(plugin.compiler, plugin.compiler_major) +
           ", the host with " + CompilerName(host.compiler, host.compiler_major) + tail;
  }
  const std::pair<const char*, std::pair<uint32_t, uint32_t>> sizes[] = {
      {"std::string", {plugin.sizeof_string, host.sizeof_string}},
      {"std::vector", {plugin.sizeof_vector, host.sizeof_vector}},
      {"std::function", {plugin.sizeof_function, host.sizeof_function}},
      {"nlohmann::json", {plugin.sizeof_json, host.sizeof_json}},
      {"std::filesystem::path", {plugin.sizeof_path, host.sizeof_path}}};
  for (const auto& [type, size] : sizes) {
    if (size.first != size.second) {
      return std::string("built with a ") + type + " of " + std::to_string(size.first) +
             " bytes, the host's has " + std::to_string(size.second) + tail;
    }
  }
  return "";
}

const TesseraBuildRecord& HostBuildRecord() {
  static const TesseraBuildRecord record = TESSERA_BUILD_RECORD;
  return record;
}

const std::vector<std::string>& PluginKindNames() {
  static const std::vector<std::string> kinds = {"detector", "matcher",         "pair_selector",
                                                 "mapper",   "bundle_adjuster", "exporter"};
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
  if (const std::string mismatch = BuildMismatch(info.build, HostBuildRecord());
      !mismatch.empty()) {
    const std::string name = info.name != nullptr ? Quote(info.name) + " " : "";
    record.refusal = where + "plugin " + name + mismatch;
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
  registry.own_services_ = HostPluginServices::Make(registry);
  registry.services_ = registry.own_services_;
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
      CreateObject(record, nlohmann::json::object(), record.kind, "");
  return plugin->EffectiveOptions();
}

std::unique_ptr<Plugin> PluginRegistry::CreateObject(const PluginRecord& record,
                                                     const nlohmann::json& options,
                                                     const std::string& json_path,
                                                     const std::string& options_path) const {
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
    plugin = factory(options, services_.lock());
  } catch (const OptionError& error) {
    // Plugins report paths relative to their options; anchor them in the manifest.
    const std::string path = (options_path.empty() ? json_path + ".options" : options_path) +
                             (error.path().empty() ? "" : "." + error.path());
    throw InputError(OptionError::Join(path, error.message()) + " (plugin " + Quote(record.name) +
                     ", " + record.file.string() + ")");
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
  plugin->SetLogSink(PluginLogSink(record.name));
  return plugin;
}

}  // namespace tessera
