#include "plugin/plugin_registry.h"

#include <dlfcn.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <mutex>
#include <optional>
#include <set>

#include "plugin/host_plugin_services.h"
#include "plugin/option_descriptions.h"
#include "plugin/plugin_crash_log.h"
#include "plugin/plugin_probe.h"

namespace tessera {
namespace {

constexpr const char* kInfoSymbol = "tessera_plugin_info";
constexpr const char* kFactorySymbol = "tessera_plugin_create";
constexpr const char* kOptionsSymbol = "tessera_plugin_options";

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
                         {"describes_options", describes_options},
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
  auto mode = boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local;
#ifdef __SANITIZE_ADDRESS__
  // Sanitizer builds keep a plugin mapped after its last handle goes (RTLD_NODELETE), so
  // that LeakSanitizer scans the plugin's globals at exit and can name its frames: once
  // unmapped, what its globals held would be reported as leaked "from <unknown module>".
  mode = mode | static_cast<boost::dll::load_mode::type>(RTLD_NODELETE);
#endif
  {
    // Static initialisers run here: a crash in them is the file's.
    const PluginCallScope scope(file.string(), PluginStage::kLoad, "");
    library->load(file, mode, error);
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
  record.describes_options = library->has(kOptionsSymbol);
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

namespace {

// Deeper than this, a chain of plugins made for plugins is taken for a loop that the
// names alone do not show (a plugin that asks for others with changing options).
constexpr size_t kMaxPluginNesting = 8;

// A chain of plugins that makes itself: passed through every level unchanged (it is a
// HostInputError), so that the user reads the chain, not a wrapper's failure to start.
class PluginChainError : public HostInputError {
 public:
  using HostInputError::HostInputError;
};

// Options refused by a plugin made for another plugin: `path` below the `options` it was
// given. Each maker on the way out finds those options among its own and lengthens the
// path, so that the outermost names the manifest's path
// (pipeline.bundle_adjuster.options.primary_options.loss).
class NestedOptionError : public HostInputError {
 public:
  NestedOptionError(const std::string& fallback, std::string path, nlohmann::json options,
                    std::string message, std::string who)
      : HostInputError(fallback),
        path(std::move(path)),
        options(std::move(options)),
        message(std::move(message)),
        who(std::move(who)) {}
  std::string path;
  nlohmann::json options;
  std::string message;
  std::string who;  // "plugin 'ceres', FILE, made by plugin 'wrapper'"
};

// The JSON path of `needle` in `haystack` ("" for the whole, "a.b", "list[2]"), or
// nullopt when it is not there.
std::optional<std::string> FindJsonPath(const nlohmann::json& haystack,
                                        const nlohmann::json& needle) {
  if (haystack == needle) return std::string();
  if (haystack.is_object()) {
    for (const auto& [key, value] : haystack.items()) {
      if (const auto below = FindJsonPath(value, needle)) {
        return key + (below->empty() || (*below)[0] == '[' ? "" : ".") + *below;
      }
    }
  }
  if (haystack.is_array()) {
    for (size_t i = 0; i < haystack.size(); ++i) {
      if (const auto below = FindJsonPath(haystack[i], needle)) {
        return "[" + std::to_string(i) + "]" + (below->empty() || (*below)[0] == '[' ? "" : ".") +
               *below;
      }
    }
  }
  return std::nullopt;
}

std::string JoinPath(const std::string& head, const std::string& tail) {
  if (tail.empty()) return head;
  return head + (head.empty() || tail[0] == '[' ? "" : ".") + tail;
}

// Refuses to make `name` when the thread is already inside it (a plugin asking the host
// for itself, or A -> B -> A), or when plugins made for plugins nest too deep.
void CheckPluginChain(const std::string& kind, const std::string& name,
                      const std::filesystem::path& file) {
  const std::vector<std::string> active = ActivePluginCalls();
  std::string chain;
  for (const std::string& plugin : active) chain += "'" + plugin + "' -> ";
  chain += "'" + name + "'";
  if (std::find(active.begin(), active.end(), name) != active.end()) {
    throw PluginChainError("plugin creation loops: " + chain + ": plugin '" + active.back() +
                           "' asks the host for the " + kind + " '" + name +
                           "', which is already being made or called (" + file.string() +
                           "); a plugin cannot wrap itself");
  }
  if (active.size() >= kMaxPluginNesting) {
    throw PluginChainError("plugins made for plugins nest deeper than " +
                           std::to_string(kMaxPluginNesting) + ": " + chain);
  }
}

// Says, once per plugin name in a process, which file runs when files found later on
// the search path (a bundled plugin) carry the same name: "pipeline.detector: plugin
// 'orb' runs from A (version 2.0); it shadows B (version 1.0), found later on the
// plugin path".
void AnnounceShadowing(const PluginRecord& record, const std::vector<PluginRecord>& records,
                       const std::string& json_path) {
  std::string shadowed;
  for (const PluginRecord& other : records) {
    if (other.usable() || other.name != record.name || other.file == record.file) continue;
    if (other.refusal.find(": duplicate plugin name ") == std::string::npos) continue;
    shadowed +=
        (shadowed.empty() ? "" : ", ") + other.file.string() + " (version " + other.version + ")";
  }
  if (shadowed.empty()) return;
  static std::mutex mutex;
  static std::set<std::string> announced;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!announced.insert(record.name).second) return;
  }
  spdlog::warn(
      "{}: plugin '{}' runs from {} (version {}); it shadows {}, found later on the "
      "plugin path (the manifest's plugin_paths, then TESSERA_PLUGIN_PATH, then the "
      "bundled plugins; in a folder, by file name)",
      json_path, record.name, record.file.string(), record.version, shadowed);
}

}  // namespace

void PluginRegistry::EnsureLoaded(const PluginRecord& record, const std::string& json_path) const {
  if (record.library) return;
  // Inspected in a child process only: open it here now.
  PluginRecord loaded = InspectPluginFile(record.file);
  if (!loaded.usable()) throw InputError(json_path + ".plugin: " + loaded.refusal);
  if (loaded.name != record.name || loaded.kind != record.kind ||
      loaded.describes_options != record.describes_options) {
    throw InputError(record.file.string() + ": the file changed while Tessera was running");
  }
  record.library = std::move(loaded.library);
}

std::optional<std::vector<OptionDescription>> PluginRegistry::DescribeOptions(
    const PluginRecord& record) const {
  if (!record.describes_options) return std::nullopt;
  EnsureLoaded(record, record.kind);
  const auto& describe = record.library->get_alias<PluginOptionsDescriber>(kOptionsSymbol);
  const std::string who = "plugin " + Quote(record.name) + " (" + record.file.string() + ")";
  nlohmann::json described;
  try {
    const PluginCallScope scope(record.name, PluginStage::kOptions, "describing its options");
    described = describe();
  } catch (const std::exception& error) {
    throw InputError(who + ": describing its options failed: " + error.what());
  }
  return ParseOptionDescriptions(described, who);
}

const PluginRecord& PluginRegistry::Find(const std::string& name) const {
  std::vector<std::string> names;
  for (const auto& record : records_) {
    if (record.usable() && record.name == name) return record;
    if (record.usable()) names.push_back(record.name);
  }
  for (const auto& record : records_) {
    if (!record.usable() && record.name == name) {
      throw InputError("plugin " + Quote(name) + " is refused: " + record.refusal);
    }
  }
  throw InputError("no plugin " + Quote(name) + " on the plugin path" + DidYouMean(name, names));
}

std::unique_ptr<Plugin> PluginRegistry::CreateObject(const PluginRecord& record,
                                                     const nlohmann::json& options,
                                                     const std::string& json_path,
                                                     const std::string& options_path) const {
  // Made for another plugin (Plugin::host()) while that one is being made or called.
  const bool nested = !ActivePluginCalls().empty();
  if (nested) CheckPluginChain(record.kind, record.name, record.file);
  EnsureLoaded(record, json_path);
  // Its crash records carry this build: a rebuilt plugin, or other options, run again.
  SetCurrentPluginBuild(record.name, MakePluginBuild(record.version, record.file, options.dump()));
  AnnounceShadowing(record, records_, json_path);
  const auto& factory = record.library->get_alias<PluginFactory>(kFactorySymbol);
  const std::string options_base = options_path.empty() ? json_path + ".options" : options_path;
  const std::string who = "plugin " + Quote(record.name) + ", " + record.file.string();
  std::unique_ptr<Plugin> plugin;
  try {
    const PluginCallScope scope(record.name, PluginStage::kCreate, "from " + record.file.string());
    plugin = factory(options, services_.lock());
  } catch (const OptionError& error) {
    // Plugins report paths relative to their options; anchor them in the manifest.
    const std::string fallback =
        OptionError::Join(JoinPath(options_base, error.path()), error.message()) + " (" + who + ")";
    if (nested) throw NestedOptionError(fallback, error.path(), options, error.message(), who);
    throw InputError(fallback);
  } catch (const NestedOptionError& error) {
    // A plugin this one made refused its options: find them among this one's.
    const std::optional<std::string> at = FindJsonPath(options, error.options);
    const std::string made_by = error.who + ", made by plugin " + Quote(record.name);
    if (!at) {
      throw InputError(options_base + ": plugin " + Quote(record.name) +
                       " made a plugin with options it refuses, " +
                       OptionError::Join(JoinPath("options", error.path), error.message) + " (" +
                       made_by + ")");
    }
    const std::string path = JoinPath(*at, error.path);
    const std::string fallback =
        OptionError::Join(JoinPath(options_base, path), error.message) + " (" + made_by + ")";
    if (nested) throw NestedOptionError(fallback, path, options, error.message, made_by);
    throw InputError(fallback);
  } catch (const PluginChainError& error) {
    if (nested) throw;
    throw InputError(json_path + ": " + error.what());
  } catch (const PluginError&) {
    throw;  // a plugin this one made failed: it is named
  } catch (const HostInputError&) {
    throw;  // the host refused what this plugin asked of it: the host's words
  } catch (const InputError& error) {
    throw InputError(record.file.string() + ": plugin " + Quote(record.name) +
                     " failed to start: " + error.what());
  } catch (const std::exception& error) {
    // Not the user's input: the plugin's failure, exit code 1, as for any call.
    throw PluginError(record.name, PluginStage::kCreate, "from " + record.file.string(),
                      error.what(), /*input_error=*/false);
  } catch (...) {
    throw PluginError(record.name, PluginStage::kCreate, "from " + record.file.string(),
                      "it threw an exception that is not a std::exception",
                      /*input_error=*/false);
  }
  if (plugin == nullptr) {
    throw PluginError(record.name, PluginStage::kCreate, "from " + record.file.string(),
                      "its factory returned nothing", /*input_error=*/false);
  }
  plugin->SetLogSink(PluginLogSink(record.name));
  return plugin;
}

}  // namespace tessera
