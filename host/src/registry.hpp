// The plugin registry (spec: "Build layout"). Candidates are the *.so files of the bundled
// directory, of every --plugin-path and of VARIA_PLUGIN_PATH. A candidate's symbol table is read
// without loading it (boost::dll::library_info) to learn which kind and type it provides
// (the varia_type_<kind>__<type> marker), so that a run loads only the files its scene names.
// Loading checks varia_abi_version before importing anything else. Objects a plugin makes hold a
// reference to its shared_library, so a library never unloads under a live object.
// Trust: a candidate file, or a directory holding candidates, that is writable by group or others
// is refused (never loaded, nor its symbol table read); `list()` gives the reason, and `find()`
// names it when a scene needs a type only such a file declares.
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "errors.hpp"
#include "varia/abi/plugin_object.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::host {

// What a plugin declares in its metadata, read once when it is loaded. The properties the host
// acts on are typed here (declared_properties() checks their types, refusing the plugin
// otherwise); the whole object stays for `varia plugins`.
struct DeclaredProperties {
  bool symplectic = false;  // a one-step method's "symplectic" (in canonical coordinates)
};

// A parameter whose value the host makes into plugin objects of `kind`, the plugin's parts of this
// role (abi/plugin_object.hpp, Part): its schema property carries "x-varia-part": "<kind>".
struct PartRole {
  std::string role, kind;
};

struct PluginRecord {
  std::filesystem::path file;
  std::string kind, type, version;
  nlohmann::json parameter_schema, properties;
  DeclaredProperties declared;
  std::vector<PartRole> part_roles{};
};

// An object made for a role of another's parameters, which the made object borrows.
struct MadePart {
  std::string role;
  std::shared_ptr<PluginObject> object;
};

struct Refusal {
  std::filesystem::path file;
  std::string reason;
};

// The kind and type a candidate's marker symbol declares (type with '_' already read as '-').
struct Marker {
  std::string kind, type;
};

// What the symbol table of a candidate says, read without loading it: the dynamic symbol table of
// an ELF64 file (kept by `strip`), else what boost::dll reads.
struct SymbolScan {
  bool parsed = false;            // false: not a binary that can be read
  bool has_symbol_table = false;  // false: no symbols can be read; the file is never loaded (load())
  std::vector<Marker> markers;
};

// "lagrangian 'pendulum' (<file>)": how messages name a plugin.
std::string describe(const PluginRecord& record);

class Registry {
 public:
  // The directories searched, in order: the bundled plugins (found relative to the running
  // executable), each of `plugin_paths`, then VARIA_PLUGIN_PATH (colon-separated).
  static std::vector<std::filesystem::path> search_path(const std::vector<std::string>& plugin_paths);
  // The same with the bundled plugins' directory given (the Python module finds them beside itself).
  static std::vector<std::filesystem::path> search_path(const std::vector<std::string>& plugin_paths,
                                                        const std::filesystem::path& bundled);
  explicit Registry(std::vector<std::filesystem::path> directories);
  ~Registry();
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;

  // Every plugin found, loading every candidate; the refused files with their reasons.
  std::vector<PluginRecord> list(std::vector<Refusal>& refused);
  // The plugin of this kind and type, loading only the candidate files that declare it. Throws
  // InputError for an unknown type (listing the valid ones), PluginLoadError for a bad file,
  // and PluginLoadError naming both files for a duplicate type name.
  const PluginRecord& find(const std::string& kind, const std::string& type);
  // Constructs an object of a plugin found with find(); parameters are those of the scene's
  // object (its "type" key removed), already validated against the plugin's schema. Throws
  // InputError "<message> (the <type> plugin <file name>)" when the plugin refuses a parameter value
  // (kRefusedParameter), PluginLoadError "<file>: <type>: <message>" when it fails otherwise.
  // `parts` are the objects made from the parameters of its part roles; the made object keeps them
  // alive.
  std::shared_ptr<PluginObject> create(const std::string& kind, const std::string& type,
                                       const nlohmann::json& parameters, const sdk::Context& context,
                                       std::vector<MadePart> parts = {});
  template <class T>
  std::shared_ptr<T> create_as(const std::string& kind, const std::string& type,
                               const nlohmann::json& parameters, const sdk::Context& context,
                               std::vector<MadePart> parts = {}) {
    return std::static_pointer_cast<T>(create(kind, type, parameters, context, std::move(parts)));
  }
  // Type names of the plugins loaded so far, in load order (the run record's plugins_loaded).
  std::vector<std::string> loaded() const;
  // The record of the plugin that made an object, from the object's origin (PluginObject::origin,
  // set by create() to the record, which lives as long as the registry).
  static const PluginRecord& record_of(const void* origin);

 private:
  struct Loaded;
  // Loads one candidate and checks its ABI version and metadata; the metadata must agree with the
  // markers of its symbol table. Throws PluginLoadError "<file>: <reason>".
  static std::shared_ptr<Loaded> load(const std::filesystem::path& file, const SymbolScan& scan);
  const SymbolScan& scan(const std::filesystem::path& file);  // read once per file
  const std::vector<std::filesystem::path>& candidates();
  std::vector<std::filesystem::path> files_declaring(const std::string& kind, const std::string& type);
  std::string valid_types(const std::string& kind);

  static std::optional<std::reference_wrapper<const PluginRecord>> part_named(const std::vector<MadePart>& parts,
                                                                             std::string_view message);
  // The error for a type that only refused (untrusted) files declare, if one does.
  void check_not_refused(const std::string& kind, const std::string& type);

  std::vector<std::filesystem::path> directories_;
  std::optional<std::vector<std::filesystem::path>> candidates_;
  std::vector<Refusal> untrusted_;  // filled with candidates_
  std::map<std::filesystem::path, SymbolScan> scans_;
  std::map<std::string, std::shared_ptr<Loaded>> loaded_;  // key: kind + "/" + type
  std::vector<std::string> load_order_;
};

}  // namespace varia::host
